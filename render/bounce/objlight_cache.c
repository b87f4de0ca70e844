/* lamprig — the receivers' light on the objects: an on-disk cache of the form-factor rows
 * (objlight_priv.h), the part of lr_objlight_create that casts 512 rays from every vertex
 * (the candle 0.9 s, the lamp shade 2.4 s on the 2-core machine) and depends only on the
 * geometry: the receiver bounce's solver (its patches and surfaces, lr_tr_geometry_key) and
 * the object meshes.
 *
 * File: <dir>/objlight-<key>.bin beside translucent radiosity's F and S (render/transrad/
 * cache.c, the same rules; layout by render/reference/cache_file.h): the magic "LROLC002", the
 * key, the mesh count, per mesh its vertex count and entry count, the payload's hash, then the
 * payload: per mesh the row starts, columns, values, a far-face flag and (when set) the far
 * faces' triangles and barycentrics. Written atomically; read back only when everything checks (magic,
 * key, counts, sizes to the byte, the payload hash, rows monotonic and ending at their count,
 * columns among the source patches, values finite and >= 0, far triangles in the mesh or
 * none, barycentrics finite); else ignored and rebuilt (a truncated or corrupt file costs a
 * rebuild, never a wrong answer). Bump the tag when the rows change meaning. */
#include "render/bounce/objlight_priv.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/file.h"
#include "render/reference/cache_file.h"
#include "render/reference/reference.h"

#define MAGIC "LROLC002"

uint64_t lr_objlight_cache_key(const lr_objlight *ol, const lr_tr *t, int rays)
{
    lr_ref_hash h;
    lr_ref_hash_init(&h);
    /* v2: plane hits weighted by the cells' open fractions (render/transrad/cover.c) */
    lr_ref_hash_str(&h, "lamprig objlight rows v2");
    const uint32_t order = 0x01020304u; /* native size_t and byte order: another key */
    lr_ref_hash_u64(&h, sizeof(size_t));
    lr_ref_hash_bytes(&h, &order, sizeof order);
    lr_ref_hash_u64(&h, lr_tr_geometry_key(t));
    lr_ref_hash_u64(&h, ol->first_source);
    lr_ref_hash_u64(&h, ol->n_patches);
    lr_ref_hash_u64(&h, (uint64_t)rays);
    lr_ref_hash_u64(&h, (uint64_t)ol->count);
    for (int i = 0; i < ol->count; i++) {
        const lr_objlight_desc *d = &ol->m[i].d;
        size_t nv = lr_mesh_vertex_count(d->mesh), nt = lr_mesh_triangle_count(d->mesh);
        lr_ref_hash_u64(&h, nv);
        lr_ref_hash_u64(&h, nt);
        lr_ref_hash_bytes(&h, lr_mesh_positions(d->mesh), 3 * nv * sizeof(float));
        lr_ref_hash_bytes(&h, lr_mesh_normals(d->mesh), 3 * nv * sizeof(float));
        lr_ref_hash_bytes(&h, lr_mesh_indices(d->mesh), 3 * nt * sizeof(uint32_t));
        lr_ref_hash_u64(&h, (uint64_t)d->two_sided);
        lr_ref_hash_double(&h, d->far_mm);
    }
    return h.h;
}

static int cache_path(const char *dir, uint64_t key, char *out, size_t cap)
{
    int k = snprintf(out, cap, "%s/objlight-%016llx.bin", dir, (unsigned long long)key);
    return k > 0 && (size_t)k < cap ? 0 : -1;
}


/* Bytes of mesh i's payload with nv vertices, nnz entries and (has_far) far faces. */
static size_t mesh_bytes(size_t nv, size_t nnz, bool has_far)
{
    size_t b = (2 * nv + 1) * sizeof(size_t) + nnz * (sizeof(uint32_t) + sizeof(float)) +
               sizeof(uint64_t);
    if (has_far)
        b += nv * sizeof(size_t) + 2 * nv * sizeof(float);
    return b;
}

/* Header words: key, count, then (nv, nnz) per mesh (render/reference/cache_file.h adds the
 * magic and the payload hash). */
static int header_words(int count) { return 2 + 2 * count; }

int lr_objlight_cache_store(const lr_objlight *ol, uint64_t key, const char *dir, lr_err *e)
{
    int rc0 = lr_dir_make(dir, "objects' light cache", e);
    if (rc0)
        return rc0;
    char path[1024];
    if (cache_path(dir, key, path, sizeof path))
        return lr_err_set(e, LR_EINVAL, "objects' light cache: field 'dir': path too long");
    if (ol->count > LR_TR_MAX_SURFACES)
        return lr_err_set(e, LR_EINVAL, "objects' light cache: %d meshes; at most %d",
                          ol->count, LR_TR_MAX_SURFACES);
    /* Per mesh: row starts, columns, values, the far flag, (far) triangles, barycentrics. */
    lr_cache_piece pc[6 * LR_TR_MAX_SURFACES];
    uint64_t w[2 + 2 * LR_TR_MAX_SURFACES], far[LR_TR_MAX_SURFACES];
    int np = 0;
    w[0] = key;
    w[1] = (uint64_t)ol->count;
    for (int i = 0; i < ol->count; i++) {
        const ol_mesh *m = &ol->m[i];
        size_t nnz = m->row[2 * m->nv];
        far[i] = m->far_tri != NULL;
        w[2 + 2 * i] = m->nv;
        w[3 + 2 * i] = nnz;
        pc[np++] = (lr_cache_piece){m->row, (2 * m->nv + 1) * sizeof *m->row};
        pc[np++] = (lr_cache_piece){m->col, nnz * sizeof *m->col};
        pc[np++] = (lr_cache_piece){m->val, nnz * sizeof *m->val};
        pc[np++] = (lr_cache_piece){&far[i], sizeof far[i]};
        if (far[i]) {
            pc[np++] = (lr_cache_piece){m->far_tri, m->nv * sizeof *m->far_tri};
            pc[np++] = (lr_cache_piece){m->far_uv, 2 * m->nv * sizeof *m->far_uv};
        }
    }
    return lr_cache_file_write(path, MAGIC, w, header_words(ol->count), pc, np,
                               "objects' light cache", e);
}

