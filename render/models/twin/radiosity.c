/* CPU twin of the scattered-radiosity pass (PIPELINE.md pass 2) and its untruncated reference.
 * See radiosity.h. */
#include "render/models/twin/radiosity.h"

#include <math.h>
#include <stdint.h>

#include "render/base/rng.h"
#include "render/models/twin/sh.h"
#include "render/optics/optics.h"

/* A light closer to x_o than this many bounding radii is taken to sit on it: the lookup sphere
 * through x_o would have radius 0, so the light is moved this far along n_o (only for the
 * stereographic map; rays still start at the light). */
#define LR_CPU_ON_SURFACE_EPS 1e-9
/* Rays from the light ignore hits closer than this many bounding radii (a light on the
 * surface must not see its own triangle at t = 0). */
#define LR_CPU_TMIN 1e-7

double lr_cpu_stereo_lookup(lr_vec3 xl, lr_vec3 xo, lr_vec3 no, lr_vec3 xj, lr_vec3 *v)
{
    lr_vec3 h = lr_v3_sub(xl, xo);
    double d = lr_v3_len(h);
    lr_vec3 A = lr_v3_add(xl, h); /* antipode of x_o on the sphere of radius d around x_l */
    lr_vec3 ja = lr_v3_sub(xj, A);
    double ja2 = lr_v3_dot(ja, ja);
    if (!(d > 0.0) || !(ja2 > 0.0)) {
        *v = lr_v3(0.0, 0.0, 0.0);
        return 0.0;
    }
    lr_vec3 l = lr_v3_scale(ja, 1.0 / sqrt(ja2));
    double hl = lr_v3_dot(h, l);
    /* seed 003 Eq. 13: x_stereo - x_l = h - 2 (h.l) l (the second intersection of the line
     * from A along l with the sphere). */
    *v = lr_v3_sub(h, lr_v3_scale(l, 2.0 * hl));
    /* PIPELINE.md: central projection from A of the plane patch onto the sphere (area ratio
     * t^2 |l.n_o| / (|xj - A|^2 |l.n_P|), |l.n_P| = |h.l| / d), over d^2 for solid angle. */
    double t = fabs(2.0 * hl);
    return 2.0 * t * fabs(lr_v3_dot(l, no)) / (d * ja2);
}

/* Everything one estimate needs, fixed per call. */
typedef struct ctx {
    const lr_scene_object *obj;
    const lr_light *light;
    lr_vec3 xo, no, t1, t2;
    lr_vec3 xl;   /* point/spot: light position */
    lr_vec3 xs;   /* point/spot: the light as the stereographic map sees it (moved off x_o) */
    double d;     /* |xs - xo| */
    lr_vec3 wl;   /* directional: travel direction */
    lr_vec3 cp;   /* directional reference: object centre projected into x_o's light plane */
    double tmin;
    int pairs; /* the multipole's pole pairs (lr_sss_pairs), once per estimate, not per sample */
    const lr_scene_object *const *others;
    int n_others;
    lr_vec3 (*snap)(void *, lr_vec3);
    void *snap_ctx;
} ctx;

/* The light G-buffer's view of the lit point: two-sided open surfaces face the light, and
 * another object nearer to the light along the ray takes the texel. */
static bool gbuffer_texel(const ctx *k, lr_vec3 org, lr_vec3 dir, double tmin, lr_vec3 *xi,
                          lr_vec3 *ni)
{
    if (!lr_first_surface(k->obj, org, dir, tmin, xi, ni))
        return false;
    if (!k->obj->closed && lr_v3_dot(*ni, dir) > 0.0)
        *ni = lr_v3_scale(*ni, -1.0);
    double t = lr_v3_len(lr_v3_sub(*xi, org));
    for (int i = 0; i < k->n_others; i++)
        if (k->others[i] != k->obj && lr_bvh_occluded(k->others[i]->bvh, org, dir, tmin, t))
            return false;
    return true;
}

/* pi S_d F_t for the surface seen from the light along unit vh (point/spot), band c;
 * 0 when the ray misses or the light cannot enter there. */
static double lit_point(const ctx *k, lr_vec3 vh, int c)
{
    lr_vec3 xi, ni;
    lr_vec3 look = k->snap ? lr_v3_normalize(k->snap(k->snap_ctx, vh)) : vh;
    if (!gbuffer_texel(k, k->xl, look, k->tmin, &xi, &ni))
        return 0.0;
    double shape = lr_light_shape(k->light, vh);
    if (!(shape > 0.0))
        return 0.0;
    double sd[3];
    /* w_i = -look points from x_i to the light; n_i . w_i <= 0 contributes 0 (PIPELINE.md). */
    lr_sss_sd_fresnel_n(k->obj->sss_model, &k->obj->coeffs, k->obj->thickness_mm, k->pairs, xi,
                        ni, lr_v3_scale(look, -1.0), k->xo, k->no, sd);
    return M_PI * sd[c] * shape;
}

