/* lamprig — the receivers' light on the objects: the struct shared by objlight.c (the rows'
 * build and evaluation) and objlight_cache.c (the rows on disk). Not for other modules. */
#ifndef LR_OBJLIGHT_PRIV_H
#define LR_OBJLIGHT_PRIV_H

#include <stdint.h>

#include "render/bounce/objlight.h"

/* Sparse rows: entries [row[k], row[k + 1]) of col / val, k = 2 v + side. */
typedef struct ol_mesh {
    lr_objlight_desc d;
    size_t nv;
    size_t *row;
    uint32_t *col;
    float *val;
    /* Closed walls: per vertex the far face's triangle (SIZE_MAX: none) and barycentrics. */
    size_t *far_tri;
    float *far_uv;
    float *E[LR_TR_MAX_SLOTS]; /* nv x 6 */
} ol_mesh;

struct lr_objlight {
    int count;
    ol_mesh m[LR_TR_MAX_SURFACES];
    size_t first_source, n_patches;
    double *W; /* n_patches x 3 scratch */
    double build_s;
    bool cache_hit; /* the rows came from the on-disk cache (objlight_cache.c) */
};

/* The cache key of ol's rows (its meshes' descriptions set, before any row is built): the
 * solver's geometry key, first_source, rays and every mesh's vertices, normals, triangles,
 * two_sided and far_mm. */
uint64_t lr_objlight_cache_key(const lr_objlight *ol, const lr_tr *t, int rays);
/* Fills every mesh's rows (and far faces) from <dir>/objlight-<key>.bin when it exists and
 * checks to the byte; false (nothing changed) otherwise. */
bool lr_objlight_cache_load(lr_objlight *ol, uint64_t key, const char *dir);
/* Writes them atomically (temp file + rename). */
int lr_objlight_cache_store(const lr_objlight *ol, uint64_t key, const char *dir, lr_err *e);

#endif
