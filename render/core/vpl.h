/* lamprig — CPU twin of pass 4 (PIPELINE.md): stable VPLs on an object's outer surface and the
 * receivers' irradiance from them and directly from the light (per unit light intensity).
 *
 * VPL v stands on the outermost surface of the object along u_v = lr_halton_sphere(v + 1) from
 * the object's bounding-box centre c (the farthest hit of the ray c + t u_v; the cube map of
 * PIPELINE.md sampled at u_v, without its texel quantisation). It carries the area
 * A_v = |x_v - c|^2 (4 pi / N_vpl) / max(|n_v . u_v|, 0.05) and emits F_t(w) B(x_v) / pi into its
 * outer hemisphere. A direction whose ray misses the object gives no VPL (valid = false). */
#ifndef LR_CORE_VPL_H
#define LR_CORE_VPL_H

#include <stdbool.h>

#include "render/scene/scene.h"

/* PIPELINE.md: the floor of |n_v . u_v| in A_v. */
#define LR_CPU_VPL_COS_FLOOR 0.05

typedef struct lr_vpl_point {
    bool valid;
    lr_vec3 x, n, u; /* position, unit outward normal, placement direction */
    double area;     /* A_v, mm^2 */
    double B[3];     /* scattered radiosity there (caller fills; per band, any intensity) */
    double var[3];   /* variance of B's estimate (of the mean); 0 if unknown */
} lr_vpl_point;

/* Places `count` VPLs on obj (positions and areas; B zeroed). */
void lr_vpl_place(const lr_scene_object *obj, int count, lr_vpl_point *out);

/* E_vpl at receiver point x with unit normal n, per band, adding into E (and the variance
 * from the VPLs' B variances into var, which may be NULL): PIPELINE.md's bounded geometry term
 *   sum_v F_t(cos_v, eta) B_v / pi * A_v cos_v cos_x / max(|x - x_v|^2, A_v). */
void lr_vpl_point_irradiance(const lr_vpl_point *v, int count, double eta, lr_vec3 x, lr_vec3 n,
                           double E[3], double var[3]);

/* The same with VPL visibility (render.vpl_visibility): a VPL whose segment to x meets any
 * object of s (ray cast against the BVHs) adds nothing. The GPU tests the same segment
 * against the outer envelope's cube map at 8 points (render/shaders/lib/vpl_irradiance.glsl),
 * which agrees where the segment crosses the object well inside its envelope and can miss a
 * grazing one. s NULL: no visibility (lr_vpl_point_irradiance). */
void lr_vpl_point_irradiance_vis(const lr_scene *s, const lr_vpl_point *v, int count, double eta,
                               lr_vec3 x, lr_vec3 n, double E[3], double var[3]);

/* Direct irradiance at x (normal n) from light l of unit intensity (directional: unit
 * radiance), 0 when any translucent object of the scene is in the way (the light G-buffer's
 * shadow test done with rays). */
double lr_direct_irradiance(const lr_scene *s, const lr_light *l, lr_vec3 x, lr_vec3 n);

#endif
