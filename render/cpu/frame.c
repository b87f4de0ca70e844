/* Whole CPU images, twin and reference; see frame.h. */
#include "render/cpu/frame.h"
#include "render/area/frames.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "render/base/mat4.h"
#include "render/models/twin/cavity_gains.h"
#include "render/cpu/maps.h"
#include "render/base/parallel.h"
#include "render/bounce/objlight.h"
#include "render/bounce/rbounce.h"
#include "render/openings/openings.h"
#include "render/core/recv_grid.h"
#include "render/lpv/scene_lpv.h"
#include "render/transrad/tr_scene.h"
#include "render/base/rng.h"
#include "render/models/twin/sh.h"
#include "render/core/surface.h"
#include "render/core/vpl.h"

void lr_cpu_camera_ray(const lr_scene *s, int width, int height, int px, int py, lr_vec3 *org,
                       lr_vec3 *dir)
{
    const lr_camera *cam = lr_scene_camera(s);
    double view[16], proj[16], vp[16], inv[16];
    lr_camera_view(cam, view);
    lr_camera_projection(cam, (double)width / height, proj);
    lr_mat4_mul(proj, view, vp);
    lr_mat4_inverse(vp, inv);
    double nx = (px + 0.5) / width * 2.0 - 1.0, ny = 1.0 - (py + 0.5) / height * 2.0;
    lr_vec3 a = lr_mat4_project(inv, lr_v3(nx, ny, -1.0));
    lr_vec3 b = lr_mat4_project(inv, lr_v3(nx, ny, 1.0));
    *org = a;
    *dir = lr_v3_normalize(lr_v3_sub(b, a));
}

typedef struct rctx {
    const lr_cpu_render_desc *d;
    const lr_scene *s;
    int W, H, nobj, nlight, nvpl, samples;
    double inv_vp[16];
    lr_cpu_maps **maps;  /* [obj * nlight + light] (PASS) */
    const lr_scene_object **objs; /* every object: occluders of each other's light lookups */
    lr_vpl_point *vpl;     /* [obj * nvpl + v]; B per band already summed over lights with I */
    double (*I)[3];      /* per light: intensity * color */
    double (*gain)[3];   /* [obj * nlight + light]: cavity gain (render/core/cavity.h) */
    lr_sh_env *sh;       /* [obj * nlight + light]: sh_translucency environments */
    lr_image *rgb, *var;
    long *object_px, *fallback_px; /* per pixel flags, summed at the end */
    /* PASS: per receiver, E_vpl and its variance at the grid's texel centres (6 doubles per
     * texel; render/core/recv_grid.h, the GPU's receiver irradiance grid), NULL for a receiver
     * without a grid. */
    double **grid;
    /* render.receiver_bounce: per receiver, the bounced irradiance F B on the receiver grid
     * (3 per texel; NULL: none), added at every pixel in both modes. */
    double **bounce;
    int nrecv;
    /* render.lpv (PASS): per receiver and light, the light-propagation volume's indirect
     * irradiance per unit radiance at the grid's texel centres (3 doubles per texel;
     * render/lpv/scene_lpv.h), [receiver * nlight + light], NULL where none; the GPU adds
     * the same to its area lights' direct grid (render/passes/area_direct.c). */
    double **lpv;
    /* render.lpv (PASS): per light, the volume's irradiance on the objects (objfield.h), and
     * per object its factors kR, kT ([obj * 6]: kR rgb, kT rgb), as lpv_pass.c gives the GPU. */
    lr_lpv_objfield **lpv_obj;
    double *lpv_k;
    lr_tr_scene *tr;     /* translucent radiosity (PASS): the solver's B and receiver extra */
    /* render.receiver_bounce with receiver_light_on_objects (PASS): the solve (its slot 0 sums
     * the lights with their intensities) and per object kR, kT ([obj * 6]) of the receivers'
     * light on the objects (render/bounce/objlight.h), as the GPU's compose pass applies. */
    lr_rbounce *rb;
    double *rl_k;
    lr_openings *op;     /* render.opening_light (render/openings/openings.h); NULL: off */
    lr_dscene *dscene; /* diffusion_grid objects' fields (NULL when the scene has none) */
    /* Per light, the lights the transport sees frame by frame (render/area/frames.h): an area
     * light's frame samples (PASS: the `frames` accumulated; REFERENCE: LR_REF_AREA_FRAMES),
     * any other light itself once. */
    lr_light **fl;
    int *nfl;
    /* PASS with render.surface_cache: per object its lattice (render/mesh/lattice.h) and,
     * per light, side and lattice point, B (3 doubles), its variance (3) and whether a map
     * saw it (1): the GPU's surface cache (render/core/surface.h), interpolated per pixel. NULL: per pixel. */
    lr_refined *ref;
    double **cache;
    long *cache_first; /* item -> (object, light, side, vertex): prefix over objects */
} rctx;

/* Frame samples standing for an area light in LR_CPU_REFERENCE: 16 cycles of the Poisson set,
 * each rotated anew (about 1000 area-uniform points). */
#define LR_REF_AREA_FRAMES (16 * LR_AREA_SEQ_MAX)

