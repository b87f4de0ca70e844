/* lamprig tests — Monte Carlo comparisons for the physical reference (render/reference). */
#ifndef LRT_MC_H
#define LRT_MC_H

#include <stdint.h>

#include "render/reference/reference.h"

/* Mean and its standard error from a sum s1 and a sum of squares s2 of n samples. */
lr_ref_estimate lrt_mean_se(double s1, double s2, double n);

/* Prints both estimates and their distance in combined standard errors, and asserts it is at
 * most 4 (two-sided 4 sigma: a false failure has probability 6.3e-5). An exact value is an
 * estimate with se 0. */
void lrt_assert_agree(const char *what, lr_ref_estimate a, lr_ref_estimate b);

/* The power leaving a sphere of radius R around the origin, per unit of 4 pi (the power of a
 * unit isotropic point light), by the camera-path estimator: Phi = int_A int_H+ L_o cos dw dA
 * with x uniform on the sphere and w cosine-weighted about the outward normal, so
 * Phi = A pi E[L_o(x, w)], L_o from lr_ref_radiance for a ray arriving at x along -w from
 * just outside. 64 fixed batches on all CPUs; paths is rounded down to a multiple of 64.
 * stats may be NULL. */
lr_ref_estimate lrt_camera_outflow(const lr_ref_scene *s, double R, int paths, uint64_t seed,
                                   lr_ref_stats *stats);

#endif
