/* lamprig — the receivers' light on the objects: see objlight.h. */
#include "render/bounce/objlight.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "render/base/parallel.h"
#include "render/lpv/objfield.h"
#include "render/optics/optics.h"

#include "render/bounce/objlight_priv.h"

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* A frame about n that varies smoothly with n except near n = +-A (a direction no shipped
 * mesh has as a normal), so that neighbouring vertices' ray sets differ smoothly. */
static void frame_of(lr_vec3 n, lr_vec3 *t1, lr_vec3 *t2)
{
    lr_vec3 a = lr_v3_normalize(lr_v3(0.2672612, 0.5345225, 0.8017837));
    lr_vec3 c = lr_v3_cross(a, n);
    if (lr_v3_len(c) < 1e-6)
        c = lr_v3_cross(lr_v3(1, 0, 0), n);
    *t1 = lr_v3_normalize(c);
    *t2 = lr_v3_cross(n, *t1);
}

typedef struct build_ctx {
    const lr_tr *t;
    ol_mesh *m;
    size_t first_source;
    int rays;
    double eps;
    const double (*dirs)[3]; /* rays x (r cos phi, r sin phi, z): cosine-distributed */
    /* per item (2 v + side) lists, packed after the loop */
    uint32_t **cols;
    float **vals;
    size_t *counts;
    int failed;
} build_ctx;

typedef struct entry {
    uint32_t q;
    float w;
} entry;

static int entry_cmp(const void *a, const void *b)
{
    uint32_t x = ((const entry *)a)->q, y = ((const entry *)b)->q;
    return x < y ? -1 : x > y;
}

static void row_item(void *vctx, long item)
{
    build_ctx *c = vctx;
    size_t v = (size_t)item / 2;
    int side = (int)(item % 2);
    c->counts[item] = 0;
    if (side == 1 && !c->m->d.two_sided)
        return;
    const float *P = lr_mesh_positions(c->m->d.mesh), *N = lr_mesh_normals(c->m->d.mesh);
    lr_vec3 x = lr_v3(P[3 * v], P[3 * v + 1], P[3 * v + 2]);
    lr_vec3 n = lr_v3_normalize(lr_v3(N[3 * v], N[3 * v + 1], N[3 * v + 2]));
    if (side == 1)
        n = lr_v3_scale(n, -1.0);
    lr_vec3 t1, t2;
    frame_of(n, &t1, &t2);
    lr_vec3 o = lr_v3_add(x, lr_v3_scale(n, c->eps));
    entry *ent = malloc((size_t)c->rays * 4 * sizeof *ent);
    if (!ent) {
        c->failed = 1;
        return;
    }
    size_t ne = 0;
    double wr = 1.0 / c->rays;
    for (int k = 0; k < c->rays; k++) {
        const double *q = c->dirs[k];
        lr_vec3 d = lr_v3_add(lr_v3_add(lr_v3_scale(t1, q[0]), lr_v3_scale(t2, q[1])),
                              lr_v3_scale(n, q[2]));
        lr_tr_cast_hit h;
        if (!lr_tr_cast(c->t, o, d, &h))
            continue;
        for (int j = 0; j < h.n; j++)
            if (h.patch[j] >= c->first_source)
                ent[ne++] = (entry){(uint32_t)h.patch[j], (float)(h.w[j] * wr)};
    }
    qsort(ent, ne, sizeof *ent, entry_cmp);
    size_t w = 0;
    for (size_t i = 0; i < ne; i++) {
        if (w && ent[w - 1].q == ent[i].q)
            ent[w - 1].w += ent[i].w;
        else
            ent[w++] = ent[i];
    }
    c->cols[item] = malloc((w ? w : 1) * sizeof **c->cols);
    c->vals[item] = malloc((w ? w : 1) * sizeof **c->vals);
    if (!c->cols[item] || !c->vals[item]) {
        c->failed = 1;
        free(ent);
        return;
    }
    for (size_t i = 0; i < w; i++) {
        c->cols[item][i] = ent[i].q;
        c->vals[item][i] = ent[i].w;
    }
    c->counts[item] = w;
    free(ent);
}

/* The far face of a closed wall along -n from each vertex: the first hit of the same mesh that
 * the ray leaves through (its face turned along the ray), within far_mm. */