/* The same for a directional light: the surface hit by the light's ray through plane point xj. */
static double lit_plane(const ctx *k, lr_vec3 xj, int c)
{
    const lr_scene_object *o = k->obj;
    if (k->snap)
        xj = k->snap(k->snap_ctx, xj);
    double back = lr_v3_dot(lr_v3_sub(xj, o->center), k->wl) + 1.01 * o->radius + 1.0;
    lr_vec3 org = lr_v3_sub(xj, lr_v3_scale(k->wl, back));
    lr_vec3 xi, ni;
    if (!gbuffer_texel(k, org, k->wl, 0.0, &xi, &ni))
        return 0.0;
    double sd[3];
    lr_sss_sd_fresnel_n(o->sss_model, &o->coeffs, o->thickness_mm, k->pairs, xi, ni,
                        lr_v3_scale(k->wl, -1.0), k->xo, k->no, sd);
    return M_PI * sd[c];
}

static lr_vec3 plane_point(const ctx *k, double r, double alpha)
{
    return lr_v3_add(k->xo, lr_v3_add(lr_v3_scale(k->t1, r * cos(alpha)),
                                      lr_v3_scale(k->t2, r * sin(alpha))));
}

/* One sample of the pass estimator (PIPELINE.md pass 2), band c. */
static double sample_pass(const ctx *k, int c, double rmax, lr_rng *rng)
{
    double sig = k->obj->coeffs.sigma_tr[c];
    double xi1 = lr_rng_next(rng), xi2 = lr_rng_next(rng);
    double r = lr_exp_radius_sample(sig, rmax, xi1);   /* seed 003 Eq. 12 (truncated) */
    double pr = lr_exp_radius_pdf(sig, rmax, r);       /* Eq. 11 */
    if (!(r > 0.0) || !(pr > 0.0))
        return 0.0;
    lr_vec3 xj = plane_point(k, r, 2.0 * M_PI * xi2);
    double inv_pA = 2.0 * M_PI * r / pr;               /* 1 / p_A, p_A = p(r) / (2 pi r) */
    if (k->light->type == LR_LIGHT_DIRECTIONAL)
        return lit_plane(k, xj, c) * inv_pA;           /* J = 1 */
    lr_vec3 v;
    double J = lr_cpu_stereo_lookup(k->xs, k->xo, k->no, xj, &v);
    if (!(J > 0.0))
        return 0.0;
    return lit_point(k, lr_v3_normalize(v), c) * J * inv_pA;
}

/* Reference plane strategy: a ladder of exponential rates, sigma_tr and sigma_t'/4^k down to
 * 1/radius, chosen uniformly (their mixture density is close to log-uniform in r over the
 * scales where S_d lives, so that albedo 1 (sigma_tr = 0, S_d ~ r^-3) and objects small
 * against 1/sigma_tr keep a finite, small variance). */
#define LR_CPU_MAX_RATES 16
typedef struct rates {
    int n;
    double r[LR_CPU_MAX_RATES];
} rates;

static rates ref_rates(const ctx *k, int c)
{
    rates out = {0};
    double s = k->obj->coeffs.sigma_tr[c], floor_rate = 1.0 / k->obj->radius;
    double lo = s > floor_rate ? s : floor_rate;
    out.r[out.n++] = lo;
    for (double q = k->obj->coeffs.sigma_t_prime[c]; q > 1.5 * lo && out.n < LR_CPU_MAX_RATES;
         q *= 0.25)
        out.r[out.n++] = q;
    return out;
}

static double rates_pdf(const rates *rt, double r)
{
    double p = 0.0;
    for (int i = 0; i < rt->n; i++)
        p += lr_exp_radius_pdf(rt->r[i], INFINITY, r);
    return p / rt->n;
}

static double rates_sample(const rates *rt, double pick, double xi)
{
    int i = (int)(pick * rt->n);
    if (i >= rt->n)
        i = rt->n - 1;
    return lr_exp_radius_sample(rt->r[i], INFINITY, xi);
}