/* The mean of the direct irradiance over the light's frame samples. */
static double direct_at(const rctx *r, int l, lr_vec3 x, lr_vec3 n)
{
    double sum = 0.0;
    for (int f = 0; f < r->nfl[l]; f++)
        sum += lr_direct_irradiance(r->s, &r->fl[l][f], x, n);
    return sum / r->nfl[l];
}

enum { CACHE_DOUBLES = 7 };

static uint64_t seed_of(const rctx *r) { return r->d->seed ? r->d->seed : 1; }

/* Light sent back into a cavity around the light (PIPELINE.md "Energy"): B times the gain. */
static void cavity(const rctx *r, int o, int l, double B[3], double var[3])
{
    const double *g = r->gain[o * r->nlight + l];
    for (int c = 0; c < 3; c++) {
        B[c] *= g[c];
        var[c] *= g[c] * g[c];
    }
}

/* B at (x, n) of object o for light l, per unit intensity, with the variance of the mean. */
static void radiosity_at(const rctx *r, int o, int l, lr_vec3 x, lr_vec3 n, uint64_t key,
                         double B[3], double var[3], bool *fallback)
{
    if (r->d->mode == LR_CPU_REFERENCE) {
        /* An area light: the mean over its first m frame samples, samples / m each. */
        int m = r->nfl[l] > 1 ? LR_AREA_SEQ_MAX : 1;
        lr_cpu_radiosity_desc rd = {.N = r->samples / m > 0 ? r->samples / m : 1,
                                    .sampler = LR_CPU_REFERENCE, .others = r->objs,
                                    .n_others = r->nobj, .sh_env = r->sh + o * r->nlight + l};
        if (r->dscene)
            lr_dscene_field(r->dscene, o, l, &rd.dfield);
        for (int c = 0; c < 3; c++)
            B[c] = var[c] = 0.0;
        for (int f = 0; f < m; f++) {
            lr_cpu_estimate est;
            lr_cpu_radiosity(lr_scene_object_at(r->s, o), &r->fl[l][f], x, n, &rd,
                             lr_rng_key(key, (uint64_t)f, 0, 0), &est);
            for (int c = 0; c < 3; c++) {
                B[c] += est.mean[c] / m;
                var[c] += est.var[c] / est.n / ((double)m * m);
            }
        }
        if (fallback)
            *fallback = false;
        cavity(r, o, l, B, var);
        return;
    }
    lr_cpu_maps_compose(r->maps[o * r->nlight + l], x, n, B, var, fallback);
    cavity(r, o, l, B, var);
}

static void vpl_item(void *p, long item)
{
    rctx *r = p;
    int o = (int)(item / r->nvpl);
    lr_vpl_point *v = &r->vpl[item];
    if (!v->valid)
        return;
    for (int l = 0; l < r->nlight; l++) {
        double B[3], var[3];
        radiosity_at(r, o, l, v->x, v->n,
                     lr_rng_key(seed_of(r) ^ 0x7B1u, (uint64_t)item, (uint64_t)l, 0), B, var, NULL);
        for (int c = 0; c < 3; c++) {
            v->B[c] += r->I[l][c] * B[c];
            v->var[c] += r->I[l][c] * r->I[l][c] * var[c];
        }
    }
}

/* Sides cached for object o: an open object also for its reversed normal. */
static int sides(const rctx *r, int o) { return lr_scene_object_at(r->s, o)->closed ? 1 : 2; }

/* The cache entry of object o, light l, side, lattice point v. */
static double *cache_at(const rctx *r, int o, int l, int side, size_t v)
{
    size_t nv = r->ref[o].nv;
    return r->cache[o] + CACHE_DOUBLES * (((size_t)l * (size_t)sides(r, o) + (size_t)side) * nv + v);
}

/* Algorithm 1 at one lattice point for every light (item over all objects' entries). */
static void cache_item(void *p, long item)
{
    rctx *r = p;
    int o = 0;
    while (item >= r->cache_first[o + 1])
        o++;
    long k = item - r->cache_first[o];
    size_t nv = r->ref[o].nv;
    int side = (int)((size_t)k / nv);
    size_t v = (size_t)k % nv;
    const float *x = r->ref[o].pos + 3 * v, *nn = r->ref[o].nrm + 3 * v;
    lr_vec3 n = lr_v3(nn[0], nn[1], nn[2]);
    if (!(lr_v3_len(n) > 1e-12))
        return;
    n = lr_v3_scale(lr_v3_normalize(n), side ? -1.0 : 1.0);
    for (int l = 0; l < r->nlight; l++) {
        double *c = cache_at(r, o, l, side, v);
        bool fb = false;
        radiosity_at(r, o, l, lr_v3(x[0], x[1], x[2]), n, 0, c, c + 3, &fb);
        c[6] = fb ? 0.0 : 1.0;
    }
}

/* B of object o for light l at the camera hit (parent triangle t, barycentrics u, v): the
 * cache interpolated over the lattice sub-triangle holding it (lr_lattice_locate), as
 * compose_cached.frag does. */
