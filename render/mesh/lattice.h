/* lamprig — lattice refinement of a triangle mesh for the objects' surface cache (issue 11:
 * render/passes/PIPELINE.md "Surface cache"), so that composition can find a point's cache
 * entries by arithmetic from its original triangle and barycentrics, per pixel, instead of
 * rasterising a refined mesh.
 *
 * Original triangle t (corners p0, p1, p2; barycentrics (u, v) of p1 and p2) of longest edge
 * L_t gets resolution R_t = max(1, ceil(L_t / h)) and the (R_t + 1)(R_t + 2) / 2 lattice
 * points (i, j), i, j >= 0, i + j <= R_t, at (u, v) = (i, j) / R_t: vertex
 * lat_base[t] + j (R_t + 1) - j (j - 1) / 2 + i, with the parent's linearly interpolated
 * position and (not renormalised) normal. Its R_t^2 sub-triangles, each a copy of the parent
 * scaled by 1 / R_t (edges at most h, the bound of lr_refine), are numbered row by row:
 * row j (0 <= j < R_t) holds 2 (R_t - j) - 1 of them, lower (i, j), (i + 1, j), (i, j + 1) at
 * 2 i and upper (i + 1, j), (i + 1, j + 1), (i, j + 1) at 2 i + 1, so triangle
 * first[t] + 2 R_t j - j^2 + 2 i + upper; the winding is the parent's. Lattice points on an
 * edge shared by two triangles are not shared (each triangle has its own; the two sides'
 * resolutions may differ): a value interpolated on either side of the edge differs by at most
 * the interpolation error of each (render/mesh/refine.h's bound). The result fills
 * lr_refined (idx, parent, uv, first as lr_refine's, plus lat_R and lat_base), so that its
 * users (the CPU twin's interpolation, the GPU's entries) take either refinement. */
#ifndef LR_LATTICE_H
#define LR_LATTICE_H

#include "render/mesh/refine.h"

/* Lattice-refines m to sub-triangle edges of at most h (mm, > 0). max_vertices (0: no
 * limit): beyond it, LR_EUNSUPPORTED naming the mesh, h and the limit. */
int lr_refine_lattice(const lr_mesh *m, double h, size_t max_vertices, lr_refined *out,
                      lr_err *e);

/* The sub-triangle of original triangle t holding barycentrics (u, v), clamped into the
 * triangle, and the point's barycentrics (w0, w1, w2) in it (sum 1) for the corners in idx
 * order: the arithmetic of render/shaders/compose_cached.frag, in double. */
size_t lr_lattice_locate(const lr_refined *r, size_t t, double u, double v, double w[3]);

#endif
