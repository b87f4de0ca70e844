/* lamprig — translucent radiosity: the subsurface-scattering matrix S of each object.
 *
 * S_ji, the radiosity leaving patch j per unit irradiance entering patch i (seed 000 Eq. 8 with
 * the isotropic multiple-scattering profile of Eq. 9-10):
 *
 *     S_ji = int_{A_i} Rd(x, c_j) dA(x),
 *
 * with the exit point fixed at j's centroid and the entry integrated over i with many points
 * when i is near j, one (the centroid) when far (seed 000 Sec. 4.1: "we simplify the double
 * integral to a single integral by fixing the exiting point to be the centroid ... the number
 * of points ... reduces as the distance increases"). The profile:
 *   a slab of thickness d (the object's thickness_mm; for translucent_radiosity without one,
 *     the wall measured under each patch, d = the mean of i's and j's, local_thickness): the
 *     multipole's transmittance T(r_perp) when i and j face opposite ways (entry and exit on
 *     the two faces of a wall), r_perp from j's centroid to x's projection on j's tangent
 *     plane; its reflectance R(r) on the same face. Seed 000 indexes a half-space profile by
 *     distance and notes that thin regions come out too dark (Sec. 6); the slab keeps the light
 *     that crosses a wall (issue 12);
 *   a half-space (other models, or walls beyond 10 diffusion lengths): the standard dipole
 *     Rd(r) (Jensen 2001; the directional dipole's S_d needs an incident direction that
 *     diffuse patch-to-patch light does not have, and it is normalised to Rd's total anyway).
 * Distances are in-object (optdist.c): a pair not joined through material within the cut-off
 * gets nothing, and a detour adds its excess to r.
 *
 * Energy. The discrete sum over patches misses or double counts the profile's peak when the
 * patches are coarse against 1/sigma_tr, so each column is scaled so that the power leaving
 * all patches, sum_j A_j S_ji / A_i, equals the plane total of i's profile (R + T of its slab,
 * Rd's total for a half-space; 1 without absorption).
 *
 * Thin walls. Where the slab's profiles are narrow against the entry points' spacing the sums
 * see only their tails and split the light evenly between the faces; those columns are built
 * by thinwall.c instead (the slab's R_tot out of the lit face, T_tot out of the far one),
 * chosen per patch by lr_tr_wall_thin (or lr_tr_settings.thin_wall). */
#include "render/transrad/tr_priv.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/parallel.h"

#define SS_NEAR_POINTS 256
#define SS_DROP 1e-7

typedef struct ss_ctx {
    lr_tr *t;
    int s;
    const double *dist; /* ns x ns */
    uint32_t **cols;
    float **vals;
    size_t *counts;
    double *thick;      /* per patch of the surface: the wall's local thickness, 0: none */
    /* Per patch: index into spreads of its thin wall's column (thinwall.c), -1: not thin.
     * One spread per distinct thickness, shared by the patches that have it. */
    int *thin;
    lr_tr_spread *spreads;
    int failed;
} ss_ctx;

static void kernel(const lr_tr_surf *sf, double d, lr_vec3 x, lr_vec3 ni, const lr_tr_patch *pj,
                   double excess, double out[3])
{
    lr_vec3 r = lr_v3_sub(pj->c, x);
    if (d > 0) {
        double R[3], T[3];
        if (lr_v3_dot(ni, pj->n) < 0) {
            double along = lr_v3_dot(r, pj->n);
            double perp = sqrt(fmax(0.0, lr_v3_dot(r, r) - along * along));
            lr_multipole_profile(sf->d.coeffs, d, perp + excess, R, T);
            memcpy(out, T, sizeof T);
        } else {
            lr_multipole_profile(sf->d.coeffs, d, lr_v3_len(r) + excess, R, T);
            memcpy(out, R, sizeof R);
        }
        return;
    }
    lr_dipole_rd(sf->d.coeffs, lr_v3_len(r) + excess, out);
}

