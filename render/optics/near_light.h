/* lamprig — a point light's irradiance integrated over a surface patch rather than sampled at
 * a point.
 *
 * A unit-intensity point light at p gives a surface point x with normal n the irradiance
 * E(x) = n . (p - x) / |p - x|^3 (cos theta / d^2), which diverges as p nears the surface. What
 * a discretisation needs is the power the patch a sample stands for receives, and that is
 * bounded: over a planar patch P with p on its front side,
 *
 *     int_P n . (p - x) / |p - x|^3 dA = Omega_P <= 2 pi,
 *
 * the solid angle P subtends at p (the integrand is the solid-angle measure). So the mean
 * irradiance over the patch is Omega_P / A_P: for d >> sqrt(A_P) it tends to the point sample
 * cos / d^2 (relative difference O(A_P / d^2)), and as d -> 0 it stays at most 2 pi / A_P.
 * Fresnel transmission depends on the cosine, which varies over the patch (near the light it
 * spans 0..1): the patch's solid-angle-weighted mean cosine, Phi_P / Omega_P with Phi_P the
 * projected solid angle (int cos d omega; Lambert's polygon formula, the form factor's), is
 * the cosine to take F_t at. Solid angles of triangles by Van Oosterom & Strackee (1983):
 *
 *     tan(Omega / 2) = a . (b x c) / (|a||b||c| + (a.b)|c| + (a.c)|b| + (b.c)|a|),
 *
 * a, b, c the corners relative to p (exact; atan2 keeps the branch for Omega up to 2 pi).
 * Users: the diffusion grid's boundary source (render/diffusion/dscene.c), sh_translucency's
 * direct term (render/models/twin/sh.c, render/shaders/lib/sh_translucency.glsl), translucent
 * radiosity's direct term and its entering part (render/transrad/direct.c). */
#ifndef LR_NEAR_LIGHT_H
#define LR_NEAR_LIGHT_H

#include "render/base/vec3.h"

/* Signed solid angle of triangle (a, b, c) seen from p: positive when p lies on the side
 * (b - a) x (c - a) points to, in [-2 pi, 2 pi]; 0 when p is in the triangle's plane. */
double lr_solid_angle_triangle(lr_vec3 p, lr_vec3 a, lr_vec3 b, lr_vec3 c);

/* Signed solid angle, seen from p, of the square of side `side` centred at c in the plane of
 * unit normal n (positive on n's side). The square's edges are along a fixed tangent frame of
 * n (lr_near_light_frame); its solid angle depends on that orientation only where the square's
 * size is comparable to p's distance. */
double lr_solid_angle_square(lr_vec3 p, lr_vec3 c, lr_vec3 n, double side);

/* Projected solid angle of that square seen from p, int (n . w) d omega over the directions w
 * from the square toward p (Lambert: 1/2 sum over edges of the angle they subtend times the
 * cosine between n and the edge plane's normal); signed like the solid angle, |Phi| <= pi. */
double lr_projected_solid_angle_square(lr_vec3 p, lr_vec3 c, lr_vec3 n, double side);

/* Projected solid angle of triangle (a, b, c), unit normal n along (b - a) x (c - a), seen
 * from p: int (n . w) d omega over the directions w toward p (Lambert, as the square's);
 * signed like lr_solid_angle_triangle, |Phi| <= pi. Phi / Omega is the solid-angle-weighted
 * mean cosine at which the light arrives on the triangle. */
double lr_projected_solid_angle_triangle(lr_vec3 p, lr_vec3 a, lr_vec3 b, lr_vec3 c, lr_vec3 n);

/* Mean over that square of max(0, n . (p - x)) / |p - x|^3: the cell-averaged irradiance of a
 * unit point light at p, max(0, Omega) / side^2; the point sample cos / d^2 at c when side is
 * 0. Finite for every p off the square and at most 2 pi / side^2. mean_cos (may be NULL): the
 * solid-angle-weighted mean cosine Phi / Omega (side 0: the centre's cosine), 0 when unlit. */
double lr_patch_irradiance(lr_vec3 p, lr_vec3 c, lr_vec3 n, double side, double *mean_cos);

/* lr_patch_irradiance as a GPU estimator and its CPU twin compute it
 * (render/shaders/lib/near_light.glsl): the patch mean up to LR_PATCH_FAR_LO sides from the
 * centre, the point sample beyond LR_PATCH_FAR_HI, smoothstep-blended between. Far off, the
 * two differ by O(side^2 / d^2) (the mean of a smooth E over the square: E + side^2 / 24
 * times its tangential Laplacian, ~ 1e-3 E at 16 sides), while the solid angle's triple
 * product loses ~ (d / side)^2 ulps to cancellation (float: ~1e-4 at 32 sides). */
#define LR_PATCH_FAR_LO 16.0
#define LR_PATCH_FAR_HI 32.0
double lr_patch_irradiance_far(lr_vec3 p, lr_vec3 c, lr_vec3 n, double side, double *mean_cos);

/* The tangent frame (t1, t2) the square above uses: t1 . n = t2 . n = t1 . t2 = 0, unit. */
void lr_near_light_frame(lr_vec3 n, lr_vec3 *t1, lr_vec3 *t2);

#endif
