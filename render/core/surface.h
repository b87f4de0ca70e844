/* lamprig — the objects' surface cache, shared by the GPU pass (render/passes/surface.h) and
 * its CPU twin (render/cpu/frame.c): the edge bound of each object's lattice and the lattice
 * itself (render/mesh/lattice.h, in an lr_refined), so that both sides cache B at the same
 * points and interpolate alike (PIPELINE.md "Surface cache"). */
#ifndef LR_CORE_SURFACE_H
#define LR_CORE_SURFACE_H

#include <stddef.h>

#include "render/base/err.h"
#include "render/mesh/refine.h"
#include "render/scene/scene.h"

/* Edge bound of the refinement in map texels (PIPELINE.md "Surface cache" derives the
 * interpolation error from it and the diffusion length 1/sigma_tr). */
#define LR_SURFACE_EDGE_TEXELS 2.0
/* Vertices of all refined meshes at most (the GPU's cache textures: 2 x 16 bytes per entry
 * plus 16 per light); beyond, the edge bound doubles. */
#define LR_SURFACE_MAX_VERTICES ((size_t)4 << 20)

/* The edge bound for the objects of s (mm): LR_SURFACE_EDGE_TEXELS texels of the radiosity
 * maps, tau = 2 R / map_size (R the radius of lr_scene_bounds, the maps' extent); at least
 * 1e-3. The object does not change it (the maps are shared); it is an argument so that a
 * per-object rule needs no new signature. */
double lr_surface_edge_bound(const lr_scene *s, int object, int map_size);

/* Object i's lattice (lr_refine_lattice) for its edge bound, doubled while the result would
 * have more than `budget` points; *h receives the bound used. */
int lr_surface_refine(const lr_scene *s, int object, int map_size, size_t budget,
                      lr_refined *out, double *h, lr_err *e);

#endif