static void ss_item(void *vctx, long item)
{
    ss_ctx *c = vctx;
    lr_tr *t = c->t;
    const lr_tr_surf *sf = &t->surf[c->s];
    size_t ns = sf->count, i = (size_t)item, pi = sf->first + i;
    const lr_tr_patch *P = t->p;
    double *col = malloc(ns * 3 * sizeof *col);
    if (!col) {
        c->failed = 1;
        return;
    }
    double sum[3] = {0, 0, 0};
    double ri = sqrt(P[pi].area / M_PI);
    bool thin = c->thin && c->thin[i] >= 0;
    if (thin)
        lr_tr_thin_column(t, c->s, i, c->thick[i], &c->spreads[c->thin[i]], col);
    for (size_t j = 0; j < ns && !thin; j++) {
        double dopt = c->dist[i * ns + j];
        double *o = col + 3 * j;
        o[0] = o[1] = o[2] = 0;
        if (!isfinite(dopt))
            continue;
        size_t pj = sf->first + j;
        double straight = lr_v3_len(lr_v3_sub(P[pj].c, P[pi].c));
        double excess = fmax(0.0, dopt - straight);
        /* The slab between the two faces: the wall's thickness at source and exit. */
        double d = c->thick ? 0.5 * (c->thick[i] + c->thick[j]) : 0.0;
        /* Near: within a few patch radii (a wall's T spreads over about its thickness, but
         * a thick wall's is smooth over a patch: the centroid does). */
        if (straight > 2.5 * ri + 2.5 * fmin(d, ri)) {
            kernel(sf, d, P[pi].c, P[pi].n, &P[pj], excess, o);
            for (int b = 0; b < 3; b++)
                o[b] *= P[pi].area;
        } else {
            for (unsigned k = 0; k < SS_NEAR_POINTS; k++) {
                lr_vec3 x, n;
                double v[3];
                lr_tr_patch_point(t, pi, k, SS_NEAR_POINTS, 0.5, 0.5, &x, &n);
                kernel(sf, d, x, n, &P[pj], excess, v);
                for (int b = 0; b < 3; b++)
                    o[b] += v[b];
            }
            for (int b = 0; b < 3; b++)
                o[b] *= P[pi].area / SS_NEAR_POINTS;
        }
        for (int b = 0; b < 3; b++)
            sum[b] += P[pj].area * o[b] / P[pi].area;
    }
    double scale[3], total[3];
    if (c->thick && c->thick[i] > 0) {
        double R[3], T[3];
        lr_multipole_total(sf->d.coeffs, c->thick[i], R, T);
        for (int b = 0; b < 3; b++)
            total[b] = R[b] + T[b];
    } else {
        lr_dipole_rd_total(sf->d.coeffs, total);
    }
    for (int b = 0; b < 3; b++)
        scale[b] = thin ? 1.0 : sum[b] > 0 ? total[b] / sum[b] : 0;
    size_t keep = 0;
    for (size_t j = 0; j < ns; j++) {
        double m = 0;
        for (int b = 0; b < 3; b++) {
            col[3 * j + b] *= scale[b];
            m = fmax(m, P[sf->first + j].area * col[3 * j + b] / P[pi].area);
        }
        if (m > SS_DROP)
            keep++;
    }
    c->cols[pi] = malloc((keep ? keep : 1) * sizeof **c->cols);
    c->vals[pi] = malloc((keep ? keep : 1) * 3 * sizeof **c->vals);
    if (!c->cols[pi] || !c->vals[pi]) {
        c->failed = 1;
        free(col);
        return;
    }
    size_t w = 0;
    for (size_t j = 0; j < ns; j++) {
        double m = 0;
        for (int b = 0; b < 3; b++)
            m = fmax(m, P[sf->first + j].area * col[3 * j + b] / P[pi].area);
        if (!(m > SS_DROP))
            continue;
        c->cols[pi][w] = (uint32_t)(sf->first + j);
        for (int b = 0; b < 3; b++)
            c->vals[pi][3 * w + (size_t)b] = (float)col[3 * j + b];
        w++;
    }
    c->counts[pi] = w;
    free(col);
}

#define TH_POINTS 16

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The wall's thickness under each patch: the multipole's slab (seed 000 indexes a half-space
 * profile by distance, which misses light that crosses a wall: issue 12 measures 3x). Given
 * ("thickness_mm" with the multipole or translucent radiosity): that value everywhere. Not
 * given, for translucent_radiosity: measured, the median over 16 points on the patch of the
 * distance along -n to where the ray leaves the material; beyond 10 diffusion lengths the
 * wall is a half-space (0: the standard dipole). Other models: none (their half-space
 * profile). */
