/* lamprig — receiver inter-reflection for every model: see rbounce.h. */
#include "render/bounce/rbounce.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "render/bounce/objlight.h"
#include "render/core/recv_grid.h"
#include "render/transrad/tr_scene.h"

#define KEY_MAX (3 + LR_TR_MAX_SURFACES * (LR_TR_KEY_MESH + 5))
#define LKEY LR_LIGHT_KEY_N /* doubles per light shape */
#define MAX_LIGHTS 8
/* Object patches: the receivers' light they reflect back varies over a body as the receivers'
 * does over their 30 mm cells. */
#define OBJECT_PATCH_MM 30

struct lr_rbounce {
    lr_tr *tr;
    lr_warn_once cache_warned; /* cache folders whose store failure was said (rebuilds reuse) */
    double key[KEY_MAX];
    int nkey;
    int n_obj, n_rcv, n_lights;
    size_t n;               /* patches */
    double *Edir[MAX_LIGHTS]; /* n x 3 per light, unit intensity */
    double lkey[MAX_LIGHTS][LKEY];
    bool lvalid[MAX_LIGHTS];
    double *Evpl;           /* n x 3: the VPL grids' patch means */
    int *cnt;               /* n: scratch, texels per patch */
    double *E;              /* n x 3 scratch */
    unsigned char *covered[LR_TR_MAX_SURFACES]; /* per receiver, R^2: texel inside a body */
    float *out[LR_TR_MAX_SURFACES][LR_TR_MAX_SLOTS]; /* per receiver, slot: R^2 x 3 */
    const lr_cancel *cancel; /* the last update's (polled by builds and solves) */
    lr_objlight *ol;        /* render.receiver_light_on_objects: the objects' E (objlight.h) */
    double build_s, direct_s, solve_s;
};

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

bool lr_rbounce_needed(const lr_scene *s)
{
    if (!s || !lr_scene_render(s)->receiver_bounce || lr_scene_light_count(s) < 1)
        return false;
    /* render.lpv's volumes carry the receivers' interreflection of their own (render/lpv/):
     * not twice. */
    if (lr_scene_render(s)->lpv > 0)
        return false;
    for (int i = 0; i < lr_scene_object_count(s); i++)
        if (lr_sss_model_props_of(lr_scene_object_at(s, i)->sss_model)->patch_solve)
            return false; /* its solve has the receivers in F (render/transrad/tr_scene.h) */
    for (int i = 0; i < lr_scene_receiver_count(s); i++)
        if (lr_scene_receiver_at(s, i)->type == LR_RECEIVER_PLANE)
            return true;
    return false;
}

