/* lamprig — the light a diffusion_grid object sends back into itself across its own cavity, as
 * a boundary source for a second solve (render/diffusion/README.md, "Cavity closure").
 *
 * The grid's source q is the light's direct irradiance. Where the light sits in a cavity (the
 * flame in a deep pool) much of what leaves the lit floor meets the object again, and lands
 * mostly on the cavity's upper walls, which the flame lights at grazing angles: spreading that
 * light like the direct light (the closure's scalar gain alone) left the walls of jar_candle's
 * pool at 0.55 of the physical reference. This source is that first bounce:
 *
 *     q_1(b) = integral over the air-side hemisphere at b of
 *              F_t(cos theta_b) F_t(cos theta_y) B(y) / pi cos theta_b d omega,
 *
 * y the first surface along the direction, B the pipeline's radiosity (composition's
 * L_o = F_t(w_o) B / pi, PIPELINE.md), by `rays` stratified cosine-distributed rays, so that
 * q_1 = mean of F_t(cos theta_b) F_t(cos theta_y) B(y). Deterministic (a fixed pattern per
 * point, turned by a hash of b). */
#ifndef LR_DIFFUSION_BOUNCE_H
#define LR_DIFFUSION_BOUNCE_H

#include "render/diffusion/dscene.h"
#include "render/scene/scene.h"

typedef struct lr_dbounce {
    const lr_scene_object *obj; /* its BVH (the grid's frame) and eta */
    lr_dfield_view field;       /* B to send back: pipeline convention, per unit intensity */
    int rays;                   /* per point, rounded down to a square (>= 1) */
} lr_dbounce;

/* lr_dirradiance_rgb_fn over an lr_dbounce. */
void lr_dbounce_q(const void *ctx, lr_vec3 b, lr_vec3 n, double q[3]);

#endif