static void cached_at(const rctx *r, int o, int l, int side, size_t t, double u, double v,
                      double B[3], double var[3], bool *fallback)
{
    double w[3];
    size_t k = lr_refined_locate(&r->ref[o], t, u, v, w);
    double cover = 0.0;
    for (int c = 0; c < 3; c++)
        B[c] = var[c] = 0.0;
    for (int j = 0; j < 3; j++) {
        const double *e = cache_at(r, o, l, side, r->ref[o].idx[3 * k + j]);
        for (int c = 0; c < 3; c++) {
            B[c] += w[j] * e[c];
            var[c] += w[j] * w[j] * e[3 + c];
        }
        cover += w[j] * e[6];
    }
    *fallback = !(cover >= 0.5);
}

/* E_vpl at texel (item mod R^2) of receiver (item / R^2)'s grid. */
static void grid_item(void *p, long item)
{
    rctx *r = p;
    const long n = (long)LR_RECV_GRID * LR_RECV_GRID;
    int i = (int)(item / n), k = (int)(item % n);
    if (!r->grid[i])
        return;
    const lr_receiver *rc = lr_scene_receiver_at(r->s, i);
    lr_recv_grid_frame f;
    lr_recv_grid_frame_of(rc, &f);
    lr_vec3 x = lr_recv_grid_point(&f, k % LR_RECV_GRID, k / LR_RECV_GRID);
    double *E = r->grid[i] + 6 * (size_t)k;
    const lr_scene *vis = lr_scene_render(r->s)->vpl_visibility ? r->s : NULL;
    for (int o = 0; o < r->nobj; o++)
        lr_vpl_point_irradiance_vis(vis, r->vpl + (size_t)o * r->nvpl, r->nvpl,
                                  lr_scene_object_at(r->s, o)->coeffs.eta, x, rc->normal, E,
                                  E + 3);
    /* Translucent radiosity: what the VPLs do not carry, per light at unit intensity
     * (render/passes/irradiance.c adds the same to the GPU's grid). */
    for (int l = 0; l < r->nlight; l++) {
        const float *X = lr_tr_scene_recv_E(r->tr, i, l);
        for (int c = 0; X && c < 3; c++)
            E[c] += r->I[l][c] * X[3 * (size_t)k + (size_t)c];
    }
}

/* render.opening_light (render/openings/openings.h): the inner faces' light through the
 * openings, per light at unit intensity times the intensity, added to the grid before the
 * bounce reads it (as the GPU's irradiance pass adds the same grids to its own). */
static int opening_light(rctx *r, lr_err *e)
{
    const size_t n = (size_t)LR_RECV_GRID * LR_RECV_GRID;
    for (int i = 0; i < r->nrecv && r->op; i++)
        for (int l = 0; l < r->nlight; l++) {
            const float *X = lr_openings_grid(r->op, i, l);
            for (size_t k = 0; X && r->grid[i] && k < n; k++)
                for (int c = 0; c < 3; c++)
                    r->grid[i][6 * k + (size_t)c] += r->I[l][c] * X[3 * k + (size_t)c];
        }
    (void)e;
    return LR_OK;
}

/* render.receiver_bounce (render/bounce/rbounce.h): the receivers' radiosity with
 * E = sum_l I_l E_dir,l + the grid's E_vpl (this grid sums the lights with their intensities;
 * by linearity the GPU's per-light solves at unit intensity give the same), its bounce kept
 * per receiver grid texel (r->bounce) and added at every receiver pixel, as the GPU's
 * irradiance pass adds it to its own grid. The reference mode solves from the same VPL grid
 * (the GPU's E), so its receivers differ from the GPU's by the VPL sum alone. */
static int receiver_bounce(rctx *r, lr_err *e)
{
    lr_rbounce *rb = NULL;
    int rc = lr_rbounce_update(&rb, r->s, NULL, e);
    if (rc || !rb) {
        lr_rbounce_destroy(rb);
        return rc;
    }
    for (int i = 0; i < r->nrecv; i++)
        lr_rbounce_vpl_d(rb, i, r->grid[i], 6);
    rc = lr_rbounce_solve(rb, 0, (const double(*)[3])r->I, e);
    const size_t n = (size_t)LR_RECV_GRID * LR_RECV_GRID;
    if (!rc && !(r->bounce = calloc((size_t)r->nrecv, sizeof *r->bounce)))
        rc = lr_err_set(e, LR_ENOMEM, "cpu render: receiver bounce: out of memory");
    for (int i = 0; i < r->nrecv && !rc; i++) {
        const float *Eb = lr_rbounce_grid(rb, i, 0);
        if (!Eb || !r->grid[i])
            continue;
        if (!(r->bounce[i] = malloc(3 * n * sizeof **r->bounce))) {
            rc = lr_err_set(e, LR_ENOMEM, "cpu render: receiver bounce: out of memory");
            break;
        }
        for (size_t k = 0; k < 3 * n; k++)
            r->bounce[i][k] = Eb[k];
    }
    if (rc || !lr_rbounce_objects(rb)) {
        lr_rbounce_destroy(rb);
        return rc;
    }
    /* Kept for the pixels: the receivers' light on the objects. */
    if (!(r->rl_k = calloc((size_t)r->nobj * 6, sizeof *r->rl_k))) {
        lr_rbounce_destroy(rb);
        return lr_err_set(e, LR_ENOMEM, "cpu render: out of memory");
    }
    for (int o = 0; o < r->nobj; o++)
        lr_objlight_factors(lr_scene_object_at(r->s, o), r->rl_k + 6 * (size_t)o,
                            r->rl_k + 6 * (size_t)o + 3);
    r->rb = rb;
    return LR_OK;
}

