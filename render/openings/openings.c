/* lamprig — light leaving the objects' inner faces through their openings: see openings.h. */
#include "render/openings/openings.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "render/models/twin/cavity_gains.h"
#include "render/base/parallel.h"
#include "render/models/twin/radiosity.h"
#include "render/core/recv_grid.h"
#include "render/base/rng.h"
#include "render/diffusion/dscene.h"
#include "render/mesh/area_pick.h"
#include "render/mesh/bvh.h"
#include "render/optics/optics.h"
#include "render/transrad/tr_scene.h"

/* The renderer's limits (render/passes/passes.h: 8 objects, 16 receivers, 4 lights). */
#define MAXO 8
#define MAXR 16
#define MAXL LR_SCENE_MAX_LIGHTS
/* Geometry key: per object a mesh key, eta, closed, the model's eligibility; per receiver a
 * mesh key and its frame. */
#define GKEY (2 + MAXO * (LR_TR_KEY_MESH + 3) + MAXR * (LR_TR_KEY_MESH + 10))
/* Light key: the light's shape and every object's material and model. */
#define LKEY (LR_LIGHT_KEY_N + MAXO * (sizeof(lr_coeffs) / sizeof(double) + 4))

typedef struct emitter {
    int obj;
    lr_vec3 x, n; /* point, unit normal of the emitting side */
    double a;     /* area it stands for, mm^2 */
} emitter;

struct lr_openings {
    double gkey[GKEY];
    int ngkey;
    int nobj, nrcv, nlights;
    emitter *em;
    size_t ne;
    double area;
    /* Receiver cells: receiver r's nu x nv cells are rows first[r] .. of the kernel. */
    int nu[MAXR], nv[MAXR];
    size_t first[MAXR], np;
    lr_vec3 *px;        /* cell centres */
    lr_vec3 *pn;        /* their normals */
    float *K;           /* np x ne: F_t cos cos a / (pi max(d^2, a)) V */
    double lkey[MAXL][LKEY];
    bool lvalid[MAXL];
    double *B[MAXL];    /* ne x 3 per light */
    float *grid[MAXR][MAXL];
    double *X;          /* scratch: 3 per cell of one receiver */
    double build_s, light_s;
};

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* The models whose B is known at any point (lr_sss_model_props.no_openings says why not). */
static bool eligible(const lr_scene_object *o)
{
    return !lr_sss_model_props_of(o->sss_model)->no_openings;
}

bool lr_openings_needed(const lr_scene *s)
{
    if (!s || !lr_scene_render(s)->opening_light || lr_scene_light_count(s) < 1 ||
        lr_scene_render(s)->lpv > 0)
        return false;
    bool any = false;
    for (int i = 0; i < lr_scene_object_count(s); i++) {
        const lr_scene_object *o = lr_scene_object_at(s, i);
        if (lr_sss_model_props_of(o->sss_model)->patch_solve)
            return false; /* its receiver grid carries the inner faces' light (tr_scene.h) */
        any = any || eligible(o);
    }
    if (!any)
        return false;
    for (int i = 0; i < lr_scene_receiver_count(s); i++)
        if (lr_scene_receiver_at(s, i)->type == LR_RECEIVER_PLANE)
            return true;
    return false;
}

static int geometry_key(const lr_scene *s, double *k)
{
    int n = 0;
    k[n++] = lr_scene_object_count(s);
    k[n++] = lr_scene_receiver_count(s);
    for (int i = 0; i < lr_scene_object_count(s); i++) {
        const lr_scene_object *o = lr_scene_object_at(s, i);
        lr_tr_key_mesh(k, &n, o->mesh, o->bvh);
        k[n++] = o->coeffs.eta;
        k[n++] = o->closed;
        k[n++] = eligible(o);
    }
    for (int i = 0; i < lr_scene_receiver_count(s); i++) {
        const lr_receiver *r = lr_scene_receiver_at(s, i);
        lr_tr_key_mesh(k, &n, r->mesh, r->bvh);
        double f[10] = {r->type,     r->center.x, r->center.y, r->center.z, r->normal.x,
                        r->normal.y, r->normal.z, r->u_dir.x,  r->size[0],  r->size[1]};
        memcpy(k + n, f, sizeof f);
        n += 10;
    }
    return n;
}

