/* lamprig — translucent radiosity for the renderer: see tr_scene.h. */
#include "render/transrad/tr_scene.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "render/core/recv_grid.h"

#define KEY_MAX (LR_TR_MAX_SURFACES * 26)

struct lr_tr_scene {
    lr_tr *tr;
    lr_warn_once cache_warned; /* cache folders whose store failure was said (rebuilds reuse) */
    double key[KEY_MAX];
    int nkey;
    int n_obj, n_rcv, n_lights;
    float *vB[LR_TR_MAX_SURFACES][LR_TR_MAX_SLOTS];   /* objects */
    float *rE[LR_TR_MAX_SURFACES][LR_TR_MAX_SLOTS];   /* receivers */
    const lr_mesh *mesh[LR_TR_MAX_SURFACES];
    double build_s, solve_s;
};

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

bool lr_tr_scene_needed(const lr_scene *s)
{
    for (int i = 0; i < lr_scene_object_count(s); i++)
        if (lr_sss_model_props_of(lr_scene_object_at(s, i)->sss_model)->patch_solve)
            return true;
    return false;
}

void lr_tr_plane_to_grid(const double *X, const double *open, int nu, int nv, float *out)
{
    const int R = LR_RECV_GRID;
    for (int t = 0; t < R; t++)
        for (int s = 0; s < R; s++) {
            size_t c[4];
            double w[4];
            lr_tr_plane_cells((s + 0.5) / R, (t + 0.5) / R, nu, nv, open, c, w);
            for (int b = 0; b < 3; b++) {
                double x = 0;
                for (int k = 0; k < 4; k++)
                    x += w[k] * X[3 * c[k] + (size_t)b];
                out[3 * ((size_t)t * R + s) + b] = (float)x;
            }
        }
}

void lr_tr_key_mesh(double *k, int *n, const lr_mesh *m, const lr_bvh *b)
{
    k[(*n)++] = (double)(uintptr_t)m;
    k[(*n)++] = (double)(uintptr_t)b;
    lr_vec3 lo, hi;
    lr_mesh_bounds(m, &lo, &hi);
    lr_vec3 v0 = lr_mesh_vertex(m, 0);
    double v[] = {(double)lr_mesh_triangle_count(m), (double)lr_mesh_vertex_count(m), lo.x, lo.y,
                  lo.z, hi.x, hi.y, hi.z, v0.x, v0.y, v0.z, lr_mesh_area(m)};
    for (size_t i = 0; i < sizeof v / sizeof v[0]; i++)
        k[(*n)++] = v[i];
}

/* What F and S depend on: every surface's shape and scattering (not the lights). */
static int scene_key(const lr_scene *s, double *k)
{
    int n = 0;
    for (int i = 0; i < lr_scene_object_count(s); i++) {
        const lr_scene_object *o = lr_scene_object_at(s, i);
        lr_tr_key_mesh(k, &n, o->mesh, o->bvh);
        for (int b = 0; b < 3; b++) {
            k[n++] = o->coeffs.sigma_tr[b];
            k[n++] = o->coeffs.sigma_t_prime[b];
            k[n++] = o->coeffs.albedo_prime[b];
        }
        k[n++] = o->coeffs.eta;
        k[n++] = o->sss_model;
        k[n++] = o->thickness_mm;
    }
    for (int i = 0; i < lr_scene_receiver_count(s); i++) {
        const lr_receiver *r = lr_scene_receiver_at(s, i);
        lr_tr_key_mesh(k, &n, r->mesh, r->bvh);
        for (int b = 0; b < 3; b++)
            k[n++] = r->albedo[b];
    }
    return n;
}

static void free_arrays(lr_tr_scene *ts)
{
    for (int i = 0; i < LR_TR_MAX_SURFACES; i++)
        for (int l = 0; l < LR_TR_MAX_SLOTS; l++) {
            free(ts->vB[i][l]);
            free(ts->rE[i][l]);
            ts->vB[i][l] = ts->rE[i][l] = NULL;
        }
}

void lr_tr_scene_destroy(lr_tr_scene *ts)
{
    if (!ts)
        return;
    free_arrays(ts);
    lr_tr_destroy(ts->tr);
    free(ts);
}

