/* lamprig — picking points uniformly by area over a mesh: the triangle from a cumulative area
 * table, the point in the triangle (the cavity measure, the openings' points, Poisson-disk
 * samples). */
#ifndef LR_AREA_PICK_H
#define LR_AREA_PICK_H

#include <stddef.h>

#include "render/base/vec3.h"

/* The first index of the cumulative (non-decreasing) table cdf[0 .. n-1], n >= 1, whose value
 * is above u (binary search); n - 1 when none is. */
size_t lr_cdf_pick(const double *cdf, size_t n, double u);

/* v[0] + s (v[1] - v[0]) + t (v[2] - v[0]) with (s, t) from the unit square folded onto the
 * triangle (s + t > 1: 1 - s, 1 - t): uniform (s, t) give a point uniform in its area. */
lr_vec3 lr_triangle_fold_point(const lr_vec3 v[3], double s, double t);

#endif
