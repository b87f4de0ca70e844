/* lamprig — diffusion grid internals shared by grid.c, system.c, solver.c and field.c. */
#ifndef LR_DGRID_INTERNAL_H
#define LR_DGRID_INTERNAL_H

#include <stdint.h>

#include "render/diffusion/dgrid.h"

struct lr_dgrid {
    double h;
    lr_vec3 origin;
    int n[3];
    size_t count;
    uint8_t *kind;  /* enum lr_dnode_kind per node */
    long *unknown;  /* per node: unknown index or -1 */
    long *param;    /* per node: parameter index (ghost: its owner's) or -1 */
    size_t n_in, n_ghost, n_unknown, n_band;
    size_t *unknown_node;
    size_t *param_node;
    size_t *ghost_node;
    lr_vec3 *ghost_b, *ghost_n;
    double *ghost_t;
    /* Nodes within the band (inside or ghost) with their closest surface point and normal. */
    size_t *band_node;
    lr_vec3 *band_b, *band_n;
};

/* The eight trilinear corners of p (grid nodes, clamped to the array) and their weights;
 * returns 8, or 0 for a non-finite p. */
int lr_dgrid_corners(const lr_dgrid *g, lr_vec3 p, size_t node[8], double w[8]);

/* Triquadratic (27-point Lagrange) weights of p over the unknowns around its nearest node:
 * third-order accurate values, so that the boundary condition's normal derivative taken from
 * them is second order (a trilinear value's O(h^2) error over the h of the difference would
 * leave it first order). Returns the count, or 0 when a point of the stencil is not an unknown
 * (the caller falls back to trilinear). */
int lr_dgrid_triquadratic(const lr_dgrid *g, lr_vec3 p, size_t idx[27], double w[27]);

/* A one-light source as a source per band (the same q in each): the scalar entry points are
 * the per-band ones over this. */
typedef struct lr_dgrey {
    lr_dirradiance_fn q;
    const void *ctx;
} lr_dgrey;

static inline void lr_dgrey_q(const void *ctx, lr_vec3 b, lr_vec3 n, double q[3])
{
    const lr_dgrey *g = ctx;
    q[0] = q[1] = q[2] = g->q(g->ctx, b, n);
}

#endif