static void light_key(const lr_scene *s, int l, double *k)
{
    memset(k, 0, LKEY * sizeof *k);
    const lr_light *L = lr_scene_light_at(s, l);
    lr_light_geometry_key(L, k);
    size_t n = LR_LIGHT_KEY_N, nc = sizeof(lr_coeffs) / sizeof(double);
    for (int i = 0; i < lr_scene_object_count(s) && i < MAXO; i++) {
        const lr_scene_object *o = lr_scene_object_at(s, i);
        memcpy(k + n, &o->coeffs, nc * sizeof(double));
        n += nc;
        k[n++] = o->sss_model;
        k[n++] = o->thickness_mm;
        k[n++] = o->sd_raw;
        k[n++] = o->closed;
    }
}

static void free_geometry(lr_openings *op)
{
    free(op->em);
    free(op->px);
    free(op->pn);
    free(op->K);
    free(op->X);
    op->em = NULL;
    op->px = op->pn = NULL;
    op->K = NULL;
    op->X = NULL;
    op->ne = op->np = 0;
    op->area = 0;
    for (int l = 0; l < MAXL; l++) {
        free(op->B[l]);
        op->B[l] = NULL;
        op->lvalid[l] = false;
        for (int r = 0; r < MAXR; r++) {
            free(op->grid[r][l]);
            op->grid[r][l] = NULL;
        }
    }
    op->ngkey = 0;
}

void lr_openings_destroy(lr_openings *op)
{
    if (!op)
        return;
    free_geometry(op);
    free(op);
}

/* The emitting points of object o (index oi): LR_OPENINGS_POINTS points stratified over the
 * area CDF (as render/core/cavity.c), each kept on the sides the VPLs do not emit from; calls
 * emit(ctx, x, n, a) for each kept side (a = area / LR_OPENINGS_POINTS), stopping at its first
 * nonzero return. */
typedef int (*emit_fn)(void *ctx, lr_vec3 x, lr_vec3 n, double a);

static int walk_emitters(const lr_scene_object *o, int oi, emit_fn emit, void *ctx, lr_err *e)
{
    size_t nt = lr_mesh_triangle_count(o->mesh);
    if (nt == 0)
        return LR_OK;
    double *cdf = malloc(nt * sizeof *cdf);
    if (!cdf)
        return lr_err_set(e, LR_ENOMEM, "openings: out of memory (%zu triangles)", nt);
    double area = 0.0;
    for (size_t t = 0; t < nt; t++) {
        lr_vec3 v[3];
        lr_mesh_triangle(o->mesh, t, v);
        area += 0.5 * lr_v3_len(lr_v3_cross(lr_v3_sub(v[1], v[0]), lr_v3_sub(v[2], v[0])));
        cdf[t] = area;
    }
    if (!(area > 0.0)) {
        free(cdf);
        return LR_OK;
    }
    const int M = LR_OPENINGS_POINTS;
    double a = area / M, tmin = 1e-4 * o->radius;
    lr_rng rng = lr_rng_init(lr_rng_key(1, 0x0BE4, (uint64_t)oi, 0));
    int rc = LR_OK;
    for (int i = 0; i < M && !rc; i++) {
        double pick = (i + lr_rng_next(&rng)) / M * area;
        double s = lr_rng_next(&rng), t = lr_rng_next(&rng);
        size_t lo = lr_cdf_pick(cdf, nt, pick);
        lr_vec3 v[3];
        lr_mesh_triangle(o->mesh, lo, v);
        lr_vec3 x = lr_triangle_fold_point(v, s, t);
        lr_vec3 cr = lr_v3_cross(lr_v3_sub(v[1], v[0]), lr_v3_sub(v[2], v[0]));
        if (!(lr_v3_len(cr) > 0.0))
            continue;
        lr_vec3 n = lr_v3_normalize(cr), cx = lr_v3_sub(x, o->center);
        double dc = lr_v3_len(cx);
        /* Inner: the ray from the centre through x meets the object again beyond x, so the
         * VPLs (the farthest hit along that ray, lr_vpl_place) never stand here. */
        bool inner = dc > 0.0 && lr_bvh_occluded(o->bvh, x, lr_v3_scale(cx, 1.0 / dc), tmin,
                                                 4.0 * o->radius + 1.0);
        for (int side = 0; side < 2 && !rc; side++) {
            lr_vec3 ns = side ? lr_v3_scale(n, -1.0) : n;
            bool kept = o->closed ? side == 0 && inner
                                  : inner || lr_v3_dot(ns, lr_v3_sub(o->center, x)) > 0.0;
            if (kept)
                rc = emit(ctx, x, ns, a);
        }
    }
    free(cdf);
    return rc;
}