/* Plane-strategy density per unit solid angle of direction vh (point/spot). */
static double plane_pdf_omega(const ctx *k, lr_vec3 vh, const rates *rt)
{
    lr_vec3 A = lr_v3_add(k->xs, lr_v3_sub(k->xs, k->xo));
    lr_vec3 P = lr_v3_add(k->xs, lr_v3_scale(vh, k->d));
    lr_vec3 pa = lr_v3_sub(P, A);
    double den = lr_v3_dot(k->no, pa);
    if (den == 0.0)
        return 0.0;
    double s = lr_v3_dot(k->no, lr_v3_sub(k->xo, A)) / den;
    lr_vec3 xj = lr_v3_add(A, lr_v3_scale(pa, s));
    double r = lr_v3_len(lr_v3_sub(xj, k->xo));
    lr_vec3 v;
    double J = lr_cpu_stereo_lookup(k->xs, k->xo, k->no, xj, &v);
    if (!(r > 0.0) || !(J > 0.0) || !isfinite(r))
        return 0.0;
    return rates_pdf(rt, r) / (2.0 * M_PI * r) / J;
}

/* Direction strategy: uniform in the cone from the light around the object's bounding sphere
 * (every lit point is inside it), or over the whole sphere when the light is inside it. */
static double cone_cos(const ctx *k, lr_vec3 *axis)
{
    lr_vec3 to = lr_v3_sub(k->obj->center, k->xl);
    double dist = lr_v3_len(to), R = 1.0001 * k->obj->radius;
    if (!(dist > R)) {
        *axis = lr_v3(0, 0, 1);
        return -1.0;
    }
    *axis = lr_v3_scale(to, 1.0 / dist);
    return sqrt(fmax(0.0, 1.0 - (R / dist) * (R / dist)));
}

static double sample_ref(const ctx *k, int c, lr_rng *rng)
{
    rates rt = ref_rates(k, c);
    double pick = lr_rng_next(rng);
    double xi1 = lr_rng_next(rng), xi2 = lr_rng_next(rng);
    if (k->light->type == LR_LIGHT_DIRECTIONAL) {
        /* Mixture of the exp ladder around x_o and uniform over the projected disk. */
        double R = 1.0001 * k->obj->radius;
        lr_vec3 xj;
        if (pick < 0.5) {
            double r = rates_sample(&rt, 2.0 * pick, xi1);
            xj = plane_point(k, r, 2.0 * M_PI * xi2);
        } else {
            double rr = R * sqrt(xi1), a = 2.0 * M_PI * xi2;
            xj = lr_v3_add(k->cp, lr_v3_add(lr_v3_scale(k->t1, rr * cos(a)),
                                            lr_v3_scale(k->t2, rr * sin(a))));
        }
        double r = lr_v3_len(lr_v3_sub(xj, k->xo));
        double p_exp = r > 0.0 ? rates_pdf(&rt, r) / (2.0 * M_PI * r) : 0.0;
        double p_disk = lr_v3_len(lr_v3_sub(xj, k->cp)) <= R ? 1.0 / (M_PI * R * R) : 0.0;
        double p = 0.5 * p_exp + 0.5 * p_disk;
        if (!(p > 0.0) || !isfinite(p))
            return 0.0;
        return lit_plane(k, xj, c) / p;
    }
    lr_vec3 axis, vh;
    double cmax = cone_cos(k, &axis);
    if (pick < 0.5) {
        double r = rates_sample(&rt, 2.0 * pick, xi1);
        if (!(r > 0.0) || !isfinite(r))
            return 0.0;
        lr_vec3 xj = plane_point(k, r, 2.0 * M_PI * xi2), v;
        if (!(lr_cpu_stereo_lookup(k->xs, k->xo, k->no, xj, &v) > 0.0))
            return 0.0;
        vh = lr_v3_normalize(v);
    } else {
        double z = 1.0 - (1.0 - cmax) * xi1, phi = 2.0 * M_PI * xi2;
        double s = sqrt(fmax(0.0, (1.0 - z) * (1.0 + z)));
        lr_vec3 a1, a2;
        lr_tangents(axis, &a1, &a2);
        vh = lr_v3_add(lr_v3_scale(axis, z),
                       lr_v3_add(lr_v3_scale(a1, s * cos(phi)), lr_v3_scale(a2, s * sin(phi))));
    }
    double p_cone = lr_v3_dot(vh, axis) >= cmax ? 1.0 / (2.0 * M_PI * (1.0 - cmax)) : 0.0;
    double p = 0.5 * plane_pdf_omega(k, vh, &rt) + 0.5 * p_cone;
    if (!(p > 0.0) || !isfinite(p))
        return 0.0;
    return lit_point(k, vh, c) / p;
}

/* Seed 002's sh_translucency (render/models/twin/sh.h): deterministic, so the variance is 0. Without a
 * precomputed environment one is projected here through a cube of LR_CPU_SH_FALLBACK_SIZE^2
 * texels per face around the light (the caller's G-buffer cameras are unknown here). */
