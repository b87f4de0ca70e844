/* Cavity gain: see cavity.h. */
#include "render/core/cavity.h"

#include <math.h>
#include <stdlib.h>

#include "render/base/parallel.h"
#include "render/base/rng.h"
#include "render/core/ray.h"
#include "render/mesh/area_pick.h"
#include "render/mesh/bvh.h"
#include "render/optics/optics.h"

typedef struct point_ctx {
    const lr_scene_object *obj;
    const lr_light *light;
    const double *cdf; /* triangle area CDF, last = 1 */
    size_t nt;
    int npts, N;
    unsigned seed;
    lr_cavity_sample_fn B;
    const void *B_ctx;
    double (*P)[3];    /* per point: B of its unlit side(s) */
} point_ctx;

/* Whether the light sees side n of surface point x (the light G-buffer's first surface there,
 * facing the light). */
static bool lit_side(const lr_scene_object *o, lr_vec3 xl, lr_vec3 x, lr_vec3 n)
{
    lr_vec3 to = lr_v3_sub(x, xl);
    double d = lr_v3_len(to);
    if (!(d > 0.0) || !(lr_v3_dot(n, to) < 0.0))
        return false;
    lr_vec3 u = lr_v3_scale(to, 1.0 / d);
    return !lr_bvh_occluded(o->bvh, xl, u, 1e-9 * o->radius, d - 1e-6 * o->radius);
}

/* Surface point i of npts, stratified over the area CDF (point i in the i-th 1/npts of the
 * surface's area, in the mesh's triangle order), which keeps the points spread over the whole
 * surface; n its face's outward normal. */
static void surface_point(const lr_scene_object *o, const double *cdf, size_t nt, long i,
                          int npts, lr_rng *rng, lr_vec3 *x, lr_vec3 *n)
{
    double pick = (i + lr_rng_next(rng)) / npts;
    double s = lr_rng_next(rng), t = lr_rng_next(rng);
    lr_vec3 v[3];
    lr_mesh_triangle(o->mesh, lr_cdf_pick(cdf, nt, pick), v); /* first triangle with cdf > pick */
    *x = lr_triangle_fold_point(v, s, t);
    *n = lr_v3_normalize(lr_v3_cross(lr_v3_sub(v[1], v[0]), lr_v3_sub(v[2], v[0])));
}

static void point_item(void *p, long i)
{
    point_ctx *k = p;
    const lr_scene_object *o = k->obj;
    lr_rng rng = lr_rng_init(lr_rng_key(k->seed, 0xCA71, (uint64_t)i, 0));
    lr_vec3 x, n;
    surface_point(o, k->cdf, k->nt, i, k->npts, &rng, &x, &n);
    /* Closed: the outward side only. Open (two-sided): both sides emit. */
    for (int side = 0; side < (o->closed ? 1 : 2); side++) {
        lr_vec3 ns = side ? lr_v3_scale(n, -1.0) : n;
        if (lit_side(o, k->light->position, x, ns))
            continue;
        double b[3] = {0.0, 0.0, 0.0};
        k->B(k->B_ctx, x, ns, k->N, lr_rng_key(k->seed, 0xCA72, (uint64_t)i, (uint64_t)side), b);
        for (int c = 0; c < 3; c++)
            k->P[i][c] += b[c];
    }
}

/* C, R_1, F and the power entering (cavity.h): the light's power per unit intensity over
 * Halton directions (4 pi / ndir each, weighted by the spot profile) where the first surface is
 * the object's front; from each such point one cosine-distributed ray into the cavity tells
 * whether the light it sends back meets the object again. */
