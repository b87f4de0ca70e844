/* lamprig — 4x4 double matrices for transforms and cameras.
 *
 * Column-major like OpenGL: element (row r, column c) is m[c * 4 + r], so a matrix converted
 * with lr_mat4_to_float() goes straight into glUniformMatrix4fv(..., GL_FALSE, ...). Points
 * are column vectors: p' = M p. Output arguments may alias inputs.
 */
#ifndef LR_MAT4_H
#define LR_MAT4_H

#include "render/base/vec3.h"

void lr_mat4_identity(double out[16]);
/* out = a * b (b applied first). */
void lr_mat4_mul(const double a[16], const double b[16], double out[16]);
void lr_mat4_translate(lr_vec3 t, double out[16]);
void lr_mat4_scale(lr_vec3 s, double out[16]);
/* Rotation by Euler angles in degrees about the fixed x, then y, then z axes:
 * R = Rz(z) Ry(y) Rx(x). Positive angles turn counter-clockwise looking down the axis. */
void lr_mat4_rotate_xyz_deg(lr_vec3 deg, double out[16]);
/* View matrix of a camera at eye looking at target (OpenGL: the camera looks down -z, y up).
 * Returns -1 (out untouched) when eye == target or up is parallel to the view direction. */
int lr_mat4_look_at(lr_vec3 eye, lr_vec3 target, lr_vec3 up, double out[16]);
/* OpenGL perspective projection (clip z in [-1, 1]); fovy in radians, vertical. */
void lr_mat4_perspective(double fovy, double aspect, double znear, double zfar, double out[16]);
/* OpenGL orthographic projection of the box [l,r] x [b,t] x [-n,-f] in view space. */
void lr_mat4_ortho(double l, double r, double b, double t, double znear, double zfar,
                   double out[16]);
/* General inverse; returns -1 (out untouched) when singular. */
int lr_mat4_inverse(const double m[16], double out[16]);
/* Inverse transpose of the upper 3x3 (row-major 3x3 out): transforms normals. Returns -1
 * when singular. */
int lr_mat4_normal_matrix(const double m[16], double out[9]);
/* Determinant of the upper 3x3 (negative for a mirroring transform). */
double lr_mat4_det3(const double m[16]);

lr_vec3 lr_mat4_point(const double m[16], lr_vec3 p);     /* affine: w = 1, no divide */
lr_vec3 lr_mat4_project(const double m[16], lr_vec3 p);   /* with perspective divide */
lr_vec3 lr_mat4_dir(const double m[16], lr_vec3 d);       /* w = 0 */
lr_vec3 lr_mat3_apply(const double n[9], lr_vec3 v);      /* row-major 3x3 */

void lr_mat4_to_float(const double m[16], float out[16]);

#endif
