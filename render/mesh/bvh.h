/* lamprig — bounding volume hierarchy over a mesh's triangles: ray casts and closest points
 * for the CPU twin of the render passes (visibility of VPLs, light G-buffer rays, reference).
 *
 * Answers are exactly those of the brute-force loops below (same triangle test, same tie
 * rule: the smallest t, then the lowest triangle index), only faster; boxes are padded so
 * that rounding in the box test can never hide a hit.
 */
#ifndef LR_BVH_H
#define LR_BVH_H

#include <stdbool.h>
#include <stddef.h>

#include "render/base/err.h"
#include "render/base/vec3.h"
#include "render/mesh/mesh.h"

typedef struct lr_bvh lr_bvh;

typedef struct lr_hit {
    double t;        /* ray parameter: point = o + t d */
    size_t triangle; /* index into the mesh */
    double u, v;     /* barycentrics: p = (1-u-v) p0 + u p1 + v p2 */
} lr_hit;

typedef struct lr_closest {
    lr_vec3 point;
    double distance;
    size_t triangle;
    double w[3]; /* barycentric weights of point on the triangle */
} lr_closest;

/* Builds over m, which must outlive the hierarchy (it is read, not copied). */
int lr_bvh_create(const lr_mesh *m, lr_bvh **out, lr_err *e);
void lr_bvh_destroy(lr_bvh *b);
const lr_mesh *lr_bvh_mesh(const lr_bvh *b);

/* Nearest hit with tmin <= t <= tmax (both faces count); false when none. */
bool lr_bvh_intersect(const lr_bvh *b, lr_vec3 o, lr_vec3 d, double tmin, double tmax,
                      lr_hit *hit);
/* Any hit in [tmin, tmax]: shadow rays. */
bool lr_bvh_occluded(const lr_bvh *b, lr_vec3 o, lr_vec3 d, double tmin, double tmax);
/* Closest surface point within max_dist (INFINITY for no limit); false when none. */
bool lr_bvh_closest(const lr_bvh *b, lr_vec3 p, double max_dist, lr_closest *out);

/* The same by testing every triangle (the reference the tests hold the hierarchy to). */
bool lr_mesh_intersect(const lr_mesh *m, lr_vec3 o, lr_vec3 d, double tmin, double tmax,
                       lr_hit *hit);
bool lr_mesh_closest(const lr_mesh *m, lr_vec3 p, double max_dist, lr_closest *out);

#endif