static void far_faces(ol_mesh *m, double eps)
{
    const float *P = lr_mesh_positions(m->d.mesh), *N = lr_mesh_normals(m->d.mesh);
    for (size_t v = 0; v < m->nv; v++) {
        m->far_tri[v] = SIZE_MAX;
        lr_vec3 x = lr_v3(P[3 * v], P[3 * v + 1], P[3 * v + 2]);
        lr_vec3 n = lr_v3_normalize(lr_v3(N[3 * v], N[3 * v + 1], N[3 * v + 2]));
        lr_vec3 d = lr_v3_scale(n, -1.0);
        lr_hit h;
        if (!lr_bvh_intersect(m->d.bvh, lr_v3_add(x, lr_v3_scale(d, eps)), d, 0.0, m->d.far_mm,
                              &h))
            continue;
        if (lr_v3_dot(lr_mesh_triangle_normal(m->d.mesh, h.triangle), d) <= 0.0)
            continue; /* entering material again: not the wall's other face */
        m->far_tri[v] = h.triangle;
        m->far_uv[2 * v] = (float)h.u;
        m->far_uv[2 * v + 1] = (float)h.v;
    }
}

static void mesh_free(ol_mesh *m)
{
    free(m->row);
    free(m->col);
    free(m->val);
    free(m->far_tri);
    free(m->far_uv);
    for (int s = 0; s < LR_TR_MAX_SLOTS; s++)
        free(m->E[s]);
    memset(m, 0, sizeof *m);
}

void lr_objlight_destroy(lr_objlight *ol)
{
    if (!ol)
        return;
    for (int i = 0; i < ol->count; i++)
        mesh_free(&ol->m[i]);
    free(ol->W);
    free(ol);
}

static int build_mesh(const lr_tr *t, lr_objlight *ol, int i, const double (*dirs)[3], int rays,
                      lr_err *e)
{
    ol_mesh *m = &ol->m[i];
    size_t nv = m->nv = lr_mesh_vertex_count(m->d.mesh), items = 2 * nv;
    build_ctx c = {.t = t, .m = m, .first_source = ol->first_source, .rays = rays,
                   .eps = lr_tr_ray_eps(t), .dirs = dirs};
    c.cols = calloc(items ? items : 1, sizeof *c.cols);
    c.vals = calloc(items ? items : 1, sizeof *c.vals);
    c.counts = calloc(items ? items : 1, sizeof *c.counts);
    m->row = calloc(items + 1, sizeof *m->row);
    int rc = LR_OK;
    if (!c.cols || !c.vals || !c.counts || !m->row) {
        rc = lr_err_set(e, LR_ENOMEM, "receiver light on objects: object %d: out of memory "
                        "(%zu vertices)", i, nv);
        goto done;
    }
    lr_parallel_for((long)items, 0, row_item, &c);
    if (c.failed) {
        rc = lr_err_set(e, LR_ENOMEM, "receiver light on objects: object %d: out of memory "
                        "(rows)", i);
        goto done;
    }
    for (size_t k = 0; k < items; k++)
        m->row[k + 1] = m->row[k] + c.counts[k];
    size_t nnz = m->row[items];
    m->col = malloc((nnz ? nnz : 1) * sizeof *m->col);
    m->val = malloc((nnz ? nnz : 1) * sizeof *m->val);
    if (!m->col || !m->val) {
        rc = lr_err_set(e, LR_ENOMEM, "receiver light on objects: object %d: out of memory "
                        "(%zu entries)", i, nnz);
        goto done;
    }
    for (size_t k = 0; k < items; k++)
        if (c.counts[k]) {
            memcpy(m->col + m->row[k], c.cols[k], c.counts[k] * sizeof *m->col);
            memcpy(m->val + m->row[k], c.vals[k], c.counts[k] * sizeof *m->val);
        }
    if (m->d.far_mm > 0.0 && !m->d.two_sided) {
        m->far_tri = malloc((nv ? nv : 1) * sizeof *m->far_tri);
        m->far_uv = malloc((nv ? nv : 1) * 2 * sizeof *m->far_uv);
        if (!m->far_tri || !m->far_uv) {
            rc = lr_err_set(e, LR_ENOMEM, "receiver light on objects: object %d: out of memory "
                            "(far faces)", i);
            goto done;
        }
        far_faces(m, c.eps);
    }
done:
    for (size_t k = 0; c.cols && c.vals && k < items; k++) {
        free(c.cols[k]);
        free(c.vals[k]);
    }
    free(c.cols);
    free(c.vals);
    free(c.counts);
    return rc;
}