typedef struct append_ctx {
    lr_openings *op;
    int oi;
    size_t *cap;
    lr_err *e;
} append_ctx;

static int append_emitter(void *ctx, lr_vec3 x, lr_vec3 n, double a)
{
    append_ctx *c = ctx;
    lr_openings *op = c->op;
    if (op->ne == *c->cap) {
        size_t nc = *c->cap ? 2 * *c->cap : 1024;
        emitter *g = realloc(op->em, nc * sizeof *g);
        if (!g)
            return lr_err_set(c->e, LR_ENOMEM, "openings: out of memory (%zu emitters)", nc);
        op->em = g;
        *c->cap = nc;
    }
    op->em[op->ne++] = (emitter){.obj = c->oi, .x = x, .n = n, .a = a};
    op->area += a;
    return LR_OK;
}

static int add_emitters(lr_openings *op, const lr_scene_object *o, int oi, size_t *cap, lr_err *e)
{
    append_ctx c = {op, oi, cap, e};
    return walk_emitters(o, oi, append_emitter, &c, e);
}

static int sum_area(void *ctx, lr_vec3 x, lr_vec3 n, double a)
{
    (void)x, (void)n;
    *(double *)ctx += a;
    return LR_OK;
}

double lr_openings_inner_fraction(const lr_scene_object *o, int index)
{
    double emitting = 0.0, area = lr_mesh_area(o->mesh);
    lr_err e = {0};
    if (!(area > 0.0) || walk_emitters(o, index, sum_area, &emitting, &e))
        return 0.0;
    return emitting / area;
}

typedef struct kernel_ctx {
    lr_openings *op;
    const lr_scene *s;
} kernel_ctx;

/* Emitter m's geometry term to receiver point x (normal nx), 0 where hidden. */
static double kernel_at(const emitter *m, const lr_scene *s, lr_vec3 x, lr_vec3 nx)
{
    lr_vec3 d = lr_v3_sub(x, m->x);
    double d2 = lr_v3_dot(d, d), dist = sqrt(d2);
    if (!(dist > 0.0))
        return 0.0;
    lr_vec3 w = lr_v3_scale(d, 1.0 / dist);
    double cj = lr_v3_dot(m->n, w), cx = -lr_v3_dot(nx, w);
    if (!(cj > 0.0) || !(cx > 0.0))
        return 0.0;
    for (int i = 0; i < lr_scene_object_count(s); i++) {
        const lr_scene_object *o = lr_scene_object_at(s, i);
        if (lr_bvh_occluded(o->bvh, m->x, w, 1e-6 * o->radius, dist * (1.0 - 1e-9)))
            return 0.0;
    }
    double eta = lr_scene_object_at(s, m->obj)->coeffs.eta;
    return lr_fresnel_transmittance(cj, eta) / M_PI * m->a * cj * cx / fmax(d2, m->a);
}

