/* lamprig — translucent radiosity: E, the direct light of one light at unit intensity.
 *
 * Per patch, the mean over direct_samples points of the light's irradiance shape(w) cos / d^2
 * (point, spot) or cos (directional: unit radiance on a surface facing it), each point shadowed
 * by every surface (seed 000 Eq. 14's E). On a translucent patch the part that enters is
 * weighted by the boundary's F_t(cos) (Ein); the rest, Edir - Ein, is reflected by the
 * interface. Quad and disk lights: direct_area.c.
 *
 * Point and spot lights: the mean of point samples of cos / d^2 diverges as the light nears a
 * patch (a sample 1e-3 mm off it weighs 1e6 / mm^2), while the patch receives at most 2 pi:
 * its mean irradiance is Omega / A (near_light.h; Omega the solid angle of its front-facing
 * triangles seen from the light), times the part of it the samples find lit (unshadowed,
 * inside the spot's profile), weighted as the samples' own cos / d^2; the part entering a
 * translucent patch takes F_t at the patch's mean cosine Phi / Omega (projected solid angle
 * over solid angle). Far off, Omega / A is the point mean to O(A / d^2). */
#include "render/transrad/tr_priv.h"

#include <math.h>
#include <string.h>

#include "render/base/parallel.h"
#include "render/base/rng.h"
#include "render/optics/near_light.h"

typedef struct dl_ctx {
    lr_tr *t;
    const lr_light *light;
    double eps;
} dl_ctx;

/* A point, spot or directional light's irradiance shape(w) cos / d^2 at x, shadowed. */
static void point_irradiance(const void *vctx, size_t p, unsigned k, lr_vec3 x, lr_vec3 n,
                             bool trans, double eta, double *e, double *ein)
{
    (void)p, (void)k;
    const dl_ctx *c = vctx;
    *e = *ein = 0;
    lr_vec3 w;
    double dist, g;
    if (c->light->type == LR_LIGHT_DIRECTIONAL) {
        w = lr_v3_scale(c->light->direction, -1);
        dist = INFINITY;
        g = 1;
    } else {
        lr_vec3 L = lr_v3_sub(c->light->position, x);
        dist = lr_v3_len(L);
        if (!(dist > 0))
            return;
        w = lr_v3_scale(L, 1 / dist);
        g = lr_light_shape(c->light, lr_v3_scale(w, -1)) / (dist * dist);
    }
    double cs = lr_v3_dot(n, w);
    if (cs <= 0 || g <= 0)
        return;
    lr_vec3 o = lr_v3_add(x, lr_v3_scale(n, c->eps));
    if (lr_tr_occluded(c->t, o, w, isfinite(dist) ? dist - c->eps : INFINITY))
        return;
    *e = g * cs;
    *ein = g * cs * (trans ? lr_fresnel_transmittance(cs, eta) : 1.0);
}

void lr_tr_direct_patch(lr_tr *t, size_t p, lr_tr_point_irradiance point, const void *ctx)
{
    const lr_tr_surf *sf = &t->surf[t->p[p].surface];
    bool trans = sf->d.kind == LR_TR_TRANSLUCENT;
    double eta = trans ? sf->d.coeffs->eta : 1.0;
    unsigned m = (unsigned)t->set.direct_samples;
    lr_rng rng = lr_rng_init(lr_rng_key(t->set.seed, 0xD1EC, p, 0));
    double ju = lr_rng_next(&rng), jv = lr_rng_next(&rng);
    double e = 0, ein = 0;
    unsigned open = 0;
    for (unsigned k = 0; k < m; k++) {
        lr_vec3 x, n;
        lr_tr_patch_point(t, p, k, m, ju, jv, &x, &n);
        /* The mean over a plane cell's open part (cover.c). */
        if (lr_tr_point_covered(t, p, x))
            continue;
        open++;
        double ek, eik;
        point(ctx, p, k, x, n, trans, eta, &ek, &eik);
        e += ek;
        ein += eik;
    }
    for (int b = 0; b < 3; b++) {
        t->Edir[3 * p + (size_t)b] = open ? e / open : 0;
        t->Ein[3 * p + (size_t)b] = open ? ein / open : 0;
    }
}

/* Solid angle of patch p's front faces seen from x (the face's normal side); *proj (may be
 * NULL): their projected solid angle (mesh patches; plane cells leave it 0). */
