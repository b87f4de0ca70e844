/* lamprig — translucent radiosity: an on-disk cache of the precomputation (F, its escapes, S),
 * the part of lr_tr_create that takes tens of seconds (the lamp shade: 41 s on the loaded
 * 2-core machine) and depends only on the geometry, the materials and the patch settings.
 *
 * File: <dir>/transrad-<key>.bin, key = 64-bit FNV-1a (render/reference's hasher) over a format
 * tag, the settings that shape F and S (patch_mm, receiver_mm, rays_per_patch, seed,
 * thin_wall), every surface's description (kind, albedo, scattering coefficients, model, thickness, plane
 * frame, cells), its mesh's vertices and triangles, and the patches built from them (centroid,
 * normal, area, surface). Layout (render/reference/cache_file.h: magic, header words, payload
 * hash, payload; written atomically): the magic "LRTRC002", key, n, nnz(F), nnz(S), then F's
 * row starts, columns, values, the escapes, S's row starts, columns, values. Read back only
 * when everything checks: magic, key, sizes to the byte, the payload hash, rows monotonic and
 * ending at nnz, columns < n, values finite; else
 * it is ignored, rebuilt and overwritten (a truncated or corrupt file costs a rebuild, never a
 * wrong answer). Bump the tag when F or S change meaning. */
#include "render/transrad/tr_priv.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/file.h"
#include "render/reference/cache_file.h"
#include "render/reference/reference.h"

#define MAGIC "LRTRC002"
#define HEADER_WORDS 4 /* key, n, nnzF, nnzS (render/reference/cache_file.h adds the hash) */

uint64_t lr_tr_cache_key(const lr_tr *t)
{
    lr_ref_hash h;
    lr_ref_hash_init(&h);
    /* v2: thin walls' S columns (thinwall.c) */
    /* v6: rows of plane cells over their open part (cover.c) */
    lr_ref_hash_str(&h, "lamprig transrad F S v6");
    /* The file holds native size_t, float and byte order: another machine is another key. */
    const uint32_t order = 0x01020304u;
    lr_ref_hash_u64(&h, sizeof(size_t));
    lr_ref_hash_bytes(&h, &order, sizeof order);
    lr_ref_hash_double(&h, t->set.patch_mm);
    lr_ref_hash_double(&h, t->set.receiver_mm);
    lr_ref_hash_u64(&h, (uint64_t)t->set.rays_per_patch);
    lr_ref_hash_u64(&h, t->set.seed);
    lr_ref_hash_u64(&h, (uint64_t)t->set.thin_wall);
    lr_ref_hash_u64(&h, (uint64_t)t->nsurf);
    for (int s = 0; s < t->nsurf; s++) {
        const lr_tr_surface_desc *d = &t->surf[s].d;
        lr_ref_hash_u64(&h, (uint64_t)d->kind);
        lr_ref_hash_u64(&h, (uint64_t)d->covers);
        for (int b = 0; b < 3; b++)
            lr_ref_hash_double(&h, d->albedo[b]);
        if (d->kind == LR_TR_TRANSLUCENT) {
            const lr_coeffs *c = d->coeffs;
            for (int b = 0; b < 3; b++) {
                lr_ref_hash_double(&h, c->sigma_t_prime[b]);
                lr_ref_hash_double(&h, c->albedo_prime[b]);
                lr_ref_hash_double(&h, c->sigma_tr[b]);
                lr_ref_hash_double(&h, c->D[b]);
                lr_ref_hash_double(&h, c->sd_norm[b]);
            }
            lr_ref_hash_double(&h, c->eta);
            lr_ref_hash_double(&h, c->A);
            lr_ref_hash_u64(&h, (uint64_t)d->model);
            lr_ref_hash_double(&h, d->thickness_mm);
        }
        lr_ref_hash_vec3(&h, d->center);
        lr_ref_hash_vec3(&h, d->normal);
        lr_ref_hash_vec3(&h, d->u_dir);
        lr_ref_hash_double(&h, d->size_u);
        lr_ref_hash_double(&h, d->size_v);
        lr_ref_hash_u64(&h, (uint64_t)d->cells_u);
        lr_ref_hash_u64(&h, (uint64_t)d->cells_v);
        lr_ref_hash_double(&h, d->patch_mm);
        size_t nv = lr_mesh_vertex_count(d->mesh), nt = lr_mesh_triangle_count(d->mesh);
        lr_ref_hash_u64(&h, nv);
        lr_ref_hash_u64(&h, nt);
        lr_ref_hash_bytes(&h, lr_mesh_positions(d->mesh), 3 * nv * sizeof(float));
        lr_ref_hash_bytes(&h, lr_mesh_indices(d->mesh), 3 * nt * sizeof(uint32_t));
    }
    lr_ref_hash_u64(&h, t->n);
    for (size_t p = 0; p < t->n; p++) {
        lr_ref_hash_vec3(&h, t->p[p].c);
        lr_ref_hash_vec3(&h, t->p[p].n);
        lr_ref_hash_double(&h, t->p[p].area);
        lr_ref_hash_u64(&h, (uint64_t)t->p[p].surface);
    }
    return h.h;
}