static void cavity_geometry(const lr_scene_object *obj, const lr_light *l, int ndir,
                            unsigned seed, lr_cavity *out)
{
    double eta = obj->coeffs.eta, hit = 0.0, entered = 0.0, rehit = 0.0, w = 4.0 * M_PI / ndir;
    lr_rng rng = lr_rng_init(lr_rng_key(seed, 0xCA70, 0, 0));
    for (int i = 0; i < ndir; i++) {
        lr_vec3 u = lr_halton_sphere((unsigned)i + 1), xi, ni;
        double shape = lr_light_shape(l, u);
        double xi1 = lr_rng_next(&rng), xi2 = lr_rng_next(&rng);
        if (!(shape > 0.0) ||
            !lr_first_surface(obj, l->position, u, 1e-9 * obj->radius, &xi, &ni))
            continue;
        if (!obj->closed && lr_v3_dot(ni, u) > 0.0)
            ni = lr_v3_scale(ni, -1.0); /* open surfaces are two-sided */
        double mu = -lr_v3_dot(ni, u);
        if (!(mu > 0.0))
            continue; /* met from behind: no light enters (PIPELINE.md) */
        hit += w * shape;
        entered += w * shape * lr_fresnel_transmittance(mu, eta);
        lr_vec3 t1, t2;
        lr_tangents(ni, &t1, &t2);
        double rr = sqrt(xi1), ph = 2.0 * M_PI * xi2, z = sqrt(fmax(0.0, 1.0 - xi1));
        lr_vec3 dir = lr_v3_add(lr_v3_scale(ni, z), lr_v3_add(lr_v3_scale(t1, rr * cos(ph)),
                                                               lr_v3_scale(t2, rr * sin(ph))));
        if (lr_bvh_occluded(obj->bvh, xi, dir, 1e-6 * obj->radius, INFINITY))
            rehit += w * shape;
    }
    out->C = hit / (4.0 * M_PI);
    out->R1 = hit > 0.0 ? 1.0 - entered / hit : 0.0;
    out->F = hit > 0.0 ? rehit / hit : 0.0;
    out->entered = entered;
}

/* The triangle-area CDF of obj's mesh (last entry 1) and the total area; NULL with *area -1
 * when out of memory, 0 when the mesh has no area. */
static double *area_cdf(const lr_scene_object *obj, double *area)
{
    size_t nt = lr_mesh_triangle_count(obj->mesh);
    double *cdf = nt ? malloc(nt * sizeof *cdf) : NULL;
    *area = nt ? -1.0 : 0.0;
    if (!cdf)
        return NULL;
    *area = 0.0;
    for (size_t t = 0; t < nt; t++) {
        lr_vec3 v[3];
        lr_mesh_triangle(obj->mesh, t, v);
        *area += 0.5 * lr_v3_len(lr_v3_cross(lr_v3_sub(v[1], v[0]), lr_v3_sub(v[2], v[0])));
        cdf[t] = *area;
    }
    if (!(*area > 0.0)) {
        free(cdf);
        return NULL;
    }
    for (size_t t = 0; t < nt; t++)
        cdf[t] /= *area;
    cdf[nt - 1] = 1.0;
    return cdf;
}

static int no_area(const lr_scene_object *obj, double area, lr_err *e)
{
    return area < 0.0 ? lr_err_set(e, LR_ENOMEM, "cavity: out of memory")
                      : lr_err_set(e, LR_EINVAL, "cavity: object '%s' has no surface area",
                                   obj->name);
}

/* What both measurements start with: *out reset, and where the closure applies and light
 * enters, C, R_1, F and the power entering, and the surface's area CDF in *cdf (the caller
 * frees it). *cdf stays NULL when there is nothing more to measure. */
static int cavity_begin(const lr_scene_object *obj, const lr_light *l, bool applies,
                        const lr_cavity_desc *d, lr_cavity *out, double **cdf,
                        double *area, lr_err *e)
{
    *out = (lr_cavity){.gain = {1.0, 1.0, 1.0}, .applies = applies};
    *cdf = NULL;
    if (!applies)
        return LR_OK;
    cavity_geometry(obj, l, d && d->directions > 0 ? d->directions : 4096,
                    d && d->seed ? d->seed : 1, out);
    if (!(out->entered > 0.0))
        return LR_OK;
    return (*cdf = area_cdf(obj, area)) ? LR_OK : no_area(obj, *area, e);
}

/* The gain from C, R_1, F, b (cavity.h's geometric series), per band. */
static void cavity_gain(lr_cavity *out, double T)
{
    for (int c = 0; c < 3; c++) {
        double R1 = out->R1, F = out->F;
        double rho1 = R1 + (1.0 - R1) * out->b[c];
        double rhod = (1.0 - T) + T * out->b[c];
        double den = (1.0 - R1) * (1.0 - rhod * F);
        double g = den > 0.0 ? 1.0 + T * rho1 * F / den : LR_CAVITY_GAIN_MAX;
        out->gain[c] = isfinite(g) ? fmin(fmax(g, 1.0), LR_CAVITY_GAIN_MAX) : LR_CAVITY_GAIN_MAX;
    }
}