/* Adds w times the bilinear value at x of a receiver grid (LR_RECV_GRID^2 texels, `stride`
 * values each, the three read from `off`), as the GPU samples its grids: over texel centres. */
static void grid_bilinear_add(const lr_receiver *rc, lr_vec3 x, const double *g, int stride,
                              int off, const double w[3], double E[3])
{
    lr_recv_grid_frame f;
    if (!lr_recv_grid_frame_of(rc, &f))
        return;
    int ti[4];
    double tw[4];
    lr_recv_grid_taps(&f, x, ti, tw);
    for (int q = 0; q < 4; q++)
        for (int c = 0; c < 3; c++)
            E[c] += w[c] * tw[q] * g[(size_t)stride * (size_t)ti[q] + (size_t)off + (size_t)c];
}

/* render.receiver_light_on_objects: the receivers' light on object o at the camera ray's hit
 * of its triangle (barycentrics, as the GPU interpolates its per-vertex varyings), on the side
 * the GPU takes (gl_FrontFacing: the triangle's winding against the ray), already weighted by
 * the lights' intensities: F_t(w_o) / pi (kR E+ + kT E-), the back side of an open object
 * kR E- + kT E+ (objlight.h). Adds to L. */
static void receiver_light(const rctx *r, int o, lr_vec3 org, lr_vec3 dir, double ft,
                           double L[3])
{
    const lr_scene_object *ob = lr_scene_object_at(r->s, o);
    lr_hit hit;
    if (!lr_bvh_intersect(ob->bvh, org, dir, 0.0, INFINITY, &hit))
        return;
    double E[6];
    lr_objlight_at(lr_rbounce_objects(r->rb), o, 0, hit.triangle, hit.u, hit.v, E);
    bool back = !ob->closed && lr_v3_dot(lr_mesh_triangle_normal(ob->mesh, hit.triangle), dir) > 0.0;
    const double *k = r->rl_k + 6 * (size_t)o;
    for (int c = 0; c < 3; c++) {
        double B = back ? k[c] * E[3 + c] + k[3 + c] * E[c] : k[c] * E[c] + k[3 + c] * E[3 + c];
        L[c] += ft / M_PI * B; /* seed 003 Eq. 5 */
    }
}

/* render.lpv: adds to B the volume's light on object o for light l at (x, n), per unit
 * intensity: kR E(x, n) + kT E(x, -n) (render/lpv/objfield.h; lib/lpv_object.glsl). */
static void lpv_object_B(const rctx *r, int o, int l, lr_vec3 x, lr_vec3 n, double B[3])
{
    const double *k = r->lpv_k + 6 * (size_t)o;
    double E[3], Eb[3] = {0, 0, 0};
    lr_lpv_objfield_irradiance(r->lpv_obj[l], x, n, E);
    if (k[3] > 0.0 || k[4] > 0.0 || k[5] > 0.0)
        lr_lpv_objfield_irradiance(r->lpv_obj[l], x, lr_v3_scale(n, -1.0), Eb);
    for (int c = 0; c < 3; c++)
        B[c] += k[c] * E[c] + k[3 + c] * Eb[c];
}

/* Nearest hit of the camera ray among objects (kind 0) and receivers (kind 1). */
static bool trace(const lr_scene *s, lr_vec3 org, lr_vec3 dir, int *kind, int *index, lr_vec3 *x,
                  lr_vec3 *n)
{
    double best = INFINITY;
    lr_hit h;
    bool any = false;
    for (int i = 0; i < lr_scene_object_count(s); i++)
        if (lr_bvh_intersect(lr_scene_object_at(s, i)->bvh, org, dir, 0.0, best, &h) && h.t < best) {
            best = h.t;
            *kind = 0;
            *index = i;
            any = true;
        }
    for (int i = 0; i < lr_scene_receiver_count(s); i++)
        if (lr_bvh_intersect(lr_scene_receiver_at(s, i)->bvh, org, dir, 0.0, best, &h) &&
            h.t < best) {
            best = h.t;
            *kind = 1;
            *index = i;
            any = true;
            *n = lr_mesh_triangle_normal(lr_scene_receiver_at(s, i)->mesh, h.triangle);
        }
    if (!any)
        return false;
    if (*kind == 0) {
        /* Same hit again, now with the interpolated normal. */
        lr_first_surface(lr_scene_object_at(s, *index), org, dir, 0.0, x, n);
    } else {
        *x = lr_v3_add(org, lr_v3_scale(dir, best));
    }
    return true;
}

static void pixel_item(void *p, long item);

typedef struct pixel_span {
    rctx *r;
    long base;
} pixel_span;

static void span_item(void *p, long item)
{
    pixel_span *s = p;
    pixel_item(s->r, s->base + item);
}

/* Every pixel; with a progress listener in sixteen spans, reported as each ends (the items
 * are independent, so the split changes nothing but the reports). */
static void render_pixels(rctx *r)
{
    const lr_progress *pg = r->d->progress;
    long n = (long)r->W * r->H;
    if (!pg || !pg->fn) {
        lr_parallel_for(n, r->d->threads, pixel_item, r);
        return;
    }
    enum { SPANS = 16 };
    lr_progress_report(pg, "cpu pixels", 0, SPANS);
    for (int k = 0; k < SPANS; k++) {
        pixel_span s = {r, n * k / SPANS};
        lr_parallel_for(n * (k + 1) / SPANS - s.base, r->d->threads, span_item, &s);
        lr_progress_report(pg, "cpu pixels", k + 1, SPANS);
    }
}