uint64_t lr_tr_geometry_key(const lr_tr *t) { return lr_tr_cache_key(t); }

int lr_tr_cache_path(const char *dir, uint64_t key, char *out, size_t cap)
{
    int k = snprintf(out, cap, "%s/transrad-%016llx.bin", dir, (unsigned long long)key);
    return k > 0 && (size_t)k < cap ? 0 : -1;
}

/* The payload's sizes in file order: F's row starts, columns, values, the escapes, S's row
 * starts, columns, values. */
static void piece_sizes(size_t n, size_t nf, size_t ns, size_t out[7])
{
    out[0] = (n + 1) * sizeof(size_t);
    out[1] = nf * sizeof(uint32_t);
    out[2] = nf * sizeof(float);
    out[3] = n * sizeof(double);
    out[4] = (n + 1) * sizeof(size_t);
    out[5] = ns * sizeof(uint32_t);
    out[6] = 3 * ns * sizeof(float);
}

int lr_tr_cache_store(const lr_tr *t, uint64_t key, const char *dir, lr_err *e)
{
    /* The folder and its parent (~/.cache may not exist yet). */
    int rc0 = lr_dir_make(dir, "transrad cache", e);
    if (rc0)
        return rc0;
    char path[1024];
    if (lr_tr_cache_path(dir, key, path, sizeof path))
        return lr_err_set(e, LR_EINVAL, "transrad cache: field 'dir': path too long");
    size_t n = t->n, nf = t->F.row[n], ns = t->S.row[n], b[7];
    piece_sizes(n, nf, ns, b);
    const void *src[7] = {t->F.row, t->F.col, t->F.val, t->escape, t->S.row, t->S.col, t->S.val};
    lr_cache_piece pc[7];
    for (int i = 0; i < 7; i++)
        pc[i] = (lr_cache_piece){src[i], b[i]};
    uint64_t w[HEADER_WORDS] = {key, n, nf, ns};
    return lr_cache_file_write(path, MAGIC, w, HEADER_WORDS, pc, 7, "transrad cache", e);
}

static bool rows_ok(const size_t *row, size_t n, size_t nnz, const uint32_t *col)
{
    if (row[0] != 0 || row[n] != nnz)
        return false;
    for (size_t i = 0; i < n; i++)
        if (row[i + 1] < row[i])
            return false;
    for (size_t k = 0; k < nnz; k++)
        if (col[k] >= n)
            return false;
    return true;
}

static bool finite_f(const float *v, size_t m)
{
    for (size_t i = 0; i < m; i++)
        if (!isfinite(v[i]) || v[i] < 0)
            return false;
    return true;
}

/* Physics a valid file cannot break, whatever wrote it (a hash only says the bytes are the
 * writer's): F's row p is the fraction of p's hemisphere landing on each patch, so with the
 * escaping fraction it sums to at most 1; S's column p (source p, listed in row p) conserves
 * energy, sum_q A_q S_qp <= A_p per band (subsurface.c: the column is scaled to the slab's
 * R + T <= 1). PLAUSIBLE_TOL covers the float rounding of those sums (measured on the shipped
 * candle and lamp shade: F 1 + 2e-8, S 0.95). */
