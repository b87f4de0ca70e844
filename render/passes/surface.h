/* lamprig — the objects' surface cache (issue 11; render/passes/PIPELINE.md "Surface cache";
 * surface.c): B_l of Algorithm 1 per light at unit intensity at the points of a lattice over
 * every triangle of every object mesh (render/mesh/lattice.h), view-independent, redrawn only
 * when the maps change or accumulate. Composition interpolates it per pixel over the lattice
 * sub-triangle holding the pixel's point and applies F_t(w_o) / pi, so a camera move runs no
 * gather and rasterises only the original mesh. */
#ifndef LR_SURFACE_H
#define LR_SURFACE_H

#include "render/core/surface.h"
#include "render/passes/passes.h"
#include "render/passes/radiosity.h"

/* Cache texels per row. */
#define LR_SURFACE_ROW 2048

/* Entries: object i's lattice vertex v (render/mesh/lattice.h) at texel base[i] + v with its
 * normal; an open
 * (two-sided) object also at base[i] + nv[i] + v with the normal reversed. Layer l of B is
 * light l's B (rgb) and whether a map saw the point (a: 1, or 0 for Algorithm 1's fallback). */
typedef struct lr_surface {
    lr_gpu_mesh mesh[LR_MAX_OBJECTS]; /* the object meshes unindexed with their lattices
                                       * (compose_cached.vert), drawn by lr_surface_draw */
    int base[LR_MAX_OBJECTS], nv[LR_MAX_OBJECTS];
    double h[LR_MAX_OBJECTS]; /* edge bound of each one's lattice, mm */
    int n_objects, entries, rows, n_lights;
    lr_tex *pos, *nrm; /* per entry: x (w 1: an entry), n */
    lr_tex *B;         /* 2D array, one layer per light */
    lr_fb *fb;
    bool built;        /* lattices and entries for the current geometry and settings */
    bool valid;        /* B drawn (from the maps of run `gen`) */
    unsigned gen;      /* lr_radiosity.gen it was drawn from (set by the renderer) */
} lr_surface;

void lr_surface_free(lr_surface *sc);
/* Drops the lattices (geometry, material or settings changed): rebuilt at the next run. */
void lr_surface_invalidate_geometry(lr_surface *sc);
/* Builds the lattices if needed and evaluates Algorithm 1 at every entry from rad's maps. */
int lr_surface_run(lr_surface *sc, const lr_pass_ctx *c, const lr_radiosity *rad, lr_err *e);
/* Draws object i for compose_cached.vert/.frag (glDrawArrays over its unindexed mesh). */
void lr_surface_draw(const lr_surface *sc, int object);
/* Binds the cache for compose_cached.frag (unit 11) and u_surface_row. */
void lr_surface_bind(const lr_surface *sc, lr_program *p);

#endif