static int local_thickness(const lr_tr *t, int s, double **out, lr_err *e)
{
    const lr_tr_surf *sf = &t->surf[s];
    *out = NULL;
    const lr_sss_model_props *p = lr_sss_model_props_of(sf->d.model);
    bool slab = p->slab || p->measures_thickness;
    if (!slab)
        return LR_OK;
    double *th = calloc(sf->count ? sf->count : 1, sizeof *th);
    if (!th)
        return lr_err_set(e, LR_ENOMEM, "transrad: surface %d: out of memory (thickness)", s);
    double str = INFINITY;
    for (int b = 0; b < 3; b++)
        str = fmin(str, sf->d.coeffs->sigma_tr[b]);
    double eps = lr_tr_eps(t);
    for (size_t i = 0; i < sf->count; i++) {
        if (sf->d.thickness_mm > 0) {
            th[i] = sf->d.thickness_mm;
            continue;
        }
        if (!p->measures_thickness)
            continue;
        /* From points on the surface, not the centroid: a patch is a cluster of triangles,
         * and on a curved face its centroid lies off the surface (a candle's melt-pool dish:
         * 0.03-0.2 mm above it, in the air, so the ray measured the air gap down to the wax
         * and the pool floor became a 0.1 mm "wall", thin by lr_tr_wall_thin: its light
         * stayed in the entry patch, and without the thin-wall rule the centroid sums of
         * that narrow profile pushed 64 % of it onto the outer wall). The median over the
         * patch's points ignores the few that graze an edge. */
        double dk[TH_POINTS];
        int nk = 0;
        for (unsigned k = 0; k < TH_POINTS; k++) {
            lr_vec3 x, n;
            lr_tr_patch_point(t, sf->first + i, k, TH_POINTS, 0.5, 0.5, &x, &n);
            lr_vec3 in = lr_v3_scale(n, -1);
            lr_hit h;
            if (lr_bvh_intersect(sf->d.bvh, lr_v3_add(x, lr_v3_scale(in, eps)), in, 0.0,
                                 INFINITY, &h))
                dk[nk++] = h.t + eps;
        }
        if (nk > 0) {
            qsort(dk, (size_t)nk, sizeof *dk, cmp_double);
            double d = nk % 2 ? dk[nk / 2] : 0.5 * (dk[nk / 2 - 1] + dk[nk / 2]);
            th[i] = str > 0 && d * str > 10 ? 0 : fmax(d, LR_MULTIPOLE_D_MIN);
        }
    }
    *out = th;
    return LR_OK;
}

/* Which columns of surface s are a thin wall's (thinwall.c): by the rule lr_tr_wall_thin on
 * each patch's slab (auto), none (off) or every slab patch (on). Each distinct thickness's
 * spread is built once (a run of equal thicknesses, as an object's thickness_mm gives, shares
 * it) and kept for the columns. *out NULL: none. */
static int thin_columns(const lr_tr *t, int s, const double *thick, int **out,
                        lr_tr_spread **spreads, lr_err *e)
{
    const lr_tr_surf *sf = &t->surf[s];
    *out = NULL;
    *spreads = NULL;
    if (!thick || t->set.thin_wall == LR_TR_THIN_OFF)
        return LR_OK;
    size_t n = sf->count ? sf->count : 1, used = 0, cap = 0;
    int *th = malloc(n * sizeof *th);
    lr_tr_spread *sp = NULL;
    if (!th)
        goto oom;
    double h = sf->d.patch_mm > 0 ? sf->d.patch_mm : t->set.patch_mm;
    double last_d = -1;
    int last = -1;
    for (size_t i = 0; i < sf->count; i++) {
        th[i] = -1;
        if (!(thick[i] > 0))
            continue;
        if (thick[i] != last_d) { /* a new thickness: one evaluation of the rule, and a
                                    * spread where it is thin */
            last_d = thick[i];
            last = -1;
            if (t->set.thin_wall == LR_TR_THIN_ON || lr_tr_wall_thin(sf->d.coeffs, last_d, h)) {
                if (used == cap) {
                    size_t ncap = cap ? 2 * cap : 4;
                    lr_tr_spread *g = realloc(sp, ncap * sizeof *g);
                    if (!g)
                        goto oom;
                    sp = g;
                    cap = ncap;
                }
                lr_tr_spread_build(sf->d.coeffs, last_d, &sp[used]);
                last = (int)used++;
            }
        }
        th[i] = last;
    }
    *out = th;
    *spreads = sp;
    return LR_OK;
oom:
    free(th);
    free(sp);
    return lr_err_set(e, LR_ENOMEM, "transrad: surface %d: out of memory (thin walls)", s);
}

