/* lamprig — translucent radiosity: the solver's private state, shared by its files. */
#ifndef LR_TR_PRIV_H
#define LR_TR_PRIV_H

#include "render/transrad/transrad.h"

typedef struct lr_tr_patch {
    lr_vec3 c, n;       /* area-weighted centroid, unit mean normal */
    double area;        /* mm^2 */
    int surface;
    size_t tri0, ntri;  /* range in lr_tr.tris (mesh kinds); plane: none */
    int cu, cv;         /* plane: the cell */
} lr_tr_patch;

typedef struct lr_tr_surf {
    lr_tr_surface_desc d;
    size_t first, count;  /* its patches */
    size_t *tri_patch;    /* mesh kinds: triangle -> patch */
    double t_hem;         /* translucent: lr_hemi_transmittance(eta) */
    lr_vec3 a, b;         /* plane: unit axes along size_u, size_v */
    int nu, nv;
    lr_mesh *own_mesh;    /* a refined copy when the given triangles exceed patch_mm */
    lr_bvh *own_bvh;
} lr_tr_surf;

/* Sparse rows: entries [row[i], row[i+1]) of col/val. */
typedef struct lr_tr_rows {
    size_t *row;
    uint32_t *col;
    float *val;  /* F: one value; S: three per entry (bands) */
} lr_tr_rows;

typedef struct lr_tr_slot {
    double *W, *Wsss, *H, *Hind; /* n x 3 */
    bool valid;
} lr_tr_slot;

/* The precomputed transfer (transfer.c): LU factors of I - K per band, row-major n x n. */
typedef struct lr_tr_transfer {
    double *lu[3];
    uint32_t *perm[3];
    bool built;
} lr_tr_transfer;

struct lr_tr {
    lr_tr_settings set;
    int nsurf;
    lr_tr_surf surf[LR_TR_MAX_SURFACES];
    size_t n;
    lr_tr_patch *p;
    size_t *tris;         /* triangles of mesh patches, grouped by patch */
    lr_tr_rows F;         /* row p: (q, F_pq) */
    double *escape;
    lr_tr_rows S;         /* column-major by source: row p lists (q, S_qp[3]) */
    double *Edir, *Ein;   /* scratch n x 3: direct irradiance, and the part that enters */
    lr_tr_slot slot[LR_TR_MAX_SLOTS];
    lr_tr_transfer X;
    bool cache_hit;       /* F and S came from the cache (cache.c) */
    /* cover.c: per patch, whether it is a plane cell that meets a covering body's bounds,
     * and its open fraction (1 elsewhere); both NULL when no surface covers. */
    unsigned char *cover_check;
    double *open;
};

/* cover.c: the open part of plane cells under closed bodies (the surfaces marked covers).
 * Builds cover_check and open (after the patches); whether point x of patch p lies inside a
 * covering body; the jitter of patch p's form-factor rays (formfactor.c's points: origins
 * u, v, directions). */
int lr_tr_build_cover(lr_tr *t, lr_err *e);
bool lr_tr_point_covered(const lr_tr *t, size_t p, lr_vec3 x);
void lr_tr_ff_jitter(const lr_tr *t, size_t p, double j[4]);

/* patches.c */
int lr_tr_build_patches(lr_tr *t, lr_err *e);
/* Point k of m spread over patch p (area-weighted, stratified); its normal. */
void lr_tr_patch_point(const lr_tr *t, size_t p, unsigned k, unsigned m, double jitter_u,
                       double jitter_v, lr_vec3 *x, lr_vec3 *n);
/* Nearest hit over every surface; *patch = SIZE_MAX for a back face (absorbed) and false
 * when nothing is hit. */
bool lr_tr_trace(const lr_tr *t, lr_vec3 o, lr_vec3 d, double tmax, size_t *patch,
                 double *dist);
bool lr_tr_occluded(const lr_tr *t, lr_vec3 o, lr_vec3 d, double tmax);
/* A ray origin just off the surface along n (scale of the scene). */
double lr_tr_eps(const lr_tr *t);

/* refine.c: a copy of surface s's mesh cut until no edge exceeds its patch size (at most
 * LR_TR_MAX_TRIANGLES triangles), so that clusters can be as small as asked. */
