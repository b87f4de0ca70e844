/* lamprig — translucent radiosity: an on-disk cache of the precomputation (F, its escapes, S),
 * the part of lr_tr_create that takes tens of seconds (the lamp shade: 41 s on the loaded
 * 2-core machine) and depends only on the geometry, the materials and the patch settings.
 *
 * File: <dir>/transrad-<key>.bin, key = 64-bit FNV-1a (render/reference's hasher) over a format
 * tag, the settings that shape F and S (patch_mm, receiver_mm, rays_per_patch, seed,
 * thin_wall), every surface's description (kind, albedo, scattering coefficients, model, thickness, plane
 * frame, cells), its mesh's vertices and triangles, and the patches built from them (centroid,
 * normal, area, surface). Layout: the magic "LRTRC001", key, n, nnz(F), nnz(S), a hash of the
 * payload, then F's row starts, columns, values, the escapes, S's row starts, columns, values.
 * Written whole through render/base/atomic_file (a temp file renamed over), so a reader sees
 * the old file or the new one. Read back only when everything checks: magic, key, sizes to the
 * byte, the payload hash, rows monotonic and ending at nnz, columns < n, values finite; else
 * it is ignored, rebuilt and overwritten (a truncated or corrupt file costs a rebuild, never a
 * wrong answer). Bump the tag when F or S change meaning. */
#include "render/transrad/tr_priv.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "render/base/atomic_file.h"
#include "render/base/file.h"
#include "render/reference/reference.h"

#define MAGIC "LRTRC001"
#define HEADER_WORDS 6 /* key, n, nnzF, nnzS, payload hash; after the 8-byte magic */

uint64_t lr_tr_cache_key(const lr_tr *t)
{
    lr_ref_hash h;
    lr_ref_hash_init(&h);
    /* v2: thin walls' S columns (thinwall.c) */
    lr_ref_hash_str(&h, "lamprig transrad F S v3");
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

/* The payload's pieces in file order. */
typedef struct piece {
    void *p;
    size_t bytes;
} piece;

static void pieces(size_t n, size_t nf, size_t ns, piece out[7])
{
    out[0] = (piece){NULL, (n + 1) * sizeof(size_t)};
    out[1] = (piece){NULL, nf * sizeof(uint32_t)};
    out[2] = (piece){NULL, nf * sizeof(float)};
    out[3] = (piece){NULL, n * sizeof(double)};
    out[4] = (piece){NULL, (n + 1) * sizeof(size_t)};
    out[5] = (piece){NULL, ns * sizeof(uint32_t)};
    out[6] = (piece){NULL, 3 * ns * sizeof(float)};
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
    size_t n = t->n, nf = t->F.row[n], ns = t->S.row[n];
    piece pc[7];
    pieces(n, nf, ns, pc);
    pc[0].p = t->F.row;
    pc[1].p = t->F.col;
    pc[2].p = t->F.val;
    pc[3].p = t->escape;
    pc[4].p = t->S.row;
    pc[5].p = t->S.col;
    pc[6].p = t->S.val;
    size_t head = 8 + HEADER_WORDS * sizeof(uint64_t), len = head;
    for (int i = 0; i < 7; i++)
        len += pc[i].bytes;
    unsigned char *buf = malloc(len);
    if (!buf)
        return lr_err_set(e, LR_ENOMEM, "transrad cache: out of memory (%zu bytes)", len);
    size_t off = head;
    for (int i = 0; i < 7; i++) {
        if (pc[i].bytes)
            memcpy(buf + off, pc[i].p, pc[i].bytes);
        off += pc[i].bytes;
    }
    uint64_t w[HEADER_WORDS] = {key, n, nf, ns, lr_ref_hash_of(buf + head, len - head), 0};
    memcpy(buf, MAGIC, 8);
    memcpy(buf + 8, w, sizeof w);
    int rc = lr_atomic_write(path, buf, len, e);
    free(buf);
    return rc;
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

bool lr_tr_cache_load(lr_tr *t, uint64_t key, const char *dir)
{
    char path[1024], *data = NULL;
    size_t len = 0;
    lr_err e = {0};
    if (lr_tr_cache_path(dir, key, path, sizeof path) || lr_file_read(path, &data, &len, &e))
        return false;
    size_t head = 8 + HEADER_WORDS * sizeof(uint64_t), n = t->n;
    uint64_t w[HEADER_WORDS];
    bool ok = len >= head && !memcmp(data, MAGIC, 8);
    if (ok) {
        memcpy(w, data + 8, sizeof w);
        ok = w[0] == key && w[1] == n && w[2] <= (uint64_t)n * n && w[3] <= (uint64_t)n * n;
    }
    piece pc[7];
    size_t want = head;
    if (ok) {
        pieces(n, (size_t)w[2], (size_t)w[3], pc);
        for (int i = 0; i < 7; i++)
            want += pc[i].bytes;
        ok = len == want && lr_ref_hash_of((unsigned char *)data + head, len - head) == w[4];
    }
    lr_tr_rows F = {0}, S = {0};
    double *escape = NULL;
    if (ok) {
        size_t nf = (size_t)w[2], ns = (size_t)w[3];
        F.row = malloc(pc[0].bytes);
        F.col = malloc(pc[1].bytes ? pc[1].bytes : 1);
        F.val = malloc(pc[2].bytes ? pc[2].bytes : 1);
        escape = malloc(pc[3].bytes ? pc[3].bytes : 1);
        S.row = malloc(pc[4].bytes);
        S.col = malloc(pc[5].bytes ? pc[5].bytes : 1);
        S.val = malloc(pc[6].bytes ? pc[6].bytes : 1);
        void *dst[7] = {F.row, F.col, F.val, escape, S.row, S.col, S.val};
        ok = F.row && F.col && F.val && escape && S.row && S.col && S.val;
        size_t off = head;
        for (int i = 0; ok && i < 7; i++) {
            memcpy(dst[i], data + off, pc[i].bytes);
            off += pc[i].bytes;
        }
        ok = ok && rows_ok(F.row, n, nf, F.col) && rows_ok(S.row, n, ns, S.col) &&
             finite_f(F.val, nf) && finite_f(S.val, 3 * ns);
        for (size_t p = 0; ok && p < n; p++)
            ok = isfinite(escape[p]) && escape[p] >= 0 && escape[p] <= 1;
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