int lr_objlight_create(const lr_tr *t, size_t first_source, const lr_objlight_desc *d, int count,
                       int rays, const lr_objlight_cache *cache, lr_objlight **out, lr_err *e)
{
    const char *cache_dir = cache ? cache->dir : NULL;
    *out = NULL;
    if (!t || (count > 0 && !d))
        return lr_err_set(e, LR_EINVAL, "receiver light on objects: NULL %s",
                          !t ? "solver" : "meshes");
    if (count < 0 || count > LR_TR_MAX_SURFACES)
        return lr_err_set(e, LR_EINVAL, "receiver light on objects: field 'count': %d outside "
                          "[0, %d]", count, LR_TR_MAX_SURFACES);
    if (rays <= 0)
        rays = LR_OBJLIGHT_RAYS;
    if (rays > 1 << 16)
        return lr_err_set(e, LR_EINVAL, "receiver light on objects: field 'rays': %d above %d",
                          rays, 1 << 16);
    for (int i = 0; i < count; i++)
        if (!d[i].mesh || !d[i].bvh)
            return lr_err_set(e, LR_EINVAL, "receiver light on objects: object %d: NULL %s", i,
                              !d[i].mesh ? "mesh" : "bvh");
    double t0 = now_s();
    lr_objlight *ol = calloc(1, sizeof *ol);
    double (*dirs)[3] = malloc((size_t)rays * sizeof *dirs);
    if (!ol || !dirs) {
        free(ol);
        free(dirs);
        return lr_err_set(e, LR_ENOMEM, "receiver light on objects: out of memory");
    }
    /* Cosine-distributed directions from a Halton set (bases 2, 3), the same for every vertex:
     * radius sqrt(u1) on the unit disk lifted to the hemisphere. */
    for (int k = 0; k < rays; k++) {
        double u1 = (k + 0.5) / rays, u2 = lr_halton((unsigned)k + 1, 2);
        double r = sqrt(u1), phi = 2 * M_PI * u2;
        dirs[k][0] = r * cos(phi);
        dirs[k][1] = r * sin(phi);
        dirs[k][2] = sqrt(fmax(0.0, 1.0 - u1));
    }
    ol->count = count;
    ol->first_source = first_source;
    ol->n_patches = lr_tr_patch_count(t);
    ol->W = calloc(3 * (ol->n_patches ? ol->n_patches : 1), sizeof *ol->W);
    int rc = ol->W ? LR_OK : lr_err_set(e, LR_ENOMEM, "receiver light on objects: out of memory");
    for (int i = 0; i < count; i++) {
        ol->m[i].d = d[i];
        ol->m[i].nv = lr_mesh_vertex_count(d[i].mesh);
    }
    uint64_t key = cache_dir ? lr_objlight_cache_key(ol, t, rays) : 0;
    ol->cache_hit = !rc && cache_dir && lr_objlight_cache_load(ol, key, cache_dir);
    for (int i = 0; i < count && !rc && !ol->cache_hit; i++)
        rc = build_mesh(t, ol, i, (const double(*)[3])dirs, rays, e);
    if (!rc && !ol->cache_hit && cache_dir) {
        /* Best effort: a folder that cannot be written costs the next start a rebuild, which
         * is said (once per folder: the same folder fails the same way at every rebuild). */
        lr_err ce = {0};
        if (lr_objlight_cache_store(ol, key, cache_dir, &ce) &&
            lr_warn_once_first(cache->warned, cache_dir))
            lr_warn(&cache->warn, "cache not stored: %s (the rows of %d meshes are rebuilt at "
                    "every start until the folder is writable)", ce.msg, count);
    }
    free(dirs);
    if (rc) {
        lr_objlight_destroy(ol);
        return rc;
    }
    ol->build_s = now_s() - t0;
    *out = ol;
    return LR_OK;
}

/* Light of one row: sum of val W over its entries. */
static void row_E(const ol_mesh *m, const double *W, size_t k, float out[3])
{
    double s[3] = {0, 0, 0};
    for (size_t j = m->row[k]; j < m->row[k + 1]; j++) {
        const double *w = W + 3 * (size_t)m->col[j];
        for (int b = 0; b < 3; b++)
            s[b] += m->val[j] * w[b];
    }
    for (int b = 0; b < 3; b++)
        out[b] = (float)s[b];
}

