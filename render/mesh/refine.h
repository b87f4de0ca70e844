/* lamprig — a refined copy of a triangle mesh: every edge at most h long (issue 11, the
 * objects' surface cache: render/passes/surface.h, render/core/surface.h; and the mesh every
 * scene object is drawn with, render/scene/scene_internal.h LR_SCENE_MAX_EDGE_MM).
 *
 * Edges longer than h are split at their midpoints, shared between the two triangles of an
 * edge, so the result is conforming (no T-junctions) and renders the same surface: a new
 * vertex's position and normal are the mean of the edge's end points (the normal is not
 * renormalised), so that barycentric interpolation over the refined triangles gives exactly
 * the parent's linearly interpolated position and normal field. A triangle with 1, 2 or 3
 * split edges becomes 2, 3 or 4 triangles of the same winding; the splitting repeats until no
 * edge is longer than h. Each refined triangle records its parent and its corners'
 * barycentrics in the parent, so a ray hit on the original mesh (render/mesh/bvh.h: triangle,
 * u, v) finds its refined triangle without a new BVH (lr_refined_locate). */
#ifndef LR_REFINE_H
#define LR_REFINE_H

#include <stddef.h>
#include <stdint.h>

#include "render/base/err.h"
#include "render/mesh/mesh.h"

typedef struct lr_refined {
    size_t nv, nt;
    float *pos;        /* 3 per vertex */
    float *nrm;        /* 3 per vertex: the parent's interpolated normal, not unit */
    uint32_t *idx;     /* 3 per triangle, refined triangles grouped by parent */
    uint32_t *parent;  /* per refined triangle: its triangle in the original mesh */
    float *uv;         /* 6 per refined triangle: (u, v) of each corner in the parent */
    size_t *first;     /* per original triangle t: its refined triangles are first[t] ..
                        * first[t + 1] - 1 (n_parents + 1 entries) */
    size_t n_parents;
    /* Lattice refinement only (lr_refine_lattice; NULL for lr_refine): per original
     * triangle t its lattice resolution R and its first vertex (render/mesh/lattice.h). */
    uint32_t *lat_R, *lat_base;
} lr_refined;

/* Refines m so that no edge is longer than h (mm, > 0). max_vertices (0: no limit) bounds
 * the result: beyond it, LR_EUNSUPPORTED naming the mesh, h and the limit. */
int lr_refine(const lr_mesh *m, double h, size_t max_vertices, lr_refined *out, lr_err *e);
void lr_refined_free(lr_refined *r);

/* The refined triangle holding barycentrics (u, v) of original triangle t, and the
 * barycentrics (w0, w1, w2) of the point in it (sum 1). Returns that triangle's index. A
 * lattice refinement (lat_R set) is located by arithmetic (lr_lattice_locate). */
size_t lr_refined_locate(const lr_refined *r, size_t t, double u, double v, double w[3]);

#endif
