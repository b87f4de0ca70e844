/* lamprig — CPU twin of pass 2 (render/passes/PIPELINE.md): the scattered-radiosity estimator
 * at one surface point, and the converged (untruncated) reference of the same quantity.
 *
 * B_c(x_o, n_o) is the scattered radiosity (seed 003 Eq. 4) at x_o for a light of UNIT
 * intensity (point/spot: 1 W/sr, directional: unit radiance); callers multiply by
 * intensity * color[c]. The light G-buffer is replaced by ray casts from the light against the
 * object's BVH: x_i, n_i are the first surface along the lookup direction, n_i the interpolated
 * vertex normal (what the rasteriser would store); an open object (closed == false, e.g. a
 * zero-thickness shade) is two-sided: n_i is turned toward the light, as the GLSL G-buffer
 * does.
 *
 * Two samplers of the same integral B = pi * int S_d F_t(w_i) d(omega) (point/spot) or
 * pi * int S_d F_t dA_plane (directional):
 *   LR_CPU_PASS       exactly the GPU pass: per band N samples of r ~ exp(sigma_tr) truncated
 *                     at r_max, alpha uniform (seed 003 Eq. 11-12); point/spot through the
 *                     stereographic lookup (Eq. 13-14) with the exact Jacobian J; directional
 *                     through the light's view plane (J = 1). Biased only by the truncation.
 *   LR_CPU_REFERENCE  no truncation: a one-sample mixture (balance heuristic) of the pass's
 *                     plane sampling with r_max = Inf and uniform directions over the sphere
 *                     (directional: uniform over the object's projected disk). The mixture
 *                     keeps the weight f/p bounded where the plane's far end maps to the
 *                     antipodal cap, so the variance is finite for every material, albedo 1
 *                     (sigma_tr = 0, plane sampled at rate 1/radius) included.
 */
#ifndef LR_MODELS_RADIOSITY_H
#define LR_MODELS_RADIOSITY_H

#include <stdbool.h>
#include <stdint.h>

#include "render/base/vec3.h"
#include "render/core/ray.h"
#include "render/diffusion/dscene.h"
#include "render/scene/scene.h"

/* PIPELINE.md: r_max = 20 max(bounding radius, |x_l - x_o|) (directional: 20 radii). */
#define LR_CPU_RMAX_RADII 20.0

enum lr_cpu_sampler { LR_CPU_PASS = 0, LR_CPU_REFERENCE = 1 };

typedef struct lr_cpu_radiosity_desc {
    int N;                       /* samples per band; 0: 16 */
    enum lr_cpu_sampler sampler; /* default LR_CPU_PASS */
    double r_max;                /* LR_CPU_PASS: 0 = LR_CPU_RMAX_RADII * max(object radius,
                                  * |x_l - x_o|) (directional: * radius) */
    /* Other translucent objects of the scene: the light G-buffer holds the first surface of
     * any of them, and a lookup that meets another object first brings no light (as the GLSL
     * pass). NULL / 0: the object alone. */
    const lr_scene_object *const *others;
    int n_others;
    /* Optional emulation of the light G-buffer's resolution (for GPU parity): maps the lookup
     * direction v (point/spot) or plane point x_j (directional) to the one whose first
     * surface the G-buffer texel holds (its texel centre). NULL: exact ray casts. */
    lr_vec3 (*snap)(void *snap_ctx, lr_vec3 v);
    void *snap_ctx;
    /* "model": "diffusion_grid" (seed 001): B is the solved field at x_o (lr_dfield_eval, the
     * pass's arithmetic; no samples, variance 0); data NULL gives 0. Both samplers. */
    lr_dfield_view dfield;
    /* Objects with model sh_translucency: the light's projected environment (render/models/twin/sh.h,
     * lr_cpu_sh_env through the scene's G-buffer cameras). NULL: projected per call through a
     * small cube (slow). Their estimate is deterministic (variance 0, the sampler unused). */
    const struct lr_sh_env *sh_env;
} lr_cpu_radiosity_desc;

typedef struct lr_cpu_estimate {
    double mean[3]; /* B_c per unit light intensity, W/mm^2 per W/sr */
    double var[3];  /* sample variance of ONE sample (unbiased, n - 1); of the mean: var / n */
    int n;          /* samples per band */
} lr_cpu_estimate;

/* Estimates B at (xo, no) (no unit, pointing out of the medium) for object `obj` lit by
 * `light`; `stream` keys the random numbers (lr_rng_key of seed, map, texel, frame): the same
 * key gives the same result on any thread. Finite and >= 0 for every finite input. */
void lr_cpu_radiosity(const lr_scene_object *obj, const lr_light *light, lr_vec3 xo, lr_vec3 no,
                      const lr_cpu_radiosity_desc *d, uint64_t stream, lr_cpu_estimate *out);

/* Stereographic lookup of seed 003 Eq. 13-14 for a light at xl and a plane sample xj in the
 * tangent plane (xo, no): writes the (unnormalised) lookup direction v = h - 2 (h.l) l and
 * returns the Jacobian d(omega)/dA_j = 2 t |l.no| / (d |xj - A|^2), t = |2 h.l|, of the map
 * from the plane to directions around the light (PIPELINE.md). 0 where undefined (xj == A). */
double lr_cpu_stereo_lookup(lr_vec3 xl, lr_vec3 xo, lr_vec3 no, lr_vec3 xj, lr_vec3 *v);


#endif
