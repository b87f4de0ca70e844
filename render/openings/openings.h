/* lamprig — the light an object's inner faces send to the plane receivers through its
 * openings (issue 12 part 3; render/openings/README.md).
 *
 * The VPLs (PIPELINE.md pass 4) stand on each object's outermost surface seen from its centre
 * c, so a lamp shade's or a votive's inner face, lit by the light inside, reached no receiver:
 * issue 12 measured that light at 28 % of the shade's receiver light. This module gathers it.
 * Emitters are points spread uniformly by area over every surface point that is NOT the
 * outermost along its ray from c (the VPLs' own criterion, so nothing is counted twice: a
 * point is inner when the ray c -> x meets the object again beyond x), on the side that faces
 * the cavity (a closed object's outward normal; an open object's both sides there, and at
 * outer points the side toward c, which the VPLs do not emit from). Emitter j (area a_j,
 * normal n_j) gives receiver point x (normal n_x)
 *
 *   E(x) = sum_j F_t(cos_j, eta) B_j / pi * a_j cos_j cos_x / max(|x - x_j|^2, a_j) * V(x_j, x)
 *
 * (composition's emitted radiance L_o = F_t(w_o) B / pi, seed 003 Eq. 5, and the VPLs' bounded
 * geometry term), V a ray cast against every object's BVH: light that meets the shade again is
 * the cavity closure's (render/core/cavity.h, which multiplies B by the gain for the fraction
 * F that returns), so only the light that leaves through the openings is added here. B_j is
 * the object's model at x_j for the light at unit intensity (lr_cpu_radiosity, the untruncated
 * sampler, fixed seeds) times that light's cavity gain (lr_cavity_scene_gains): the same
 * numbers on the GPU and in the CPU twin. E is evaluated at the centres of a grid of cells of
 * about LR_OPENINGS_CELL_MM over each plane receiver and written bilinearly at the receiver
 * grid's texel centres (render/core/recv_grid.h), where the GPU's irradiance pass
 * (render/passes/irradiance.c) and the twin (render/cpu/frame.c) add it to E_vpl before the
 * receiver bounce (render/bounce/) reads the grid, so the bounce carries it too.
 *
 * Linear in the lights: one grid per light at unit intensity (the dimmer stays blend-only).
 * The emitters and the geometry kernel (F_t, cosines, distance, visibility) are built when the
 * objects' or receivers' geometry or an object's eta changes; B and the grids when a light's
 * shape or an object's material or model changes. Point and spot lights only (others: 0).
 * Opaque struct; create/destroy; errors name the field. */
#ifndef LR_OPENINGS_H
#define LR_OPENINGS_H

#include <stdbool.h>
#include <stddef.h>

#include "render/base/err.h"
#include "render/scene/scene.h"

/* Receiver cells, mm (at most LR_OPENINGS_MAX_CELLS a side). */
#define LR_OPENINGS_CELL_MM 30.0
#define LR_OPENINGS_MAX_CELLS 64
/* Emitter points drawn per object (uniform by area over all of it; the inner ones are kept). */
#define LR_OPENINGS_POINTS 512
/* Kernel budget, entries (4 bytes each: 64 MB); a scene beyond it is refused. */
#define LR_OPENINGS_MAX_ENTRIES (16u << 20)
/* Samples per band of each emitter's B (lr_cpu_radiosity, LR_CPU_REFERENCE). */
#define LR_OPENINGS_N 256

typedef struct lr_openings lr_openings;

/* The share of object o's area (index: its place in the scene, which seeds the points) that
 * emits here: its inner faces, where the VPLs do not stand (an open object's inner side
 * counts too), from the emitters' own stratified points; 0 for an empty mesh or when out of
 * memory. The planner turns render.opening_light on where it is at least
 * LR_PLAN_INNER_MIN (render/plan/plan.h): the candles' 0, the jar's deep pool 0.16, the
 * shades' and the votive's inside 0.4-0.5. */
double lr_openings_inner_fraction(const lr_scene_object *o, int index);

/* Whether scene s asks for it (render.opening_light) and it has work: a plane receiver, a
 * light, and no object using translucent_radiosity and no render.lpv (both carry this light
 * already: render/transrad/tr_scene.h, render/lpv/). */
bool lr_openings_needed(const lr_scene *s);
/* Creates *op on first use, destroys it and sets *op = NULL when not needed; rebuilds what
 * changed (above). grid: the scene's solved diffusion_grid objects (render/diffusion/dscene.h),
 * whose B is their field (it carries their own cavity closure); NULL when the scene has none
 * (such an object's emitters then give 0). threads: 0 = all CPUs. */
struct lr_dscene;
int lr_openings_update(lr_openings **op, const lr_scene *s, const struct lr_dscene *grid,
                       int threads, lr_err *e);
void lr_openings_destroy(lr_openings *op);

/* Light l's irradiance on plane receiver r at the receiver grid's texel centres (3 floats per
 * texel, s + LR_RECV_GRID t; W/mm^2 per W/sr), NULL when r has no grid or l is out of range. */
const float *lr_openings_grid(const lr_openings *op, int r, int l);

/* Light l's irradiance at receiver point x (unit normal n), per band, added into E: the
 * kernel's sum evaluated at x itself (a ray cast per emitter; the CPU twin's REFERENCE mode,
 * which sums the VPLs per pixel too, uses it instead of the cells' grid). */
void lr_openings_irradiance_at(const lr_openings *op, const lr_scene *s, int l, lr_vec3 x,
                               lr_vec3 n, double E[3]);

/* Diagnosis and tests. Emitters kept (all objects) and their total area, mm^2. */
size_t lr_openings_emitter_count(const lr_openings *op, double *area);
/* Emitter j's point, the normal of its emitting side and the area it stands for (false when
 * j is out of range). */
bool lr_openings_emitter(const lr_openings *op, size_t j, lr_vec3 *x, lr_vec3 *n, double *a);
/* Receiver r's cell grid (nu x nv; false without one). */
bool lr_openings_cells(const lr_openings *op, int r, int *nu, int *nv);
/* Applies the kernel to given emitter radiosities B (3 per emitter, in emitter order): the
 * irradiance at receiver r's cell centres (3 per cell, row v of nu at X + 3 nu v). */
int lr_openings_apply(const lr_openings *op, int r, const double *B, double *X, lr_err *e);
/* Light l's emitter radiosities (3 per emitter; NULL before an update). */
const double *lr_openings_B(const lr_openings *op, int l);
/* Seconds of the last update: kernel build (0 when reused), B and grids. */
void lr_openings_times(const lr_openings *op, double *build_s, double *light_s);

#endif