#define LR_CPU_SH_FALLBACK_SIZE 32
static void sh_radiosity(const lr_scene_object *obj, const lr_light *light, lr_vec3 xo,
                         lr_vec3 no, const lr_cpu_radiosity_desc *d, lr_cpu_estimate *out)
{
    const lr_scene_object *const *others = d ? d->others : NULL;
    int n_others = d ? d->n_others : 0;
    lr_sh_env env;
    const lr_sh_env *use = d ? d->sh_env : NULL;
    if (!use) {
        lr_gb_camera cam;
        lr_gb_camera_make(light, obj->center, obj->radius, false, &cam);
        lr_cpu_sh_env(obj, light, &cam, LR_CPU_SH_FALLBACK_SIZE, others, n_others, 1, &env);
        use = &env;
    }
    lr_cpu_sh_B(obj, light, use, xo, no, d, out->mean);
    out->var[0] = out->var[1] = out->var[2] = 0.0;
}

void lr_cpu_radiosity(const lr_scene_object *obj, const lr_light *light, lr_vec3 xo, lr_vec3 no,
                      const lr_cpu_radiosity_desc *d, uint64_t stream, lr_cpu_estimate *out)
{
    int N = d && d->N > 0 ? d->N : 16;
    enum lr_cpu_sampler mode = d ? d->sampler : LR_CPU_PASS;
    /* PIPELINE.md: r_max = 20 max(R, |x_l - x_o|) (20 R for directional lights). */
    double rmax = d && d->r_max > 0.0 ? d->r_max : LR_CPU_RMAX_RADII * obj->radius;
    if (!(d && d->r_max > 0.0) && light->type != LR_LIGHT_DIRECTIONAL)
        rmax = LR_CPU_RMAX_RADII * fmax(obj->radius, lr_v3_len(lr_v3_sub(light->position, xo)));

    ctx k = {.obj = obj, .light = light, .xo = xo, .no = no, .tmin = LR_CPU_TMIN * obj->radius,
             .pairs = lr_sss_pairs(obj->sss_model, &obj->coeffs, obj->thickness_mm),
             .others = d ? d->others : NULL, .n_others = d ? d->n_others : 0,
             .snap = d ? d->snap : NULL, .snap_ctx = d ? d->snap_ctx : NULL};
    if (light->type == LR_LIGHT_DIRECTIONAL) {
        k.wl = light->direction;
        lr_tangents(k.wl, &k.t1, &k.t2);
        k.cp = lr_v3_sub(obj->center,
                         lr_v3_scale(k.wl, lr_v3_dot(lr_v3_sub(obj->center, xo), k.wl)));
    } else {
        lr_tangents(no, &k.t1, &k.t2);
        k.xl = light->position;
        k.xs = k.xl;
        double eps = LR_CPU_ON_SURFACE_EPS * obj->radius;
        if (!(lr_v3_len(lr_v3_sub(k.xl, xo)) > eps))
            k.xs = lr_v3_add(xo, lr_v3_scale(no, eps)); /* light on x_o: see the #define */
        k.d = lr_v3_len(lr_v3_sub(k.xs, xo));
    }

    out->n = N;
    if (lr_sss_model_props_of(obj->sss_model)->grid_field) {
        double B[3] = {0.0, 0.0, 0.0};
        if (d && d->dfield.data)
            lr_dfield_eval(d->dfield.data, d->dfield.n, d->dfield.origin, d->dfield.h, xo, B);
        for (int c = 0; c < 3; c++) {
            out->mean[c] = B[c];
            out->var[c] = 0.0;
        }
        return;
    }
    if (lr_sss_model_props_of(obj->sss_model)->light_env) {
        sh_radiosity(obj, light, xo, no, d, out);
        return;
    }
    for (int c = 0; c < 3; c++) {
        /* seed 003 Sec. 3.1: a separate set of samples per colour band. */
        lr_rng rng = lr_rng_init(lr_rng_key(stream, (uint64_t)c, 0x5A3D, 0));
        double mean = 0.0, m2 = 0.0;
        for (int j = 0; j < N; j++) {
            double f = mode == LR_CPU_REFERENCE ? sample_ref(&k, c, &rng)
                                                : sample_pass(&k, c, rmax, &rng);
            if (!isfinite(f) || f < 0.0)
                f = 0.0; /* cannot happen for finite input; never let one sample poison a map */
            double delta = f - mean; /* Welford */
            mean += delta / (j + 1);
            m2 += delta * (f - mean);
        }
        /* PIPELINE.md "Energy": S_d times its per-band normalisation (1 for the raw model). */
        double g = lr_scene_object_sd_norm(obj, c);
        out->mean[c] = g * mean;
        out->var[c] = N > 1 ? g * g * m2 / (N - 1) : 0.0;
    }
}