#define LR_TR_MAX_TRIANGLES 60000
int lr_tr_refine(lr_tr *t, int s, lr_err *e);

/* formfactor.c */
int lr_tr_build_form_factors(lr_tr *t, lr_err *e);
/* optdist.c: in-object distances from each patch of surface s to the others, n_s x n_s
 * (row-major, caller frees); INFINITY where not connected through material. */
int lr_tr_optical_distances(const lr_tr *t, int s, double **out, lr_err *e);
/* subsurface.c */
int lr_tr_build_subsurface(lr_tr *t, lr_err *e);
/* thinwall.c: the slab's lateral spread, R (which 0) and T (which 1) per band: its plane
 * totals (lr_multipole_total) and the radial CDFs int_0^r 2 pi r' P(r') dr' / total on a grid
 * of LR_TR_SPREAD_RADII radii; the radius where band b's CDF reaches u (linear between grid
 * points); r90 the largest radius holding 90 % of either profile in any band. */
#define LR_TR_SPREAD_RADII 96
typedef struct lr_tr_spread {
    double total[2][3];
    double r[LR_TR_SPREAD_RADII];
    double cdf[2][3][LR_TR_SPREAD_RADII];
    double L; /* d + 2 z_b */
} lr_tr_spread;
void lr_tr_spread_build(const lr_coeffs *c, double d, lr_tr_spread *sp);
double lr_tr_spread_radius(const lr_tr_spread *sp, int which, int band, double u);
double lr_tr_spread_r90(const lr_tr_spread *sp);
/* Column i (patch index within translucent surface s, slab thickness d, sp its spread) of a
 * thin wall's S: out[3 j + b] = S_{j i}, j over the surface's patches (n_s x 3, overwritten). */
void lr_tr_thin_column(const lr_tr *t, int s, size_t i, double d, const lr_tr_spread *sp,
                       double *out);
/* direct.c: E and Ein of one light at unit intensity (area lights: direct_area.c). */
/* Frees the per-patch row lists that F and S are built from before they are packed into their
 * CSR arrays (formfactor.c, subsurface.c); any of the three may be NULL. */
void lr_tr_row_lists_free(size_t n, uint32_t **cols, float **vals, size_t *counts);
/* The irradiance of one light at point k (x, normal n) of patch p, unit intensity: all of it
 * (*e) and the part that enters a translucent patch (*ein; eta its index). */
typedef void (*lr_tr_point_irradiance)(const void *ctx, size_t p, unsigned k, lr_vec3 x,
                                       lr_vec3 n, bool trans, double eta, double *e,
                                       double *ein);
/* Patch p's Edir and Ein, all bands: the mean of POINT over its direct_samples points
 * (direct.c; the point and the area lights' per-patch loop). */
void lr_tr_direct_patch(lr_tr *t, size_t p, lr_tr_point_irradiance point, const void *ctx);
int lr_tr_direct(lr_tr *t, const lr_light *light, lr_err *e);
/* direct_area.c: the same for a quad or disk light at unit radiance; LR_EINVAL for a
 * degenerate emitter. */
int lr_tr_direct_area(lr_tr *t, const lr_light *light, lr_err *e);

/* transfer.c: bytes the transfer of n patches takes; build it when within the settings'
 * budget (else nothing); the solve of slot sl's W, Wsss, H, Hind by it (stats: 0 sweeps, the
 * residual of the fixed point). */
size_t lr_tr_transfer_need(size_t n);
int lr_tr_transfer_build(lr_tr *t, lr_err *e);
void lr_tr_transfer_free(lr_tr_transfer *x);
int lr_tr_transfer_solve(lr_tr *t, lr_tr_slot *sl, lr_tr_stats *st, lr_err *e);

/* cache.c: the key of t's F and S (patches built), the file of a key, loading it into t (false,
 * t untouched, when missing or not valid) and storing t's. */
uint64_t lr_tr_cache_key(const lr_tr *t);
int lr_tr_cache_path(const char *dir, uint64_t key, char *out, size_t cap);
bool lr_tr_cache_load(lr_tr *t, uint64_t key, const char *dir);
int lr_tr_cache_store(const lr_tr *t, uint64_t key, const char *dir, lr_err *e);

void lr_tr_rows_free(lr_tr_rows *r);

#endif