int lr_cavity_measure_energy(const lr_scene_object *obj, const lr_light *l, bool applies,
                             const double A[3], const lr_cavity_desc *d, lr_cavity_sample_fn B,
                             const void *ctx, lr_cavity *out, lr_err *e)
{
    if (!obj || !l || !out || !B || !A)
        return lr_err_set(e, LR_EINVAL, "cavity: NULL %s",
                          !obj ? "object" : !l ? "light" : !out ? "out" : !B ? "B" : "A");
    int npts = d && d->points > 0 ? d->points : 256;
    int N = d && d->N > 0 ? d->N : 64;
    unsigned seed = d && d->seed ? d->seed : 1;
    double area, *cdf;
    int rc = cavity_begin(obj, l, applies, d, out, &cdf, &area, e);
    if (rc || !cdf)
        return rc;

    /* a: power out of the surface the light does not see, T_hem int B dA, by points uniform
     * over the surface's area. */
    double(*P)[3] = calloc((size_t)npts, sizeof *P);
    if (!P) {
        free(cdf);
        return lr_err_set(e, LR_ENOMEM, "cavity: out of memory for %d points", npts);
    }
    point_ctx pc = {obj, l, cdf, lr_mesh_triangle_count(obj->mesh), npts, N, seed, B, ctx, P};
    lr_parallel_for(npts, d ? d->threads : 0, point_item, &pc);
    double T = lr_hemi_transmittance(obj->coeffs.eta);
    for (int c = 0; c < 3; c++) {
        double sum = 0.0;
        for (int i = 0; i < npts; i++)
            sum += P[i][c];
        out->out[c] = T * sum * area / npts;
        out->a[c] = out->out[c] / out->entered;
        out->b[c] = fmax(0.0, A[c] - out->a[c]);
    }
    cavity_gain(out, T);
    free(cdf);
    free(P);
    return LR_OK;
}

int lr_cavity_measure_field(const lr_scene_object *obj, const lr_light *l,
                                enum lr_enclosure enclosure, const lr_cavity_desc *d,
                                lr_cavity_b_fn B, const void *ctx, lr_cavity *out, lr_err *e)
{
    if (!obj || !l || !B || !out)
        return lr_err_set(e, LR_EINVAL, "cavity: NULL %s",
                          !obj ? "object" : !l ? "light" : !B ? "B" : "out");
    int npts = d && d->points > 0 ? d->points : 4096;
    unsigned seed = d && d->seed ? d->seed : 1;
    double area, *cdf;
    int rc = cavity_begin(obj, l, enclosure == LR_ENCLOSURE_HULL && l->type != LR_LIGHT_DIRECTIONAL,
                          d, out, &cdf, &area, e);
    if (rc || !cdf)
        return rc;
    /* The model's own split of what entered: power out of the surface the light does not see
     * (a) and out of the one it sees (b, the cavity side), both as the renderer emits them
     * (T_hem int B dA), by points stratified over the area. A finite-geometry model's
     * cavity-side B is what that side really sends back, so b comes from it, not from the
     * energy balance of a half-space profile (lr_cavity_measure). Closed meshes: the
     * outward side only. */
    size_t nt = lr_mesh_triangle_count(obj->mesh);
    double lit[3] = {0.0, 0.0, 0.0}, unlit[3] = {0.0, 0.0, 0.0};
    lr_rng rng = lr_rng_init(lr_rng_key(seed, 0xCA73, 0, 0));
    for (int i = 0; i < npts; i++) {
        lr_vec3 x, n;
        surface_point(obj, cdf, nt, i, npts, &rng, &x, &n);
        double b[3] = {0.0, 0.0, 0.0};
        B(ctx, x, n, b);
        double *sum = lit_side(obj, l->position, x, n) ? lit : unlit;
        for (int c = 0; c < 3; c++)
            sum[c] += isfinite(b[c]) ? b[c] : 0.0;
    }
    free(cdf);
    double T = lr_hemi_transmittance(obj->coeffs.eta);
    for (int c = 0; c < 3; c++) {
        out->out[c] = T * unlit[c] * area / npts;
        out->a[c] = out->out[c] / out->entered;
        out->b[c] = fmax(0.0, T * lit[c] * area / npts / out->entered);
    }
    cavity_gain(out, T);
    return LR_OK;
}