/* Row p of the kernel: every emitter's geometry term to cell centre p. */
static void kernel_item(void *ctx, long p)
{
    kernel_ctx *k = ctx;
    lr_openings *op = k->op;
    float *row = op->K + (size_t)p * op->ne;
    for (size_t j = 0; j < op->ne; j++)
        row[j] = (float)kernel_at(&op->em[j], k->s, op->px[p], op->pn[p]);
}

void lr_openings_irradiance_at(const lr_openings *op, const lr_scene *s, int l, lr_vec3 x,
                               lr_vec3 n, double E[3])
{
    const double *B = lr_openings_B(op, l);
    for (size_t j = 0; B && j < op->ne; j++) {
        if (!(B[3 * j] > 0.0 || B[3 * j + 1] > 0.0 || B[3 * j + 2] > 0.0))
            continue;
        double k = kernel_at(&op->em[j], s, x, n);
        for (int c = 0; k > 0.0 && c < 3; c++)
            E[c] += k * B[3 * j + (size_t)c];
    }
}

static int build(lr_openings *op, const lr_scene *s, int threads, lr_err *e)
{
    size_t cap = 0;
    int rc;
    op->nobj = lr_scene_object_count(s);
    op->nrcv = lr_scene_receiver_count(s);
    for (int i = 0; i < op->nobj; i++) {
        const lr_scene_object *o = lr_scene_object_at(s, i);
        if (eligible(o) && (rc = add_emitters(op, o, i, &cap, e)))
            return rc;
    }
    size_t np = 0, maxc = 1;
    for (int r = 0; r < op->nrcv; r++) {
        lr_recv_grid_frame f;
        op->nu[r] = op->nv[r] = 0;
        op->first[r] = np;
        if (!lr_recv_grid_frame_of(lr_scene_receiver_at(s, r), &f))
            continue;
        op->nu[r] = (int)fmin(LR_OPENINGS_MAX_CELLS, fmax(1.0, ceil(f.w / LR_OPENINGS_CELL_MM)));
        op->nv[r] = (int)fmin(LR_OPENINGS_MAX_CELLS, fmax(1.0, ceil(f.h / LR_OPENINGS_CELL_MM)));
        size_t c = (size_t)op->nu[r] * (size_t)op->nv[r];
        np += c;
        maxc = c > maxc ? c : maxc;
    }
    op->np = np;
    if (op->ne > 0 && np > LR_OPENINGS_MAX_ENTRIES / op->ne)
        return lr_err_set(e, LR_EINVAL,
                          "openings: %s: %zu receiver cells x %zu emitters exceed the kernel's "
                          "%u entries (render.opening_light: fewer or smaller receivers)",
                          lr_scene_name(s), np, op->ne, (unsigned)LR_OPENINGS_MAX_ENTRIES);
    op->px = malloc((np ? np : 1) * sizeof *op->px);
    op->pn = malloc((np ? np : 1) * sizeof *op->pn);
    op->K = malloc((np ? np : 1) * (op->ne ? op->ne : 1) * sizeof *op->K);
    op->X = malloc(3 * maxc * sizeof *op->X);
    if (!op->px || !op->pn || !op->K || !op->X)
        return lr_err_set(e, LR_ENOMEM, "openings: out of memory (%zu cells x %zu emitters)",
                          np, op->ne);
    for (int r = 0; r < op->nrcv; r++) {
        lr_recv_grid_frame f;
        if (!op->nu[r] || !lr_recv_grid_frame_of(lr_scene_receiver_at(s, r), &f))
            continue;
        for (int v = 0; v < op->nv[r]; v++)
            for (int u = 0; u < op->nu[r]; u++) {
                size_t p = op->first[r] + (size_t)v * (size_t)op->nu[r] + (size_t)u;
                double su = ((u + 0.5) / op->nu[r] - 0.5) * f.w;
                double sv = ((v + 0.5) / op->nv[r] - 0.5) * f.h;
                op->px[p] = lr_v3_add(f.c, lr_v3_add(lr_v3_scale(f.a, su), lr_v3_scale(f.b, sv)));
                op->pn[p] = lr_scene_receiver_at(s, r)->normal;
            }
    }
    kernel_ctx kc = {op, s};
    if (op->ne > 0)
        lr_parallel_for((long)np, threads, kernel_item, &kc);
    else
        memset(op->K, 0, sizeof *op->K);
    return LR_OK;
}

