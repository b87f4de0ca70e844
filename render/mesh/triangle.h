/* lamprig — single-triangle geometry in double precision for the CPU reference code. */
#ifndef LR_TRIANGLE_H
#define LR_TRIANGLE_H

#include <stdbool.h>

#include "render/base/vec3.h"

/* Ray o + t d against triangle (a, b, c), Moller & Trumbore 1997, both sides. True when it
 * hits with tmin <= t <= tmax; then *t and the barycentrics (u, v) of the hit point
 * a + u (b - a) + v (c - a) are set. d need not be unit length (t is in its units).
 *
 * The barycentric bounds are widened by LR_RAY_TRIANGLE_EDGE_TOL (dimensionless, so
 * scale-free): a ray through the shared edge of two triangles otherwise could miss both by
 * rounding (a 1 m box refined to 12 mm edges let a projector ray through its top face onto
 * the bottom, test_calib_ar). An edge hit may now report either triangle; callers that count
 * crossings already step past equal t (render/diffusion/shape.c). */
#define LR_RAY_TRIANGLE_EDGE_TOL 1e-9
bool lr_ray_triangle(lr_vec3 o, lr_vec3 d, lr_vec3 a, lr_vec3 b, lr_vec3 c, double tmin,
                     double tmax, double *t, double *u, double *v);

/* Closest point to p on triangle (a, b, c) (Ericson, Real-Time Collision Detection 5.1.5),
 * with its barycentric weights w (w[0] a + w[1] b + w[2] c; a weight is exactly 0 when the
 * point lies on the opposite edge or beyond). Degenerate triangles are handled. */
lr_vec3 lr_closest_on_triangle(lr_vec3 p, lr_vec3 a, lr_vec3 b, lr_vec3 c, double w[3]);

/* Closest point to p on segment [a, b], with weights w (w[0] a + w[1] b). */
lr_vec3 lr_closest_on_segment(lr_vec3 p, lr_vec3 a, lr_vec3 b, double w[2]);

#endif