int lr_objlight_eval(lr_objlight *ol, const lr_tr *t, int slot, lr_err *e)
{
    if (!ol || !t)
        return lr_err_set(e, LR_EINVAL, "receiver light on objects: eval before create");
    if (slot < 0 || slot >= LR_TR_MAX_SLOTS)
        return lr_err_set(e, LR_EINVAL, "receiver light on objects: field 'slot': %d outside "
                          "[0, %d)", slot, LR_TR_MAX_SLOTS);
    if (lr_tr_patch_count(t) != ol->n_patches)
        return lr_err_set(e, LR_EINVAL, "receiver light on objects: the solver has %zu patches, "
                          "built for %zu", lr_tr_patch_count(t), ol->n_patches);
    for (size_t q = ol->first_source; q < ol->n_patches; q++) {
        double w[3];
        lr_tr_radiosity(t, slot, q, w);
        for (int b = 0; b < 3; b++)
            ol->W[3 * q + (size_t)b] = isfinite(w[b]) && w[b] > 0.0 ? w[b] : 0.0;
    }
    for (int i = 0; i < ol->count; i++) {
        ol_mesh *m = &ol->m[i];
        if (!m->E[slot] && !(m->E[slot] = calloc(6 * (m->nv ? m->nv : 1), sizeof *m->E[slot])))
            return lr_err_set(e, LR_ENOMEM, "receiver light on objects: out of memory");
        float *E = m->E[slot];
        for (size_t v = 0; v < m->nv; v++) {
            row_E(m, ol->W, 2 * v, E + 6 * v);
            if (m->d.two_sided)
                row_E(m, ol->W, 2 * v + 1, E + 6 * v + 3);
            else
                E[6 * v + 3] = E[6 * v + 4] = E[6 * v + 5] = 0.0f;
        }
        if (!m->far_tri)
            continue;
        const uint32_t *idx = lr_mesh_indices(m->d.mesh);
        for (size_t v = 0; v < m->nv; v++) {
            size_t tri = m->far_tri[v];
            if (tri == SIZE_MAX)
                continue;
            double u = m->far_uv[2 * v], w = m->far_uv[2 * v + 1];
            double bw[3] = {1.0 - u - w, u, w};
            for (int b = 0; b < 3; b++) {
                double s = 0.0;
                for (int j = 0; j < 3; j++)
                    s += bw[j] * E[6 * (size_t)idx[3 * tri + (size_t)j] + (size_t)b];
                E[6 * v + 3 + (size_t)b] = (float)s;
            }
        }
    }
    return LR_OK;
}

int lr_objlight_count(const lr_objlight *ol) { return ol ? ol->count : 0; }

size_t lr_objlight_vertex_count(const lr_objlight *ol, int i)
{
    return ol && i >= 0 && i < ol->count ? ol->m[i].nv : 0;
}

const float *lr_objlight_E(const lr_objlight *ol, int i, int slot)
{
    if (!ol || i < 0 || i >= ol->count || slot < 0 || slot >= LR_TR_MAX_SLOTS)
        return NULL;
    return ol->m[i].E[slot];
}

void lr_objlight_at(const lr_objlight *ol, int i, int slot, size_t tri, double u, double v,
                    double E[6])
{
    for (int k = 0; k < 6; k++)
        E[k] = 0.0;
    const float *X = lr_objlight_E(ol, i, slot);
    if (!X || tri >= lr_mesh_triangle_count(ol->m[i].d.mesh))
        return;
    const uint32_t *idx = lr_mesh_indices(ol->m[i].d.mesh);
    double bw[3] = {1.0 - u - v, u, v};
    for (int j = 0; j < 3; j++)
        for (int k = 0; k < 6; k++)
            E[k] += bw[j] * X[6 * (size_t)idx[3 * tri + (size_t)j] + (size_t)k];
}

void lr_objlight_factors(const lr_scene_object *o, double kR[3], double kT[3])
{
    double R[3], T[3], ft = lr_lpv_fresnel_diffuse(o->coeffs.eta);
    lr_lpv_object_totals(o, R, T);
    double th = o->coeffs.t_hem > 0.0 && !o->sd_raw ? o->coeffs.t_hem : 1.0;
    for (int c = 0; c < 3; c++) {
        kR[c] = ft * R[c] / th;
        kT[c] = ft * T[c] / th;
    }
}

void lr_objlight_albedo(const lr_scene_object *o, double rho[3])
{
    double R[3], T[3], ft = lr_lpv_fresnel_diffuse(o->coeffs.eta);
    lr_lpv_object_totals(o, R, T);
    for (int c = 0; c < 3; c++) {
        double r = 1.0 - ft + ft * R[c];
        rho[c] = isfinite(r) && r > 0.0 ? (r < 1.0 ? r : 1.0) : 0.0;
    }
}

double lr_objlight_build_s(const lr_objlight *ol) { return ol ? ol->build_s : 0.0; }
bool lr_objlight_cache_hit(const lr_objlight *ol) { return ol && ol->cache_hit; }