int lr_openings_apply(const lr_openings *op, int r, const double *B, double *X, lr_err *e)
{
    if (!op || !B || !X || r < 0 || r >= op->nrcv || !op->nu[r])
        return lr_err_set(e, LR_EINVAL, "openings: apply: %s",
                          !op ? "NULL handle" : !B || !X ? "NULL array" : "receiver without cells");
    size_t c = (size_t)op->nu[r] * (size_t)op->nv[r];
    for (size_t q = 0; q < c; q++) {
        const float *row = op->K + (op->first[r] + q) * op->ne;
        double sum[3] = {0, 0, 0};
        for (size_t j = 0; j < op->ne; j++)
            if (row[j] != 0.0f)
                for (int b = 0; b < 3; b++)
                    sum[b] += row[j] * B[3 * j + (size_t)b];
        for (int b = 0; b < 3; b++)
            X[3 * q + (size_t)b] = sum[b];
    }
    return LR_OK;
}

typedef struct b_ctx {
    lr_openings *op;
    const lr_scene *s;
    const lr_scene_object *const *objs;
    int l;
    const double (*gain)[3];
    const struct lr_dscene *grid;
} b_ctx;

/* Emitter j's B for light l at unit intensity, times the light's cavity gain. */
static void b_item(void *ctx, long j)
{
    b_ctx *k = ctx;
    const emitter *m = &k->op->em[j];
    double *B = k->op->B[k->l] + 3 * (size_t)j;
    lr_cpu_radiosity_desc d = {.N = LR_OPENINGS_N, .sampler = LR_CPU_REFERENCE,
                               .others = k->objs, .n_others = lr_scene_object_count(k->s)};
    /* diffusion_grid: B is the solved field (its own closure included; the gain here is 1);
     * other objects have none there. */
    if (k->grid)
        lr_dscene_field(k->grid, m->obj, k->l, &d.dfield);
    lr_cpu_estimate est;
    lr_cpu_radiosity(lr_scene_object_at(k->s, m->obj), lr_scene_light_at(k->s, k->l), m->x, m->n,
                     &d, lr_rng_key(0x0BE5, (uint64_t)j, (uint64_t)k->l, 0), &est);
    for (int c = 0; c < 3; c++) {
        double b = est.mean[c] * k->gain[m->obj][c];
        B[c] = isfinite(b) && b > 0.0 ? b : 0.0;
    }
}

static int solve_light(lr_openings *op, const lr_scene *s, const struct lr_dscene *grid, int l,
                       int threads, lr_err *e)
{
    if (!op->B[l] && !(op->B[l] = calloc(3 * (op->ne ? op->ne : 1), sizeof *op->B[l])))
        return lr_err_set(e, LR_ENOMEM, "openings: out of memory (light %d)", l);
    const lr_light *L = lr_scene_light_at(s, l);
    memset(op->B[l], 0, 3 * op->ne * sizeof *op->B[l]);
    if (op->ne && (L->type == LR_LIGHT_POINT || L->type == LR_LIGHT_SPOT)) {
        double gain[MAXO][3];
        int rc = lr_cavity_scene_gains(s, l, threads, gain, op->nobj, e);
        if (rc)
            return rc;
        const lr_scene_object *objs[MAXO];
        for (int i = 0; i < op->nobj; i++)
            objs[i] = lr_scene_object_at(s, i);
        b_ctx bc = {op, s, objs, l, (const double(*)[3])gain, grid};
        lr_parallel_for((long)op->ne, threads, b_item, &bc);
    }
    const size_t R2 = (size_t)LR_RECV_GRID * LR_RECV_GRID;
    for (int r = 0; r < op->nrcv; r++) {
        if (!op->nu[r])
            continue;
        if (!op->grid[r][l] && !(op->grid[r][l] = malloc(3 * R2 * sizeof *op->grid[r][l])))
            return lr_err_set(e, LR_ENOMEM, "openings: out of memory (grid)");
        int rc = lr_openings_apply(op, r, op->B[l], op->X, e);
        if (rc)
            return rc;
        lr_tr_plane_to_grid(op->X, NULL, op->nu[r], op->nv[r], op->grid[r][l]);
    }
    return LR_OK;
}