static void pixel_item(void *p, long item)
{
    rctx *r = p;
    int px = (int)(item % r->W), py = (int)(item / r->W);
    float *out = r->rgb->rgb + 3 * item;
    float *vout = r->var ? r->var->rgb + 3 * item : NULL;
    lr_vec3 org, dir, x, n;
    lr_cpu_camera_ray(r->s, r->W, r->H, px, py, &org, &dir);
    int kind = -1, idx = -1;
    if (!trace(r->s, org, dir, &kind, &idx, &x, &n))
        return;
    double L[3] = {0}, V[3] = {0};
    if (kind == 0) {
        r->object_px[item] = 1;
        const lr_scene_object *o = lr_scene_object_at(r->s, idx);
        if (!o->closed && lr_v3_dot(n, dir) > 0.0)
            n = lr_v3_scale(n, -1.0); /* two-sided open surface: the side the camera sees */
        /* The surface cache's entry: the hit's parent triangle and barycentrics, and the side
         * the GPU takes (gl_FrontFacing: the triangle's winding against the ray). */
        lr_hit hit;
        bool cached = r->cache && lr_bvh_intersect(o->bvh, org, dir, 0.0, INFINITY, &hit);
        int side = cached && !o->closed &&
                   lr_v3_dot(lr_mesh_triangle_normal(o->mesh, hit.triangle), dir) > 0.0;
        double cos_o = -lr_v3_dot(n, dir);
        double ft = lr_fresnel_transmittance(cos_o > 0.0 ? cos_o : 0.0, o->coeffs.eta);
        for (int l = 0; l < r->nlight; l++) {
            double B[3], var[3];
            bool fb = false;
            if (cached)
                cached_at(r, idx, l, side, hit.triangle, hit.u, hit.v, B, var, &fb);
            else
                radiosity_at(r, idx, l, x, n,
                             lr_rng_key(seed_of(r), (uint64_t)item, (uint64_t)l, 1), B, var, &fb);
            if (fb)
                r->fallback_px[item] = 1;
            if (r->lpv_obj && r->lpv_obj[l])
                lpv_object_B(r, idx, l, x, n, B);
            for (int c = 0; c < 3; c++) {
                double k = r->I[l][c] * ft / M_PI; /* seed 003 Eq. 5 */
                L[c] += k * B[c];
                V[c] += k * k * var[c];
            }
        }
        if (r->rb)
            receiver_light(r, idx, org, dir, ft, L);
    } else {
        const lr_receiver *rc = lr_scene_receiver_at(r->s, idx);
        double E[3] = {0}, EV[3] = {0};
        for (int l = 0; l < r->nlight; l++) {
            double ed = direct_at(r, l, x, n);
            for (int c = 0; c < 3; c++)
                E[c] += r->I[l][c] * ed;
        }
        static const double one[3] = {1.0, 1.0, 1.0};
        for (int l = 0; r->lpv && l < r->nlight; l++) {
            const double *g = r->lpv[(size_t)idx * r->nlight + l];
            if (g)
                grid_bilinear_add(rc, x, g, 3, 0, r->I[l], E);
        }
        if (!r->d->no_vpl && r->grid && r->grid[idx]) {
            /* The GPU's receiver irradiance grid (E, then its variance). */
            grid_bilinear_add(rc, x, r->grid[idx], 6, 0, one, E);
            grid_bilinear_add(rc, x, r->grid[idx], 6, 3, one, EV);
        } else if (!r->d->no_vpl) {
            const lr_scene *vis = lr_scene_render(r->s)->vpl_visibility ? r->s : NULL;
            for (int o = 0; o < r->nobj; o++)
                lr_vpl_point_irradiance_vis(vis, r->vpl + (size_t)o * r->nvpl, r->nvpl,
                                          lr_scene_object_at(r->s, o)->coeffs.eta, x, n, E, EV);
            /* render.opening_light at the pixel itself (the PASS grid's cells, exactly). */
            for (int l = 0; r->op && l < r->nlight; l++) {
                double Eo[3] = {0, 0, 0};
                lr_openings_irradiance_at(r->op, r->s, l, x, n, Eo);
                for (int c = 0; c < 3; c++)
                    E[c] += r->I[l][c] * Eo[c];
            }
        }
        if (!r->d->no_vpl && r->bounce && r->bounce[idx]) /* the receivers' bounce */
            grid_bilinear_add(rc, x, r->bounce[idx], 3, 0, one, E);
        for (int c = 0; c < 3; c++) {
            L[c] = rc->albedo[c] / M_PI * E[c];
            V[c] = rc->albedo[c] * rc->albedo[c] / (M_PI * M_PI) * EV[c];
        }
    }
    for (int c = 0; c < 3; c++) {
        out[c] = (float)L[c];
        if (vout)
            vout[c] = (float)V[c];
    }
}

/* render.lpv: the light-propagation volume's grids on the CPU (the GPU propagates the same
 * volumes with the compute shader; 2 further bounces off the objects, as there). */