#define PLAUSIBLE_TOL 1e-3
static bool plausible(const lr_tr *t, const lr_tr_rows *F, const lr_tr_rows *S,
                      const double *escape)
{
    for (size_t p = 0; p < t->n; p++) {
        double f = escape[p];
        for (size_t k = F->row[p]; k < F->row[p + 1]; k++)
            f += F->val[k];
        if (!(f <= 1 + PLAUSIBLE_TOL))
            return false;
        double out[3] = {0, 0, 0};
        for (size_t k = S->row[p]; k < S->row[p + 1]; k++)
            for (int c = 0; c < 3; c++)
                out[c] += t->p[S->col[k]].area * S->val[3 * k + c];
        for (int c = 0; c < 3; c++)
            if (!(out[c] <= (1 + PLAUSIBLE_TOL) * t->p[p].area))
                return false;
    }
    return true;
}

bool lr_tr_cache_load(lr_tr *t, uint64_t key, const char *dir)
{
    char path[1024], *data = NULL;
    const unsigned char *payload = NULL;
    size_t len = 0, n = t->n;
    uint64_t w[HEADER_WORDS];
    if (lr_tr_cache_path(dir, key, path, sizeof path) ||
        !lr_cache_file_read(path, MAGIC, w, HEADER_WORDS, &data, &payload, &len))
        return false;
    bool ok = w[0] == key && w[1] == n && w[2] <= (uint64_t)n * n && w[3] <= (uint64_t)n * n;
    size_t b[7], want = 0;
    if (ok) {
        piece_sizes(n, (size_t)w[2], (size_t)w[3], b);
        for (int i = 0; i < 7; i++)
            want += b[i];
        ok = len == want;
    }
    lr_tr_rows F = {0}, S = {0};
    double *escape = NULL;
    if (ok) {
        size_t nf = (size_t)w[2], ns = (size_t)w[3];
        F.row = malloc(b[0]);
        F.col = malloc(b[1] ? b[1] : 1);
        F.val = malloc(b[2] ? b[2] : 1);
        escape = malloc(b[3] ? b[3] : 1);
        S.row = malloc(b[4]);
        S.col = malloc(b[5] ? b[5] : 1);
        S.val = malloc(b[6] ? b[6] : 1);
        void *dst[7] = {F.row, F.col, F.val, escape, S.row, S.col, S.val};
        ok = F.row && F.col && F.val && escape && S.row && S.col && S.val;
        size_t off = 0;
        for (int i = 0; ok && i < 7; i++) {
            memcpy(dst[i], payload + off, b[i]);
            off += b[i];
        }
        ok = ok && rows_ok(F.row, n, nf, F.col) && rows_ok(S.row, n, ns, S.col) &&
             finite_f(F.val, nf) && finite_f(S.val, 3 * ns);
        for (size_t p = 0; ok && p < n; p++)
            ok = isfinite(escape[p]) && escape[p] >= 0 && escape[p] <= 1;
        ok = ok && plausible(t, &F, &S, escape);
    }
    free(data);
    if (!ok) {
        lr_tr_rows_free(&F);
        lr_tr_rows_free(&S);
        free(escape);
        return false;
    }
    lr_tr_rows_free(&t->F);
    lr_tr_rows_free(&t->S);
    free(t->escape);
    t->F = F;
    t->S = S;
    t->escape = escape;
    return true;
}

const char *lr_tr_cache_default_dir(char *buf, size_t cap)
{
    const char *x = getenv("XDG_CACHE_HOME"), *home = getenv("HOME");
    int k;
    if (x && x[0] == '/')
        k = snprintf(buf, cap, "%s/lamprig", x);
    else if (home && home[0] == '/')
        k = snprintf(buf, cap, "%s/.cache/lamprig", home);
    else
        return NULL;
    return k > 0 && (size_t)k < cap ? buf : NULL;
}