/* One mesh's arrays as read, checked, before they replace anything. */
typedef struct mesh_read {
    size_t *row, *far_tri;
    uint32_t *col;
    float *val, *far_uv;
} mesh_read;

static void mesh_read_free(mesh_read *r)
{
    free(r->row);
    free(r->col);
    free(r->val);
    free(r->far_tri);
    free(r->far_uv);
    *r = (mesh_read){0};
}

static bool read_mesh(const ol_mesh *m, const lr_objlight *ol, const unsigned char *p,
                      size_t nnz, bool far, mesh_read *r)
{
    size_t nv = m->nv, items = 2 * nv, nt = lr_mesh_triangle_count(m->d.mesh);
    r->row = malloc((items + 1) * sizeof *r->row);
    r->col = malloc((nnz ? nnz : 1) * sizeof *r->col);
    r->val = malloc((nnz ? nnz : 1) * sizeof *r->val);
    if (far) {
        r->far_tri = malloc((nv ? nv : 1) * sizeof *r->far_tri);
        r->far_uv = malloc((nv ? nv : 1) * 2 * sizeof *r->far_uv);
    }
    if (!r->row || !r->col || !r->val || (far && (!r->far_tri || !r->far_uv)))
        return false;
    size_t off = 0;
    memcpy(r->row, p + off, (items + 1) * sizeof *r->row);
    off += (items + 1) * sizeof *r->row;
    memcpy(r->col, p + off, nnz * sizeof *r->col);
    off += nnz * sizeof *r->col;
    memcpy(r->val, p + off, nnz * sizeof *r->val);
    off += nnz * sizeof *r->val + sizeof(uint64_t);
    if (far) {
        memcpy(r->far_tri, p + off, nv * sizeof *r->far_tri);
        off += nv * sizeof *r->far_tri;
        memcpy(r->far_uv, p + off, 2 * nv * sizeof *r->far_uv);
    }
    if (r->row[0] != 0 || r->row[items] != nnz)
        return false;
    for (size_t k = 0; k < items; k++)
        if (r->row[k + 1] < r->row[k])
            return false;
    for (size_t j = 0; j < nnz; j++)
        if (r->col[j] < ol->first_source || r->col[j] >= ol->n_patches || !isfinite(r->val[j]) ||
            r->val[j] < 0.0f)
            return false;
    for (size_t v = 0; far && v < nv; v++)
        if ((r->far_tri[v] != SIZE_MAX && r->far_tri[v] >= nt) || !isfinite(r->far_uv[2 * v]) ||
            !isfinite(r->far_uv[2 * v + 1]))
            return false;
    return true;
}

bool lr_objlight_cache_load(lr_objlight *ol, uint64_t key, const char *dir)
{
    char path[1024], *data = NULL;
    const unsigned char *u = NULL;
    size_t len = 0;
    uint64_t w[2 + 2 * LR_TR_MAX_SURFACES];
    if (ol->count > LR_TR_MAX_SURFACES || cache_path(dir, key, path, sizeof path) ||
        !lr_cache_file_read(path, MAGIC, w, header_words(ol->count), &data, &u, &len))
        return false;
    bool ok = w[0] == key && w[1] == (uint64_t)ol->count;
    /* sizes: each mesh's vertex count as built, its entries and far flag as written */
    size_t off = 0;
    bool far[LR_TR_MAX_SURFACES] = {false};
    for (int i = 0; ok && i < ol->count; i++) {
        size_t nv = ol->m[i].nv, nnz = (size_t)w[3 + 2 * i];
        ok = w[2 + 2 * i] == nv && nnz <= (size_t)ol->n_patches * 2 * (nv + 1) &&
             off + mesh_bytes(nv, nnz, false) <= len;
        if (!ok)
            break;
        uint64_t f;
        memcpy(&f, u + off + mesh_bytes(nv, nnz, false) - sizeof f, sizeof f);
        far[i] = f == 1;
        ok = f <= 1 && off + mesh_bytes(nv, nnz, far[i]) <= len;
        off += ok ? mesh_bytes(nv, nnz, far[i]) : 0;
    }
    ok = ok && off == len;
    mesh_read r[LR_TR_MAX_SURFACES] = {{0}};
    off = 0;
    for (int i = 0; ok && i < ol->count; i++) {
        size_t nnz = (size_t)w[3 + 2 * i];
        ok = read_mesh(&ol->m[i], ol, u + off, nnz, far[i], &r[i]);
        off += mesh_bytes(ol->m[i].nv, nnz, far[i]);
    }
    free(data);
    if (!ok) {
        for (int i = 0; i < ol->count; i++)
            mesh_read_free(&r[i]);
        return false;
    }
    for (int i = 0; i < ol->count; i++) {
        ol_mesh *m = &ol->m[i];
        free(m->row);
        free(m->col);
        free(m->val);
        free(m->far_tri);
        free(m->far_uv);
        m->row = r[i].row;
        m->col = r[i].col;
        m->val = r[i].val;
        m->far_tri = r[i].far_tri;
        m->far_uv = r[i].far_uv;
    }
    return true;
}