static int lpv_grids(rctx *r, int n, lr_err *e)
{
    const size_t texels = (size_t)LR_RECV_GRID * LR_RECV_GRID;
    r->lpv = calloc((size_t)r->nrecv * r->nlight, sizeof *r->lpv);
    if (!r->lpv)
        return lr_err_set(e, LR_ENOMEM, "cpu render: out of memory");
    double **out = calloc((size_t)r->nrecv, sizeof *out);
    if (!out)
        return lr_err_set(e, LR_ENOMEM, "cpu render: out of memory");
    r->lpv_obj = calloc((size_t)r->nlight, sizeof *r->lpv_obj);
    r->lpv_k = calloc((size_t)r->nobj * 6, sizeof *r->lpv_k);
    if (!r->lpv_obj || !r->lpv_k) {
        free(out);
        return lr_err_set(e, LR_ENOMEM, "cpu render: out of memory");
    }
    for (int o = 0; o < r->nobj; o++)
        lr_lpv_object_factors(lr_scene_object_at(r->s, o), r->lpv_k + 6 * (size_t)o,
                              r->lpv_k + 6 * (size_t)o + 3);
    lr_lpv_scene_desc d = {.n = n, .bounces = 2};
    int rc = LR_OK;
    for (int l = 0; l < r->nlight && !rc; l++) {
        if ((rc = lr_lpv_objfield_create(&r->lpv_obj[l], e)))
            break;
        d.objects = r->lpv_obj[l];
        for (int i = 0; i < r->nrecv && !rc; i++) {
            out[i] = NULL;
            lr_recv_grid_frame f;
            if (!lr_recv_grid_frame_of(lr_scene_receiver_at(r->s, i), &f))
                continue;
            if (!(out[i] = r->lpv[(size_t)i * r->nlight + l] =
                      malloc(sizeof(double) * 3 * texels)))
                rc = lr_err_set(e, LR_ENOMEM, "cpu render: out of memory");
        }
        if (!rc)
            rc = lr_lpv_scene_indirect(r->s, l, &d, out, NULL, e);
    }
    free(out);
    return rc;
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

int lr_cpu_render(const lr_cpu_render_desc *d, lr_image *rgb, lr_image *var,
                  lr_cpu_render_stats *stats, lr_err *e)
{
    if (!d || !d->scene || !rgb)
        return lr_err_set(e, LR_EINVAL, "cpu render: NULL %s", !d ? "descriptor" : !d->scene ? "scene" : "image");
    double t0 = now_s();
    const lr_scene *s = d->scene;
    const lr_render_settings *rs = lr_scene_render(s);
    rctx r = {.d = d, .s = s};
    r.W = d->width ? d->width : 160;
    r.H = d->height ? d->height : 120;
    r.nobj = lr_scene_object_count(s);
    r.nlight = lr_scene_light_count(s);
    bool ref = d->mode == LR_CPU_REFERENCE;
    r.nvpl = d->no_vpl ? 0 : d->vpl_count ? d->vpl_count : ref ? 1024 : rs->N_vpl;
    r.samples = d->samples ? d->samples : 1024;
    int frames = d->frames ? d->frames : rs->frames;
    int rc = LR_OK;
    memset(rgb, 0, sizeof *rgb);
    if (var)
        memset(var, 0, sizeof *var);
    if ((rc = lr_image_alloc(rgb, r.W, r.H, e)) || (var && (rc = lr_image_alloc(var, r.W, r.H, e))))
        goto fail;
    r.rgb = rgb;
    r.var = var;
    r.I = calloc((size_t)r.nlight, sizeof *r.I);
    r.maps = calloc((size_t)r.nobj * r.nlight, sizeof *r.maps);
    r.vpl = calloc((size_t)r.nobj * (r.nvpl ? r.nvpl : 1), sizeof *r.vpl);
    r.object_px = calloc((size_t)r.W * r.H, sizeof *r.object_px);
    r.fallback_px = calloc((size_t)r.W * r.H, sizeof *r.fallback_px);
    r.objs = calloc((size_t)r.nobj, sizeof *r.objs);
    r.gain = calloc((size_t)r.nobj * r.nlight + 1, sizeof *r.gain);
    r.sh = calloc((size_t)r.nobj * r.nlight + 1, sizeof *r.sh);
    if (!r.I || !r.objs || !r.gain || !r.sh || !r.maps || !r.vpl || !r.object_px || !r.fallback_px) {
        rc = lr_err_set(e, LR_ENOMEM, "cpu render: out of memory");
        goto fail;
    }
    r.fl = calloc((size_t)r.nlight, sizeof *r.fl);
    r.nfl = calloc((size_t)r.nlight, sizeof *r.nfl);
    if (!r.fl || !r.nfl) {
        rc = lr_err_set(e, LR_ENOMEM, "cpu render: out of memory");
        goto fail;
    }
    for (int l = 0; l < r.nlight; l++) {
        const lr_light *li = lr_scene_light_at(s, l);
        lr_light_rgb(li, r.I[l]);
        int nf = !lr_light_is_area(li) ? 1 : ref ? LR_REF_AREA_FRAMES : frames;
        if (!(r.fl[l] = calloc((size_t)nf, sizeof *r.fl[l]))) {
            rc = lr_err_set(e, LR_ENOMEM, "cpu render: out of memory");
            goto fail;
        }
        r.nfl[l] = nf;
        lr_area_sequence seq;
        bool area = lr_light_is_area(li) && lr_area_sequence_make(li, &seq, NULL) == LR_OK;
        for (int f = 0; f < nf; f++) {
            r.fl[l][f] = *li;
            if (area)
                r.fl[l][f].position = lr_area_frame_point(&seq, f);
        }
    }
    for (int o = 0; o < r.nobj; o++)
        r.objs[o] = lr_scene_object_at(s, o);
    /* sh_translucency: each light's environment through the GPU's G-buffer texels. */
    for (int l = 0; l < r.nlight; l++) {
        lr_gb_camera cam;
        lr_gb_camera_scene(s, l, &cam);
        for (int o = 0; o < r.nobj; o++)
            if (lr_sss_model_props_of(r.objs[o]->sss_model)->light_env)
                lr_cpu_sh_env(r.objs[o], lr_scene_light_at(s, l), &cam, rs->gbuffer_size, r.objs,
                              r.nobj, d->threads, &r.sh[o * r.nlight + l]);
    }
    for (int l = 0; l < r.nlight; l++) {
        double(*g)[3] = calloc((size_t)r.nobj + 1, sizeof *g);
        if (!g) {
            rc = lr_err_set(e, LR_ENOMEM, "cpu render: out of memory");
            goto fail;
        }
        rc = lr_cavity_scene_gains(s, l, d->threads, g, r.nobj, e);
        for (int o = 0; o < r.nobj && !rc; o++)
            for (int c = 0; c < 3; c++)
                r.gain[o * r.nlight + l][c] = g[o][c];
        free(g);
        if (rc)
            goto fail;
    }
    for (int o = 0; o < r.nobj && !r.dscene; o++)
        if (lr_sss_model_props_of(lr_scene_object_at(s, o)->sss_model)->grid_field) {
            if ((rc = lr_dscene_create(&r.dscene, e)) || (rc = lr_dscene_update(r.dscene, s, e)))
                goto fail;
        }
    double samples = 0.0;
    if (!ref && (rc = lr_tr_scene_update(&r.tr, s, NULL, e)))
        goto fail;
    if (!ref) {
        for (int o = 0; o < r.nobj; o++)
            for (int l = 0; l < r.nlight; l++) {
                lr_progress_report(d->progress, "cpu maps", o * r.nlight + l, r.nobj * r.nlight);
                lr_cpu_maps_desc md = {.object = lr_scene_object_at(s, o),
                                       .light = lr_scene_light_at(s, l),
                                       .K = d->K ? d->K : rs->K,
                                       .map_size = d->map_size ? d->map_size : rs->map_size,
                                       .N = d->N ? d->N : rs->N,
                                       .seed = (unsigned)lr_rng_key(seed_of(&r), (uint64_t)o,
                                                                    (uint64_t)l, 2),
                                       .threads = d->threads,
                                       .others = r.objs,
                                       .n_others = r.nobj,
                                       .tr = r.tr, .tr_object = o, .tr_light = l,
                                       .sh_env = r.sh + o * r.nlight + l};
                if (r.dscene)
                    lr_dscene_field(r.dscene, o, l, &md.dfield);
                lr_cpu_maps **m = &r.maps[o * r.nlight + l];
                if ((rc = lr_cpu_maps_create(&md, m, e)))
                    goto fail;
                lr_cpu_maps_accumulate(*m, frames);
                int K = lr_cpu_maps_count(*m), S = lr_cpu_maps_size(*m);
                for (int k = 0; k < K; k++)
                    for (int j = 0; j < S; j++)
                        for (int i = 0; i < S; i++)
                            if (lr_cpu_maps_texel(*m, k, i, j)->valid)
                                samples += 3.0 * md.N * frames;
            }
    }
    /* The GPU's surface cache (render.surface_cache): B at the lattice points. */
    if (!ref && rs->surface_cache) {
        int msize = d->map_size ? d->map_size : rs->map_size;
        r.ref = calloc((size_t)r.nobj, sizeof *r.ref);
        r.cache = calloc((size_t)r.nobj, sizeof *r.cache);
        r.cache_first = calloc((size_t)r.nobj + 1, sizeof *r.cache_first);
        if (!r.ref || !r.cache || !r.cache_first) {
            rc = lr_err_set(e, LR_ENOMEM, "cpu render: out of memory");
            goto fail;
        }
        size_t total = 0;
        for (int o = 0; o < r.nobj; o++) {
            double h;
            size_t budget = LR_SURFACE_MAX_VERTICES > total ? LR_SURFACE_MAX_VERTICES - total : 1;
            if ((rc = lr_surface_refine(s, o, msize, budget, &r.ref[o], &h, e)))
                goto fail;
            size_t entries = r.ref[o].nv * (size_t)sides(&r, o);
            total += entries;
            r.cache_first[o + 1] = r.cache_first[o] + (long)entries;
            r.cache[o] = calloc(entries * (size_t)r.nlight * CACHE_DOUBLES, sizeof **r.cache);
            if (!r.cache[o]) {
                rc = lr_err_set(e, LR_ENOMEM, "cpu render: surface cache: out of memory");
                goto fail;
            }
        }
        lr_parallel_for(r.cache_first[r.nobj], d->threads, cache_item, &r);
    }
    int nv = 0;
    /* render.opening_light: both modes (PASS through the grid, REFERENCE per pixel). */
    if (r.nvpl > 0 && (rc = lr_openings_update(&r.op, s, r.dscene, d->threads, e)))
        goto fail;
    if (r.nvpl > 0) {
        for (int o = 0; o < r.nobj; o++)
            lr_vpl_place(lr_scene_object_at(s, o), r.nvpl, r.vpl + (size_t)o * r.nvpl);
        lr_parallel_for((long)r.nobj * r.nvpl, d->threads, vpl_item, &r);
        for (long v = 0; v < (long)r.nobj * r.nvpl; v++)
            nv += r.vpl[v].valid;
        if (ref)
            samples += 3.0 * r.samples * nv * r.nlight;
    }
    /* The twin of the GPU's receiver irradiance grids (PASS; the reference sums the VPLs at
     * every pixel, and builds them only for the receiver bounce's E). The variance is
     * interpolated like E (the taps share their VPLs). */
    r.nrecv = lr_scene_receiver_count(s);
    const bool bounce = lr_rbounce_needed(s);
    if ((!ref || bounce) && r.nvpl > 0 && r.nrecv > 0) {
        const size_t n = (size_t)LR_RECV_GRID * LR_RECV_GRID;
        r.grid = calloc((size_t)r.nrecv, sizeof *r.grid);
        if (!r.grid) {
            rc = lr_err_set(e, LR_ENOMEM, "cpu render: out of memory");
            goto fail;
        }
        for (int i = 0; i < r.nrecv; i++) {
            lr_recv_grid_frame f;
            if (!lr_recv_grid_frame_of(lr_scene_receiver_at(s, i), &f))
                continue;
            if (!(r.grid[i] = calloc(6 * n, sizeof **r.grid))) {
                rc = lr_err_set(e, LR_ENOMEM, "cpu render: receiver grid: out of memory");
                goto fail;
            }
        }
        lr_parallel_for((long)(r.nrecv * n), d->threads, grid_item, &r);
        if ((rc = opening_light(&r, e)) || (rc = receiver_bounce(&r, e)))
            goto fail;
        if (ref) { /* the reference's pixels sum the VPLs themselves */
            for (int i = 0; i < r.nrecv; i++)
                free(r.grid[i]);
            free(r.grid);
            r.grid = NULL;
        }
    }
    if (!ref && lr_scene_render(s)->lpv > 0 && r.nrecv > 0 &&
        (rc = lpv_grids(&r, lr_scene_render(s)->lpv, e)))
        goto fail;
    if (!ref)
        lr_progress_report(d->progress, "cpu maps", r.nobj * r.nlight, r.nobj * r.nlight);
    render_pixels(&r);
    long objpx = 0, fbpx = 0;
    for (long i = 0; i < (long)r.W * r.H; i++) {
        objpx += r.object_px[i];
        fbpx += r.fallback_px[i];
    }
    if (ref)
        samples += 3.0 * r.samples * objpx * r.nlight;
    if (stats) {
        memset(stats, 0, sizeof *stats);
        stats->seconds = now_s() - t0;
        stats->samples = samples;
        stats->samples_per_s = stats->seconds > 0 ? samples / stats->seconds : 0;
        stats->object_pixels = objpx;
        stats->fallback_pixels = fbpx;
        stats->vpls = nv;
    }
fail:
    lr_rbounce_destroy(r.rb);
    free(r.rl_k);
    lr_tr_scene_destroy(r.tr);
    lr_openings_destroy(r.op);
    for (int o = 0; o < r.nobj && r.ref; o++)
        lr_refined_free(&r.ref[o]);
    for (int o = 0; o < r.nobj && r.cache; o++)
        free(r.cache[o]);
    free(r.ref);
    free(r.cache);
    free(r.cache_first);
    if (r.grid)
        for (int i = 0; i < r.nrecv; i++)
            free(r.grid[i]);
    free(r.grid);
    if (r.bounce)
        for (int i = 0; i < r.nrecv; i++)
            free(r.bounce[i]);
    free(r.bounce);
    if (r.lpv)
        for (int i = 0; i < r.nrecv * r.nlight; i++)
            free(r.lpv[i]);
    free(r.lpv);
    for (int l = 0; r.lpv_obj && l < r.nlight; l++)
        lr_lpv_objfield_destroy(r.lpv_obj[l]);
    free(r.lpv_obj);
    free(r.lpv_k);
    if (r.maps)
        for (int i = 0; i < r.nobj * r.nlight; i++)
            lr_cpu_maps_destroy(r.maps[i]);
    free(r.maps);
    lr_dscene_destroy(r.dscene); /* after the maps, which point into it */
    if (r.fl)
        for (int l = 0; l < r.nlight; l++)
            free(r.fl[l]);
    free(r.fl);
    free(r.nfl);
    free(r.vpl);
    free(r.I);
    free(r.gain);
    free(r.sh);
    free(r.object_px);
    free(r.fallback_px);
    free(r.objs);
    if (rc) {
        lr_image_free(rgb);
        if (var)
            lr_image_free(var);
    }
    return rc;
}
