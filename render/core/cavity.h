/* lamprig — inter-reflection inside a cavity around an enclosed light (issue 3, PIPELINE.md
 * "Energy"): an integrating-sphere closure of seed 000's B = (I - S F)^-1 S E to first order.
 *
 * The passes give B for light that arrives straight from the light. Inside a cavity (the bulb
 * in a shade, a light in a hollow sphere, the flame in a melt pool) part of it comes back:
 * Fresnel reflection at entry, and what the wall sends back out on the cavity side. That light
 * meets the object again with probability F (the flux-weighted view factor of the lit surface
 * to the object itself: 1 in a closed sphere, small for a shallow pool) and is scattered the
 * same way. Assuming the bounced light is spread over the walls like the direct light (exact
 * for a light at the centre of a sphere), every B scales by one factor per band, the cavity
 * gain (geometric series over the bounces)
 *
 *   gain = 1 + T_hem rho_1 F / ((1 - R_1) (1 - rho_d F)),
 *   rho_1 = R_1 + (1 - R_1) b        first hit: Fresnel reflectance R_1 at the light's incidence
 *   rho_d = (1 - T_hem) + T_hem b    later hits arrive diffusely: entry transmittance T_hem
 *   b = max(0, A - a)                energy: what entered and neither left on the far side nor
 *                                    was absorbed comes back into the cavity
 *
 * with a = (power leaving the surface the light does not see) / (power that entered), from the
 * model (area-sampled surface points, B with the untruncated sampler), and A the normalised
 * model's half-space total (lr_dipole_rd_total; 1 at albedo' 1; for "model": "multipole" the
 * slab's R + T total, lr_sss_total). For a closed non-absorbing
 * object (F = 1, A = 1) the unlit surface then emits exactly the light's power whatever a is;
 * the half-space model's own cavity-side B (which double counts in a thin wall) is not used
 * for b. Only for point and spot lights inside the object's hull (LR_ENCLOSURE_HULL); the raw
 * model ("normalize": false with the directional dipole) has no closure (A > 1 there: the
 * series would diverge); the standard dipole ("model": "standard_dipole") has it either way. */
#ifndef LR_CORE_CAVITY_H
#define LR_CORE_CAVITY_H

#include <stdbool.h>
#include <stdint.h>

#include "render/base/err.h"
#include "render/scene/scene.h"

/* Largest gain reported: a wall that lets almost nothing out (a -> 0) traps the light for
 * ~1/a bounces; beyond this the closure is not meaningful. */
#define LR_CAVITY_GAIN_MAX 1000.0

typedef struct lr_cavity_desc {
    int directions; /* light directions (Halton) for C, R_1 and F; 0: 4096 */
    int points;     /* surface points (uniform by area) for a; 0: 256 */
    int N;          /* samples per band and point (LR_CPU_REFERENCE sampler); 0: 64 */
    unsigned seed;  /* 0: 1 */
    int threads;    /* 0: all CPUs */
} lr_cavity_desc;

typedef struct lr_cavity {
    double C;          /* fraction of the light's power that meets the object's front side */
    double R1;         /* flux-weighted Fresnel reflectance there */
    double F;          /* flux-weighted view factor of the lit surface to the object */
    double entered;    /* power entering, per unit intensity (W per W/sr) */
    double out[3];     /* power leaving the unlit surface, per unit intensity, direct light */
    double a[3];       /* out / entered */
    double b[3];       /* cavity-side albedo from energy, max(0, A - a) */
    double gain[3];    /* the cavity gain; 1 where the closure does not apply */
    bool applies;      /* enclosed point/spot light and the normalised model */
} lr_cavity;

/* B per unit intensity at surface point x, normal n, estimated with N samples per band from the
 * random stream `key` (the untruncated sampler of the profile models:
 * render/models/twin/cavity_gains.c). */
typedef void (*lr_cavity_sample_fn)(const void *ctx, lr_vec3 x, lr_vec3 n, int N, uint64_t key,
                                    double B[3]);

/* The closure with b from energy (b = max(0, A - a), the comment above) for a half-space
 * profile model: `applies` says whether it closes the cavity at all (an enclosed point/spot
 * light and a model with a closure; the models decide: lr_cavity_measure), A[c] the model's
 * total (what entered and was not absorbed), B its estimator at surface points. */
int lr_cavity_measure_energy(const lr_scene_object *obj, const lr_light *l, bool applies,
                             const double A[3], const lr_cavity_desc *d, lr_cavity_sample_fn B,
                             const void *ctx, lr_cavity *out, lr_err *e);

/* B per unit intensity leaving an object at surface point x, outward normal n, as a model
 * that is not a profile solved it (the grid's field: render/diffusion/dscene.c). */
typedef void (*lr_cavity_b_fn)(const void *ctx, lr_vec3 x, lr_vec3 n, double B[3]);

/* The closure for a model with its own finite geometry (diffusion_grid): C, R_1, F as above;
 * a and b from that model's solved B (b: what the cavity side really sends back, not
 * max(0, A - a)). d->points: surface points, 0: 4096 (B is cheap to evaluate); d->N unused.
 * Applies to point and spot lights with LR_ENCLOSURE_HULL whatever the object's model. */
int lr_cavity_measure_field(const lr_scene_object *obj, const lr_light *l,
                                enum lr_enclosure enclosure, const lr_cavity_desc *d,
                                lr_cavity_b_fn B, const void *ctx, lr_cavity *out, lr_err *e);

#endif