int lr_openings_update(lr_openings **opp, const lr_scene *s, const struct lr_dscene *grid,
                       int threads, lr_err *e)
{
    if (!opp)
        return lr_err_set(e, LR_EINVAL, "openings: NULL handle");
    if (!lr_openings_needed(s)) {
        lr_openings_destroy(*opp);
        *opp = NULL;
        return LR_OK;
    }
    if (lr_scene_object_count(s) > MAXO || lr_scene_receiver_count(s) > MAXR)
        return lr_err_set(e, LR_EINVAL, "openings: %s: %d objects, %d receivers (at most %d, %d)",
                          lr_scene_name(s), lr_scene_object_count(s),
                          lr_scene_receiver_count(s), MAXO, MAXR);
    lr_openings *op = *opp;
    if (!op) {
        if (!(op = calloc(1, sizeof *op)))
            return lr_err_set(e, LR_ENOMEM, "openings: out of memory");
        *opp = op;
    }
    double key[GKEY];
    int nk = geometry_key(s, key), rc;
    double t0 = now_s();
    op->build_s = 0;
    if (nk != op->ngkey || memcmp(key, op->gkey, (size_t)nk * sizeof *key)) {
        free_geometry(op);
        if ((rc = build(op, s, threads, e))) {
            free_geometry(op);
            return rc;
        }
        memcpy(op->gkey, key, (size_t)nk * sizeof *key);
        op->ngkey = nk;
        op->build_s = now_s() - t0;
    }
    double t1 = now_s();
    op->nlights = lr_scene_light_count(s);
    for (int l = 0; l < op->nlights && l < MAXL; l++) {
        double lk[LKEY];
        light_key(s, l, lk);
        if (op->lvalid[l] && !memcmp(lk, op->lkey[l], sizeof lk))
            continue;
        op->lvalid[l] = false;
        if ((rc = solve_light(op, s, grid, l, threads, e)))
            return rc;
        memcpy(op->lkey[l], lk, sizeof lk);
        op->lvalid[l] = true;
    }
    op->light_s = now_s() - t1;
    return LR_OK;
}

const float *lr_openings_grid(const lr_openings *op, int r, int l)
{
    if (!op || r < 0 || r >= op->nrcv || l < 0 || l >= op->nlights || l >= MAXL ||
        !op->lvalid[l])
        return NULL;
    return op->grid[r][l];
}

size_t lr_openings_emitter_count(const lr_openings *op, double *area)
{
    if (area)
        *area = op ? op->area : 0.0;
    return op ? op->ne : 0;
}

bool lr_openings_emitter(const lr_openings *op, size_t j, lr_vec3 *x, lr_vec3 *n, double *a)
{
    if (!op || j >= op->ne)
        return false;
    *x = op->em[j].x;
    *n = op->em[j].n;
    *a = op->em[j].a;
    return true;
}

bool lr_openings_cells(const lr_openings *op, int r, int *nu, int *nv)
{
    if (!op || r < 0 || r >= op->nrcv || !op->nu[r])
        return false;
    *nu = op->nu[r];
    *nv = op->nv[r];
    return true;
}

const double *lr_openings_B(const lr_openings *op, int l)
{
    return op && l >= 0 && l < MAXL && op->lvalid[l] ? op->B[l] : NULL;
}

void lr_openings_times(const lr_openings *op, double *build_s, double *light_s)
{
    if (build_s)
        *build_s = op ? op->build_s : 0;
    if (light_s)
        *light_s = op ? op->light_s : 0;
}