/* What the patches, F and the albedos depend on: the objects' and receivers' shapes. */
static int scene_key(const lr_scene *s, double *k)
{
    int n = 0;
    k[n++] = lr_scene_object_count(s);
    k[n++] = lr_scene_receiver_count(s);
    k[n++] = lr_scene_render(s)->receiver_light_on_objects;
    for (int i = 0; i < lr_scene_object_count(s); i++) {
        const lr_scene_object *o = lr_scene_object_at(s, i);
        lr_tr_key_mesh(k, &n, o->mesh, o->bvh);
        k[n++] = o->closed; /* the objects' light: E- (objlight.h) */
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

/* What a light's direct irradiance at unit intensity depends on (not its intensity, colour or
 * flicker: those scale it). */
static void light_key(const lr_light *l, double *k)
{
    lr_light_geometry_key(l, k);
}

static void free_solver(lr_rbounce *rb)
{
    lr_objlight_destroy(rb->ol);
    rb->ol = NULL;
    lr_tr_destroy(rb->tr);
    rb->tr = NULL;
    for (int l = 0; l < MAX_LIGHTS; l++) {
        free(rb->Edir[l]);
        rb->Edir[l] = NULL;
        rb->lvalid[l] = false;
    }
    free(rb->Evpl);
    free(rb->E);
    free(rb->cnt);
    rb->Evpl = rb->E = NULL;
    rb->cnt = NULL;
    for (int r = 0; r < LR_TR_MAX_SURFACES; r++) {
        free(rb->covered[r]);
        rb->covered[r] = NULL;
    }
    for (int r = 0; r < LR_TR_MAX_SURFACES; r++)
        for (int sl = 0; sl < LR_TR_MAX_SLOTS; sl++) {
            free(rb->out[r][sl]);
            rb->out[r][sl] = NULL;
        }
    rb->nkey = 0;
}

void lr_rbounce_destroy(lr_rbounce *rb)
{
    if (!rb)
        return;
    free_solver(rb);
    free(rb);
}

/* The objects (diffuse, no E of their own) and the receivers (planes as grids, boxes as
 * meshes) with their albedo. */
static int build(lr_rbounce *rb, const lr_scene *s, lr_err *e)
{
    int no = lr_scene_object_count(s), nr = lr_scene_receiver_count(s), n = 0;
    if (no + nr > LR_TR_MAX_SURFACES)
        return lr_err_set(e, LR_EINVAL,
                          "receiver bounce: %s: %d objects and receivers, at most %d",
                          lr_scene_name(s), no + nr, LR_TR_MAX_SURFACES);
    lr_tr_surface_desc d[LR_TR_MAX_SURFACES];
    for (int i = 0; i < no; i++) {
        const lr_scene_object *o = lr_scene_object_at(s, i);
        /* A closed body covers the receiver cells it stands on (render/transrad/cover.c). Its
         * albedo follows its material (set_object_albedo at every update): 0 here, so that F
         * and its cache do not depend on the material. */
        d[n++] = (lr_tr_surface_desc){.kind = LR_TR_DIFFUSE, .mesh = o->mesh, .bvh = o->bvh,
                                      .patch_mm = OBJECT_PATCH_MM, .covers = o->closed};
    }
    for (int i = 0; i < nr; i++) {
        const lr_receiver *r = lr_scene_receiver_at(s, i);
        lr_tr_surface_desc x = {.kind = r->type == LR_RECEIVER_PLANE ? LR_TR_PLANE : LR_TR_DIFFUSE,
                                .mesh = r->mesh, .bvh = r->bvh, .center = r->center,
                                .normal = r->normal, .u_dir = r->u_dir, .size_u = r->size[0],
                                .size_v = r->size[1], .patch_mm = 30};
        for (int b = 0; b < 3; b++)
            x.albedo[b] = r->albedo[b];
        d[n++] = x;
    }
    char cdir[1024];
    lr_tr_settings set = {.rays_per_patch = 512,
                          .cache_dir = lr_tr_cache_default_dir(cdir, sizeof cdir),
                          .warn = *lr_scene_warn_sink(s), .warned = &rb->cache_warned,
                          .cancel = rb->cancel};
    int rc = lr_tr_create(d, n, &set, &rb->tr, e);
    if (rc)
        return rc;
    rb->n = lr_tr_patch_count(rb->tr);
    size_t n3 = 3 * (rb->n ? rb->n : 1);
    rb->Evpl = calloc(n3, sizeof *rb->Evpl);
    rb->E = calloc(n3, sizeof *rb->E);
    rb->cnt = calloc(rb->n ? rb->n : 1, sizeof *rb->cnt);
    if (!rb->Evpl || !rb->E || !rb->cnt)
        return lr_err_set(e, LR_ENOMEM, "receiver bounce: out of memory (%zu patches)", rb->n);
    rb->n_obj = no;
    rb->n_rcv = nr;
    /* The texels inside a body standing on a receiver: left out of the VPL grid's cell means,
     * which are over the cells' open part like the solver's F and E. */
    const double *open = lr_tr_open_fractions(rb->tr);
    const int R = LR_RECV_GRID;
    for (int r = 0; r < nr && open; r++) {
        size_t first, count;
        lr_tr_surface_patches(rb->tr, no + r, &first, &count);
        bool any = false;
        for (size_t p = first; p < first + count; p++)
            any = any || open[p] < 1;
        if (!any)
            continue;
        if (!(rb->covered[r] = calloc((size_t)R * R, 1)))
            return lr_err_set(e, LR_ENOMEM, "receiver bounce: out of memory (covered texels)");
        for (int t = 0; t < R; t++)
            for (int c = 0; c < R; c++)
                rb->covered[r][(size_t)t * R + (size_t)c] =
                    lr_tr_plane_point_covered(rb->tr, no + r, (c + 0.5) / R, (t + 0.5) / R);
    }
    if (!lr_scene_render(s)->receiver_light_on_objects || no == 0)
        return LR_OK;
    /* The receivers' light on the objects: rows of every object vertex against the
     * receivers' patches (objlight.h); E- from the far face of a closed wall with
     * thickness_mm (the multipole's T), by rays on the back of an open one. */
    lr_objlight_desc od[LR_TR_MAX_SURFACES];
    for (int i = 0; i < no; i++) {
        const lr_scene_object *o = lr_scene_object_at(s, i);
        od[i] = (lr_objlight_desc){.mesh = o->mesh, .bvh = o->bvh, .two_sided = !o->closed,
                                   .far_mm = o->thickness_mm > 0 ? 2 * o->thickness_mm + 1 : 0};
    }
    size_t first, count;
    lr_tr_surface_patches(rb->tr, no, &first, &count);
    lr_objlight_cache oc = {.dir = lr_tr_cache_default_dir(cdir, sizeof cdir),
                            .warn = *lr_scene_warn_sink(s), .warned = &rb->cache_warned};
    return lr_objlight_create(rb->tr, first, od, no, 0, &oc, &rb->ol, e);
}

/* The objects' patches reflect the receivers' light with the albedo their material shows
 * diffuse light (lr_objlight_albedo): set at every update, as a material can change (a preset,
 * a translucency knob) without the geometry, and F does not depend on it. */
static int set_object_albedo(lr_rbounce *rb, const lr_scene *s, lr_err *e)
{
    for (int i = 0; i < rb->n_obj; i++) {
        double rho[3];
        lr_objlight_albedo(lr_scene_object_at(s, i), rho);
        int rc = lr_tr_set_albedo(rb->tr, i, rho, e);
        if (rc)
            return rc;
    }
    return LR_OK;
}

int lr_rbounce_update(lr_rbounce **rbp, const lr_scene *s, const lr_cancel *cancel, lr_err *e)
{
    if (!rbp)
        return lr_err_set(e, LR_EINVAL, "receiver bounce: NULL handle");
    if (!lr_rbounce_needed(s)) {
        lr_rbounce_destroy(*rbp);
        *rbp = NULL;
        return LR_OK;
    }
    if (lr_scene_light_count(s) > MAX_LIGHTS)
        return lr_err_set(e, LR_EINVAL, "receiver bounce: %s: %d lights, at most %d",
                          lr_scene_name(s), lr_scene_light_count(s), MAX_LIGHTS);
    lr_rbounce *rb = *rbp;
    if (!rb) {
        if (!(rb = calloc(1, sizeof *rb)))
            return lr_err_set(e, LR_ENOMEM, "receiver bounce: out of memory");
        *rbp = rb;
    }
    rb->cancel = cancel;
    lr_tr_set_cancel(rb->tr, cancel);
    double key[KEY_MAX];
    int nk = scene_key(s, key), rc;
    double t0 = now_s();
    rb->build_s = 0;
    if (!rb->tr || nk != rb->nkey || memcmp(key, rb->key, (size_t)nk * sizeof *key)) {
        free_solver(rb);
        if ((rc = build(rb, s, e))) {
            free_solver(rb);
            return rc;
        }
        memcpy(rb->key, key, (size_t)nk * sizeof *key);
        rb->nkey = nk;
        rb->build_s = now_s() - t0;
    }
    if ((rc = set_object_albedo(rb, s, e)))
        return rc;
    double t1 = now_s();
    rb->n_lights = lr_scene_light_count(s);
    for (int l = 0; l < rb->n_lights; l++) {
        double lk[LKEY];
        light_key(lr_scene_light_at(s, l), lk);
        if (rb->lvalid[l] && !memcmp(lk, rb->lkey[l], sizeof lk))
            continue;
        if (!rb->Edir[l] && !(rb->Edir[l] = calloc(3 * (rb->n ? rb->n : 1), sizeof *rb->Edir[l])))
            return lr_err_set(e, LR_ENOMEM, "receiver bounce: out of memory (direct light)");
        if ((rc = lr_tr_direct_irradiance(rb->tr, lr_scene_light_at(s, l), rb->Edir[l], e)))
            return rc;
        memcpy(rb->lkey[l], lk, sizeof lk);
        rb->lvalid[l] = true;
    }
    rb->direct_s = now_s() - t1;
    memset(rb->Evpl, 0, 3 * rb->n * sizeof *rb->Evpl);
    return LR_OK;
}

/* Patch means of grid texels: the patch of texel (s, t) is the cell holding its centre; texels
 * inside a body standing on the receiver are not counted. */
static void vpl_means(lr_rbounce *rb, int r, const float *gf, const double *gd, int stride)
{
    if (!rb || !rb->tr || r < 0 || r >= rb->n_rcv)
        return;
    int si = rb->n_obj + r, nu, nv;
    size_t first, count;
    lr_tr_surface_patches(rb->tr, si, &first, &count);
    if (!lr_tr_plane_grid(rb->tr, si, &nu, &nv) || (size_t)nu * (size_t)nv != count)
        return;
    double *m = rb->Evpl + 3 * first;
    memset(m, 0, 3 * count * sizeof *m);
    if ((!gf && !gd) || stride < 3)
        return;
    int *cnt = rb->cnt;
    memset(cnt, 0, count * sizeof *cnt);
    const int R = LR_RECV_GRID;
    const unsigned char *covered = rb->covered[r];
    for (int t = 0; t < R; t++) {
        int v = (int)((t + 0.5) * nv / R);
        for (int s = 0; s < R; s++) {
            int u = (int)((s + 0.5) * nu / R);
            size_t k = (size_t)t * R + (size_t)s, p = (size_t)v * (size_t)nu + (size_t)u;
            if (covered && covered[k])
                continue;
            for (int b = 0; b < 3; b++) {
                double x = gf ? gf[k * (size_t)stride + (size_t)b] : gd[k * (size_t)stride + (size_t)b];
                m[3 * p + (size_t)b] += isfinite(x) && x > 0 ? x : 0;
            }
            cnt[p]++;
        }
    }
    for (size_t p = 0; p < count; p++)
        for (int b = 0; b < 3; b++)
            m[3 * p + (size_t)b] = cnt[p] ? m[3 * p + (size_t)b] / cnt[p] : 0;
}

void lr_rbounce_vpl_f(lr_rbounce *rb, int r, const float *grid, int stride)
{
    vpl_means(rb, r, grid, NULL, stride);
}

void lr_rbounce_vpl_d(lr_rbounce *rb, int r, const double *grid, int stride)
{
    vpl_means(rb, r, NULL, grid, stride);
}

/* E_b of receiver r on the texel grid: bilinear between patch centres ((u + 1/2)/nu of the
 * plane, as the texels' (s + 1/2)/R), clamped at the edges (as render/transrad/tr_scene.c),
 * weighted by the cells' open parts (each cell's E_b is its open part's mean). */
static int write_grid(lr_rbounce *rb, int r, int slot, lr_err *e)
{
    int si = rb->n_obj + r, nu, nv;
    size_t first, count;
    lr_tr_surface_patches(rb->tr, si, &first, &count);
    if (!lr_tr_plane_grid(rb->tr, si, &nu, &nv) || (size_t)nu * (size_t)nv != count)
        return LR_OK;
    const int R = LR_RECV_GRID;
    float **out = &rb->out[r][slot];
    if (!*out && !(*out = malloc((size_t)R * R * 3 * sizeof **out)))
        return lr_err_set(e, LR_ENOMEM, "receiver bounce: out of memory (grid)");
    double *X = rb->E; /* the scratch E is free after the solve */
    for (size_t p = 0; p < count; p++)
        lr_tr_indirect(rb->tr, slot, first + p, X + 3 * p);
    const double *open = lr_tr_open_fractions(rb->tr);
    lr_tr_plane_to_grid(X, open ? open + first : NULL, nu, nv, *out);
    return LR_OK;
}

int lr_rbounce_solve(lr_rbounce *rb, int slot, const double (*w)[3], lr_err *e)
{
    if (!rb || !rb->tr)
        return lr_err_set(e, LR_EINVAL, "receiver bounce: solve before update");
    if (slot < 0 || slot >= LR_TR_MAX_SLOTS)
        return lr_err_set(e, LR_EINVAL, "receiver bounce: field 'slot': %d outside [0, %d)",
                          slot, LR_TR_MAX_SLOTS);
    double t0 = now_s();
    size_t first0, cnt0;
    lr_tr_surface_patches(rb->tr, rb->n_obj, &first0, &cnt0);
    for (size_t p = 0; p < rb->n; p++)
        for (int b = 0; b < 3; b++) {
            size_t i = 3 * p + (size_t)b;
            double x = p >= first0 ? rb->Evpl[i] : 0;
            for (int l = 0; w && l < rb->n_lights && p >= first0; l++)
                if (rb->Edir[l] && w[l][b] > 0)
                    x += w[l][b] * rb->Edir[l][i];
            rb->E[i] = isfinite(x) && x > 0 ? x : 0;
        }
    int rc = lr_tr_solve_irradiance(rb->tr, rb->E, slot, NULL, e);
    if (!rc && rb->ol)
        rc = lr_objlight_eval(rb->ol, rb->tr, slot, e);
    for (int r = 0; r < rb->n_rcv && !rc; r++)
        rc = write_grid(rb, r, slot, e);
    rb->solve_s = now_s() - t0;
    return rc;
}

const float *lr_rbounce_grid(const lr_rbounce *rb, int r, int slot)
{
    if (!rb || r < 0 || r >= rb->n_rcv || slot < 0 || slot >= LR_TR_MAX_SLOTS)
        return NULL;
    return rb->out[r][slot];
}

const lr_tr *lr_rbounce_solver(const lr_rbounce *rb) { return rb ? rb->tr : NULL; }

const lr_objlight *lr_rbounce_objects(const lr_rbounce *rb) { return rb ? rb->ol : NULL; }

int lr_rbounce_first_receiver(const lr_rbounce *rb) { return rb ? rb->n_obj : 0; }

void lr_rbounce_times(const lr_rbounce *rb, double *build_s, double *direct_s, double *solve_s)
{
    if (build_s)
        *build_s = rb ? rb->build_s : 0;
    if (direct_s)
        *direct_s = rb ? rb->direct_s : 0;
    if (solve_s)
        *solve_s = rb ? rb->solve_s : 0;
}
