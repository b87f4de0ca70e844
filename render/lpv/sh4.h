/* lamprig — two-band spherical harmonics (4 coefficients) for the light-propagation volumes
 * (seed 004 Sec. 3.2 and 4.4 after Kaplanyan & Dachsbacher 2010, "Cascaded light propagation
 * volumes"): the real basis, the clamped-cosine lobe of Eq. 4 and Eq. 10/16, the cosine
 * convolution that turns a cell's intensity into irradiance, and the face transfer integrals
 * of Eq. 12-14.
 *
 * Coefficient order here is (c_00, c_1x, c_1y, c_1z): c_1x multiplies y_11 = k1 x,
 * c_1y multiplies y_1-1 = k1 y, c_1z multiplies y_10 = k1 z, with k0 = 1/(2 sqrt(pi)) and
 * k1 = sqrt(3/(4 pi)). A function f(w) is approximated as sum_i c_i y_i(w) with
 * c_i = integral f y_i dw. */
#ifndef LR_LPV_SH4_H
#define LR_LPV_SH4_H

#include "render/base/vec3.h"

#define LR_SH4_K0 0.28209479177387814 /* 1 / (2 sqrt(pi)) */
#define LR_SH4_K1 0.48860251190291992 /* sqrt(3 / (4 pi)) */

/* y_i(w) for unit w. */
void lr_sh4_basis(lr_vec3 w, double y[4]);
/* sum_i c_i y_i(w). */
double lr_sh4_eval(const double c[4], lr_vec3 w);

/* The SH coefficients of the clamped cosine max(0, n.w) about unit n (zonal harmonics rotated
 * to n, Kaplanyan & Dachsbacher Sec. 4; Ramamoorthi & Hanrahan 2001):
 * c_00 = sqrt(pi)/2, c_1 = sqrt(pi/3) n. Its integral over the sphere is pi, so a lobe
 * (Phi/pi) max(0, n.w) carries the flux Phi (Eq. 4's 1/pi, Eq. 10). */
void lr_sh4_cosine_lobe(lr_vec3 n, double c[4]);

/* The flux the intensity distribution c carries over the sphere: integral sum c_i y_i dw
 * = c_00 sqrt(4 pi). */
double lr_sh4_flux(const double c[4]);

/* integral I(w) max(0, d.w) dw for the intensity I = sum c_i y_i and unit d: the cosine
 * convolution pi c_00 k0 + (2 pi / 3) k1 (c_1 . d) (Ramamoorthi & Hanrahan's A_0 = pi,
 * A_1 = 2 pi / 3). For the flux arriving at a surface of normal n, d = -n. */
double lr_sh4_cosine_integral(const double c[4], lr_vec3 d);

/* The face transfer of propagation (Eq. 12-14): a source cell at the origin, its neighbour
 * one cell along the unit axis `main`, and one face of that neighbour other than the shared
 * one: the front face (side = 0) or the side face toward axis direction `side` (a unit axis
 * vector perpendicular to main). Cell units. Fills v_i = integral over the face's solid
 * angle (seen from the source's centre) of y_i dw, so the flux through the face is
 * v . c_s (Eq. 13). The integrals are exact up to the quadrature of lr_sh4_face_moments. */
typedef struct lr_sh4_faces lr_sh4_faces;
void lr_sh4_face_transfer(const lr_sh4_faces *f, lr_vec3 main, lr_vec3 side, int is_side,
                          double v[4]);

/* The three numbers the 30 face transfers are made of, for main = +z:
 * front face: solid angle 4 asin(1/10) (the square of side 1 at distance 3/2) and
 * mz_front = integral w_z dw over it; side face toward +x: solid angle
 * (2 pi / 3 - front) / 4 (the five far faces of a cube subtend what its near face does,
 * 2 pi / 3), mz_side = integral w_z dw, mx_side = integral w_x dw (the w_y integral is 0 by
 * symmetry). The first moments come from a 512 x 512 midpoint rule over the face in the
 * solid-angle measure cos / d^2 dA (relative error below 1e-6). Costs about 1 ms: callers
 * compute it once. */
struct lr_sh4_faces {
    double omega_front, mz_front;
    double omega_side, mz_side, mx_side;
};
void lr_sh4_face_moments(lr_sh4_faces *f);

#endif