int lr_tr_build_subsurface(lr_tr *t, lr_err *e)
{
    size_t n = t->n;
    ss_ctx c = {.t = t};
    c.cols = calloc(n, sizeof *c.cols);
    c.vals = calloc(n, sizeof *c.vals);
    c.counts = calloc(n, sizeof *c.counts);
    t->S.row = calloc(n + 1, sizeof *t->S.row);
    int rc = LR_OK;
    if (!c.cols || !c.vals || !c.counts || !t->S.row) {
        rc = lr_err_set(e, LR_ENOMEM, "transrad: out of memory (subsurface, %zu patches)", n);
        goto done;
    }
    for (int s = 0; s < t->nsurf; s++) {
        if (t->surf[s].d.kind != LR_TR_TRANSLUCENT)
            continue;
        double *dist = NULL;
        c.s = s;
        c.thick = NULL;
        c.thin = NULL;
        c.spreads = NULL;
        rc = local_thickness(t, s, &c.thick, e);
        if (!rc)
            rc = thin_columns(t, s, c.thick, &c.thin, &c.spreads, e);
        /* In-object distances only where a column is built from them. */
        bool need = !c.thin;
        for (size_t i = 0; c.thin && i < t->surf[s].count; i++)
            need = need || c.thin[i] < 0;
        if (!rc && need)
            rc = lr_tr_optical_distances(t, s, &dist, e);
        if (rc) {
            free(c.thick);
            free(c.thin);
            free(c.spreads);
            goto done;
        }
        c.dist = dist;
        /* Cached on disk with F: only a stop cuts it. */
        bool all = lr_parallel_for_cancel((long)t->surf[s].count, t->set.threads, ss_item,
                                              &c, t->set.cancel, LR_CANCEL_STOP);
        free(dist);
        free(c.thick);
        free(c.thin);
        free(c.spreads);
        if (!all) {
            rc = lr_cancel_check_at(t->set.cancel, LR_CANCEL_STOP, "transrad: subsurface", e);
            goto done;
        }
        if (c.failed) {
            rc = lr_err_set(e, LR_ENOMEM, "transrad: surface %d: out of memory (subsurface)", s);
            goto done;
        }
    }
    for (size_t p = 0; p < n; p++)
        t->S.row[p + 1] = t->S.row[p] + c.counts[p];
    size_t nnz = t->S.row[n];
    t->S.col = malloc((nnz ? nnz : 1) * sizeof *t->S.col);
    t->S.val = malloc((nnz ? nnz : 1) * 3 * sizeof *t->S.val);
    if (!t->S.col || !t->S.val) {
        rc = lr_err_set(e, LR_ENOMEM, "transrad: out of memory (subsurface, %zu entries)", nnz);
        goto done;
    }
    for (size_t p = 0; p < n; p++) {
        if (!c.counts[p])
            continue;
        memcpy(t->S.col + t->S.row[p], c.cols[p], c.counts[p] * sizeof *t->S.col);
        memcpy(t->S.val + 3 * t->S.row[p], c.vals[p], 3 * c.counts[p] * sizeof *t->S.val);
    }
done:
    lr_tr_row_lists_free(n, c.cols, c.vals, c.counts);
    return rc;
}

void lr_tr_subsurface(const lr_tr *t, size_t q, size_t p, double out[3])
{
    out[0] = out[1] = out[2] = 0;
    if (p >= t->n)
        return;
    for (size_t i = t->S.row[p]; i < t->S.row[p + 1]; i++)
        if (t->S.col[i] == q)
            for (int b = 0; b < 3; b++)
                out[b] = t->S.val[3 * i + (size_t)b];
}