static double patch_solid_angle(const lr_tr *t, size_t p, lr_vec3 x, double *proj)
{
    if (proj)
        *proj = 0;
    const lr_tr_patch *P = &t->p[p];
    const lr_tr_surf *sf = &t->surf[P->surface];
    lr_vec3 q[4];
    int nt;
    double om = 0;
    if (sf->d.kind == LR_TR_PLANE) {
        lr_vec3 a = lr_v3_scale(sf->a, 0.5 * sf->d.size_u / sf->nu);
        lr_vec3 b = lr_v3_scale(sf->b, 0.5 * sf->d.size_v / sf->nv);
        q[0] = lr_v3_sub(lr_v3_sub(P->c, a), b);
        q[1] = lr_v3_sub(lr_v3_add(P->c, a), b);
        q[2] = lr_v3_add(lr_v3_add(P->c, a), b);
        q[3] = lr_v3_add(lr_v3_sub(P->c, a), b);
        double s = lr_v3_dot(lr_v3_cross(lr_v3_sub(q[1], q[0]), lr_v3_sub(q[2], q[0])), P->n);
        om = lr_solid_angle_triangle(x, q[0], q[1], q[2]) +
             lr_solid_angle_triangle(x, q[0], q[2], q[3]);
        return fmax(0.0, s < 0 ? -om : om);
    }
    nt = (int)P->ntri;
    for (int i = 0; i < nt; i++) {
        size_t ti = t->tris[P->tri0 + (size_t)i];
        lr_mesh_triangle(sf->d.mesh, ti, q);
        lr_vec3 nn = lr_mesh_triangle_normal(sf->d.mesh, ti);
        double s = lr_v3_dot(lr_v3_cross(lr_v3_sub(q[1], q[0]), lr_v3_sub(q[2], q[0])), nn);
        double o = lr_solid_angle_triangle(x, q[0], q[1], q[2]);
        if ((s < 0 ? -o : o) > 0.0 && proj) {
            lr_vec3 tn = lr_v3_normalize(lr_v3_cross(lr_v3_sub(q[1], q[0]),
                                                     lr_v3_sub(q[2], q[0])));
            double ph = lr_projected_solid_angle_triangle(x, q[0], q[1], q[2], tn);
            *proj += fmax(0.0, s < 0 ? -ph : ph);
        }
        om += fmax(0.0, s < 0 ? -o : o);
    }
    return om;
}

/* A point or spot light's Edir, Ein on patch p: Omega / A times the lit part (above). */
static void point_patch(const dl_ctx *c, size_t p)
{
    lr_tr *t = c->t;
    const lr_tr_surf *sf = &t->surf[t->p[p].surface];
    bool trans = sf->d.kind == LR_TR_TRANSLUCENT;
    double eta = trans ? sf->d.coeffs->eta : 1.0;
    unsigned m = (unsigned)t->set.direct_samples;
    lr_rng rng = lr_rng_init(lr_rng_key(t->set.seed, 0xD1EC, p, 0));
    double ju = lr_rng_next(&rng), jv = lr_rng_next(&rng);
    /* front: the unshadowed, unshaped point samples over the whole patch; lit: the open
     * samples' shadowed, shaped ones. E = Omega / A times (lit / open) / (front / m): the
     * whole patch's mean, scaled to its open part's (cover.c) and to the part lit. */
    double lit = 0, lit_in = 0, front = 0;
    unsigned open = 0;
    for (unsigned k = 0; k < m; k++) {
        lr_vec3 x, n;
        lr_tr_patch_point(t, p, k, m, ju, jv, &x, &n);
        lr_vec3 L = lr_v3_sub(c->light->position, x);
        double d2 = lr_v3_dot(L, L), cs = lr_v3_dot(n, L);
        if (d2 > 0 && cs > 0)
            front += cs / (d2 * sqrt(d2));
        if (lr_tr_point_covered(t, p, x))
            continue;
        open++;
        double ek, eik;
        point_irradiance(c, p, k, x, n, trans, eta, &ek, &eik);
        lit += ek;
        lit_in += eik;
    }
    double E = 0, Ein = 0;
    if (front > 0 && lit > 0) {
        double proj, om = patch_solid_angle(t, p, c->light->position, &proj);
        E = om / t->p[p].area * (lit / open) / (front / m);
        /* The part that enters: F_t at the patch's solid-angle-weighted mean cosine Phi /
         * Omega (near_light.h), not at the samples' cosines: with the light near the patch
         * they all see it at grazing incidence (F_t ~ 0) while most of its light arrives
         * near the foot at normal incidence (the candle's floor, flame 0.1 mm above it: the
         * samples' weighting let in half the light). Far off the two agree to O(A / d^2). */
        Ein = trans && om > 0 ? E * lr_fresnel_transmittance(fmin(1.0, proj / om), eta)
                              : E * lit_in / lit;
    }
    for (int b = 0; b < 3; b++) {
        t->Edir[3 * p + (size_t)b] = E;
        t->Ein[3 * p + (size_t)b] = Ein;
    }
}

static void dl_item(void *vctx, long item)
{
    dl_ctx *c = vctx;
    if (c->light->type == LR_LIGHT_DIRECTIONAL)
        lr_tr_direct_patch(c->t, (size_t)item, point_irradiance, c);
    else
        point_patch(c, (size_t)item);
}

int lr_tr_direct(lr_tr *t, const lr_light *light, lr_err *e)
{
    if (lr_light_is_area(light))
        return lr_tr_direct_area(t, light, e);
    dl_ctx c = {t, light, lr_tr_eps(t)};
    if (!lr_parallel_for_cancel((long)t->n, t->set.threads, dl_item, &c, t->set.cancel,
                                    LR_CANCEL_STALE))
        return lr_cancel_check(t->set.cancel, "transrad: direct light", e);
    return LR_OK;
}

int lr_tr_direct_irradiance(lr_tr *t, const lr_light *light, double *E, lr_err *e)
{
    if (!t || !light || !E)
        return lr_err_set(e, LR_EINVAL, "transrad: direct irradiance: NULL argument");
    int rc = lr_tr_direct(t, light, e);
    if (!rc)
        memcpy(E, t->Edir, 3 * t->n * sizeof *E);
    return rc;
}
