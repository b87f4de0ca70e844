/* lamprig — receiver inter-reflection for every model (issue 12 part 4; render/bounce/README.md).
 *
 * The plane receivers get the light's direct light (per pixel in composition) and the objects'
 * emergent light through the VPLs (the receiver irradiance grid, render/core/recv_grid.h), but
 * the light a receiver reflects never reaches another: the candle's table, lit only by what
 * the wall sends back, stayed black. This adds the receivers' radiosity solution of seed 000
 * with S = P (the albedo) on the receivers,
 *
 *     B = (I - P F)^-1 P E                                 (seed 000 Eq. 2 / Eq. 14, S = P)
 *
 * over patches of the receivers (render/transrad's plane grids, 30 mm) and of the objects
 * (30 mm), F by cosine ray casts. An object's patches reflect the receivers' light with the
 * albedo its material shows diffuse light (lr_objlight_albedo: the interface's 1 - <F_t> plus
 * <F_t> R) and get no E of their own (their glow is the VPLs'): the light a wax body sends
 * back to the table at its foot. A closed body covers the receiver cells it stands on: their
 * F, E and solution are over their open part (render/transrad/cover.c). E per receiver patch
 * is the light's direct irradiance (shadow rays, spot cone, area lights' closed form) plus the
 * VPLs' emergent irradiance averaged over the patch's open texels of the grid; the bounced
 * irradiance E_b = F B (all orders; what the direct and VPL terms do not already carry) is
 * written at the grid's texel centres, bilinear between patch centres weighted by their open
 * fractions. Composition adds it through the grid (render/passes/irradiance.c on the GPU,
 * render/cpu/frame.c in the twin).
 *
 * Everything is linear in the lights: the GPU solves per light slot at unit intensity (E =
 * E_dir,l + E_vpl,l), so a dimmer turn stays blend-only; the twin, whose grid sums the lights
 * with their intensities, solves once with E = sum_l I_l E_dir,l + E_vpl. F is built only when
 * the objects' or receivers' geometry changes, E_dir only when a light's shape moves; a new
 * VPL grid (an accumulation frame) costs the patch means, a warm-started Gauss-Seidel solve
 * and the bilinear write.
 *
 * Objects using translucent_radiosity already have this in their solve (render/transrad/
 * tr_scene.h puts the receivers in F): then it is off (lr_rbounce_needed false).
 * Opaque struct; create/destroy; errors name the field. */
#ifndef LR_RBOUNCE_H
#define LR_RBOUNCE_H

#include <stdbool.h>

#include "render/base/err.h"
#include "render/scene/scene.h"
#include "render/transrad/transrad.h"

typedef struct lr_rbounce lr_rbounce;
typedef struct lr_objlight lr_objlight;

/* Whether scene s asks for it (render.receiver_bounce) and it has work: a plane receiver, a
 * light, no object using translucent_radiosity and no light-propagation volume (render.lpv:
 * its volumes bounce between the receivers already). */
bool lr_rbounce_needed(const lr_scene *s);
/* Creates *rb on first use; destroys it and sets *rb = NULL when not needed. Rebuilds the
 * patches and F when the objects' or receivers' geometry (or albedo) changed since the last
 * call, the direct irradiance of a light when its shape (type, position, direction, cone,
 * emitter) changed. `cancel` (NULL: never) is polled by this build and by the solves until
 * the next update (render/base/cancel.h): LR_ECANCELED then, and the next update or solve
 * redoes what was cut short. */
int lr_rbounce_update(lr_rbounce **rb, const lr_scene *s, const lr_cancel *cancel, lr_err *e);
void lr_rbounce_destroy(lr_rbounce *rb);

/* The VPLs' irradiance on plane receiver r for the next solve: its grid's LR_RECV_GRID^2
 * texels, `stride` values each, the first three RGB (W/mm^2); NULL: none. Averaged over the
 * texels whose centres lie in each patch. */
void lr_rbounce_vpl_f(lr_rbounce *rb, int r, const float *grid, int stride);
void lr_rbounce_vpl_d(lr_rbounce *rb, int r, const double *grid, int stride);
/* Solves slot (0 .. LR_TR_MAX_SLOTS - 1, warm-started from its last solution) with
 * E = sum_l w[l] E_dir,l + E_vpl, w[l] per band for each of the scene's lights (NULL: no
 * direct light), and fills the slot's bounced-irradiance grids. */
int lr_rbounce_solve(lr_rbounce *rb, int slot, const double (*w)[3], lr_err *e);
/* Slot's bounced irradiance E_b on plane receiver r at the grid's texel centres (3 floats per
 * texel, s + R t); NULL when r has no grid or the slot was not solved. */
const float *lr_rbounce_grid(const lr_rbounce *rb, int r, int slot);
/* The solver (receivers' patches after the objects': lr_rbounce_first_receiver). */
const lr_tr *lr_rbounce_solver(const lr_rbounce *rb);
int lr_rbounce_first_receiver(const lr_rbounce *rb);
/* With render.receiver_light_on_objects: the receivers' light on the objects' vertices,
 * evaluated by every lr_rbounce_solve for its slot (objlight.h); else NULL. */
const lr_objlight *lr_rbounce_objects(const lr_rbounce *rb);
/* Seconds: the last F build (0 when reused), the last direct-light update, the last solve
 * (patch means, sweeps and grid write). */
void lr_rbounce_times(const lr_rbounce *rb, double *build_s, double *direct_s, double *solve_s);

#endif
