/* lamprig — Poisson-disk samples on a triangle mesh (seed 004 Sec. 3: the translucent Poisson
 * disk samples, TPDS, on the lamp's objects and the diffuse ones, DPDS, on the receivers).
 *
 * Dart throwing (the serial form of Bowers et al. 2010, the paper's [32]): candidates are drawn
 * area-uniformly over the triangles (a triangle by its area, then a uniform point in it), and
 * a candidate is kept when no kept sample lies within r_min (Euclidean distance, as the paper
 * uses). A uniform grid of r_min cells makes each test look at 27 cells. Sampling stops after
 * `max_fails` refusals in a row: each uncovered spot of area a is then missed with
 * probability about (1 - a/A)^max_fails, so a large max_fails gives a nearly maximal set, in
 * which every surface point lies within r_min of a sample (the coverage the tests check). */
#ifndef LR_AREA_POISSON_MESH_H
#define LR_AREA_POISSON_MESH_H

#include <stdint.h>

#include "render/base/err.h"
#include "render/base/vec3.h"
#include "render/mesh/mesh.h"

typedef struct lr_surface_sample {
    lr_vec3 p;      /* on the surface, mm */
    lr_vec3 n;      /* the triangle's unit normal */
    uint32_t tri;   /* the triangle */
    double area;    /* the share of the surface it stands for: mesh area / count */
} lr_surface_sample;

typedef struct lr_poisson_set {
    lr_surface_sample *s;
    int n;
} lr_poisson_set;

/* Fills *out (freed with lr_poisson_set_free) with at most cap samples at least r_min apart.
 * LR_EINVAL for r_min <= 0, cap < 1 or max_fails < 1; LR_ENOMEM. Deterministic in seed. */
int lr_poisson_mesh(const lr_mesh *m, double r_min, int cap, int max_fails, uint64_t seed,
                    lr_poisson_set *out, lr_err *e);
void lr_poisson_set_free(lr_poisson_set *set);

#endif