/* Gaussian-weighted mean of the object's patches' map values at each vertex. */
static int vertex_values(lr_tr_scene *ts, const lr_scene_object *o, int oi, int l, lr_err *e)
{
    const lr_mesh *m = o->mesh;
    size_t nv = lr_mesh_vertex_count(m), first, count;
    lr_tr_surface_patches(ts->tr, oi, &first, &count);
    float *out = malloc(nv * 3 * sizeof *out);
    double *B = malloc((count ? count : 1) * 3 * sizeof *B);
    if (!out || !B) {
        free(out);
        free(B);
        return lr_err_set(e, LR_ENOMEM, "transrad: out of memory (vertex values)");
    }
    for (size_t p = 0; p < count; p++)
        lr_tr_map_radiosity(ts->tr, l, first + p, B + 3 * p);
    const float *N = lr_mesh_normals(m);
    /* The patch size: the cluster cell of lr_tr_settings (12 mm default). */
    double h = 12.0, h2 = h * h;
    for (size_t v = 0; v < nv; v++) {
        lr_vec3 x = lr_mesh_vertex(m, v), n = lr_v3(N[3 * v], N[3 * v + 1], N[3 * v + 2]);
        double sum[3] = {0, 0, 0}, ws = 0, best = INFINITY;
        size_t nearest = first;
        for (size_t p = 0; p < count; p++) {
            lr_vec3 c, pn;
            double A;
            lr_tr_patch_geometry(ts->tr, first + p, &c, &pn, &A);
            double cs = lr_v3_dot(pn, n);
            if (cs <= 0)
                continue;
            lr_vec3 d = lr_v3_sub(c, x);
            double d2 = lr_v3_dot(d, d);
            if (d2 < best) {
                best = d2;
                nearest = p;
            }
            if (cs < 0.5 || d2 > 4 * h2)
                continue;
            double w = A * exp(-d2 / h2);
            for (int b = 0; b < 3; b++)
                sum[b] += w * B[3 * p + (size_t)b];
            ws += w;
        }
        for (int b = 0; b < 3; b++)
            out[3 * v + (size_t)b] =
                (float)(ws > 0 ? sum[b] / ws : isfinite(best) ? B[3 * nearest + (size_t)b] : 0);
    }
    free(B);
    ts->vB[oi][l] = out;
    return LR_OK;
}

/* Irradiance the VPLs do not carry, on the receiver grid. */
static int receiver_values(lr_tr_scene *ts, const lr_scene *s, int ri, int l, lr_err *e)
{
    const lr_receiver *rc = lr_scene_receiver_at(s, ri);
    lr_recv_grid_frame f;
    if (!lr_recv_grid_frame_of(rc, &f))
        return LR_OK;
    const lr_tr *t = ts->tr;
    int no = ts->n_obj, si = no + ri;
    size_t first, count, n = lr_tr_patch_count(t);
    lr_tr_surface_patches(t, si, &first, &count);
    double *X = calloc((count ? count : 1) * 3, sizeof *X);
    float *out = malloc((size_t)LR_RECV_GRID * LR_RECV_GRID * 3 * sizeof *out);
    bool *use = calloc(n ? n : 1, sizeof *use);
    if (!X || !out || !use) {
        free(X);
        free(out);
        free(use);
        return lr_err_set(e, LR_ENOMEM, "transrad: out of memory (receiver values)");
    }
    for (size_t q = 0; q < n; q++) {
        int sq = lr_tr_patch_surface(t, q);
        if (sq >= no) {
            use[q] = true;
            continue;
        }
        const lr_scene_object *o = lr_scene_object_at(s, sq);
        if (!lr_sss_model_props_of(o->sss_model)->patch_solve)
            continue;
        lr_vec3 c, nq;
        lr_tr_patch_geometry(t, q, &c, &nq, NULL);
        use[q] = lr_v3_dot(lr_v3_sub(c, o->center), nq) < 0;
    }
    for (size_t p = 0; p < count; p++)
        for (size_t q = 0; q < n; q++) {
            if (!use[q])
                continue;
            double F = lr_tr_form_factor(t, first + p, q);
            if (F == 0)
                continue;
            double W[3];
            lr_tr_radiosity(t, l, q, W);
            for (int b = 0; b < 3; b++)
                X[3 * p + (size_t)b] += F * W[b];
        }
    /* The patch grid's cell centres are at ((u + 1/2)/nu) of the plane, as the texels' at
     * ((s + 1/2)/R): bilinear between cell centres, clamped at the edges. */
    int nu, nv;
    if (!lr_tr_plane_grid(t, si, &nu, &nv) || (size_t)nu * (size_t)nv != count) {
        free(X);
        free(out);
        free(use);
        return LR_OK;
    }
    /* Open-weighted: a cell under a closed body's foot holds only its open part's light. */
    const double *open = lr_tr_open_fractions(t);
    lr_tr_plane_to_grid(X, open ? open + first : NULL, nu, nv, out);
    free(X);
    free(use);
    ts->rE[ri][l] = out;
    return LR_OK;
}

int lr_tr_scene_update(lr_tr_scene **tsp, const lr_scene *s, const lr_cancel *cancel, lr_err *e)
{
    if (!lr_tr_scene_needed(s)) {
        lr_tr_scene_destroy(*tsp);
        *tsp = NULL;
        return LR_OK;
    }
    lr_tr_scene *ts = *tsp;
    if (!ts) {
        ts = calloc(1, sizeof *ts);
        if (!ts)
            return lr_err_set(e, LR_ENOMEM, "transrad: out of memory");
        *tsp = ts;
    }
    double key[KEY_MAX];
    int nk = scene_key(s, key);
    double t0 = now_s();
    ts->build_s = 0;
    if (!ts->tr || nk != ts->nkey || memcmp(key, ts->key, (size_t)nk * sizeof *key)) {
        lr_tr_destroy(ts->tr);
        ts->tr = NULL;
        /* F and S from the on-disk cache when this geometry was seen before (cache.c). */
        char cdir[1024];
        lr_tr_settings set = {.rays_per_patch = 256,
                              .cache_dir = lr_tr_cache_default_dir(cdir, sizeof cdir),
                              .warn = *lr_scene_warn_sink(s), .warned = &ts->cache_warned,
                              .cancel = cancel};
        int rc = lr_tr_create_scene(s, &set, &ts->tr, e);
        if (rc)
            return rc;
        memcpy(ts->key, key, (size_t)nk * sizeof *key);
        ts->nkey = nk;
        ts->build_s = now_s() - t0;
    }
    lr_tr_set_cancel(ts->tr, cancel);
    free_arrays(ts);
    ts->n_obj = lr_scene_object_count(s);
    ts->n_rcv = lr_scene_receiver_count(s);
    ts->n_lights = lr_scene_light_count(s);
    double t1 = now_s();
    for (int l = 0; l < ts->n_lights && l < LR_TR_MAX_SLOTS; l++) {
        int rc = lr_tr_solve_light(ts->tr, lr_scene_light_at(s, l), l, NULL, e);
        if (rc)
            return rc;
        for (int o = 0; o < ts->n_obj; o++) {
            ts->mesh[o] = lr_scene_object_at(s, o)->mesh;
            if (lr_sss_model_props_of(lr_scene_object_at(s, o)->sss_model)->patch_solve &&
                (rc = vertex_values(ts, lr_scene_object_at(s, o), o, l, e)))
                return rc;
        }
        for (int r = 0; r < ts->n_rcv; r++)
            if ((rc = receiver_values(ts, s, r, l, e)))
                return rc;
    }
    ts->solve_s = now_s() - t1;
    return LR_OK;
}

const float *lr_tr_scene_vertex_B(const lr_tr_scene *ts, int o, int l)
{
    if (!ts || o < 0 || o >= ts->n_obj || l < 0 || l >= LR_TR_MAX_SLOTS)
        return NULL;
    return ts->vB[o][l];
}

const float *lr_tr_scene_recv_E(const lr_tr_scene *ts, int r, int l)
{
    if (!ts || r < 0 || r >= ts->n_rcv || l < 0 || l >= LR_TR_MAX_SLOTS)
        return NULL;
    return ts->rE[r][l];
}

void lr_tr_scene_B_at(const lr_tr_scene *ts, int o, int l, size_t tri, const double w[3],
                      double out[3])
{
    out[0] = out[1] = out[2] = 0;
    const float *vB = lr_tr_scene_vertex_B(ts, o, l);
    if (!vB || tri >= lr_mesh_triangle_count(ts->mesh[o]))
        return;
    const uint32_t *idx = lr_mesh_indices(ts->mesh[o]) + 3 * tri;
    for (int k = 0; k < 3; k++)
        for (int b = 0; b < 3; b++)
            out[b] += w[k] * vB[3 * (size_t)idx[k] + (size_t)b];
}

const lr_tr *lr_tr_scene_solver(const lr_tr_scene *ts) { return ts ? ts->tr : NULL; }

void lr_tr_scene_times(const lr_tr_scene *ts, double *build_s, double *solve_s)
{
    *build_s = ts ? ts->build_s : 0;
    *solve_s = ts ? ts->solve_s : 0;
}
