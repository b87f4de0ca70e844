/* lamprig — translucent radiosity: E, the direct light of one light at unit intensity.
 *
 * Per patch, the mean over direct_samples points of the light's irradiance shape(w) cos / d^2
 * (point, spot) or cos (directional: unit radiance on a surface facing it), each point shadowed
 * by every surface (seed 000 Eq. 14's E). On a translucent patch the part that enters is
 * weighted by the boundary's F_t(cos) (Ein); the rest, Edir - Ein, is reflected by the
 * interface. Quad and disk lights: direct_area.c. */
#include "render/transrad/tr_priv.h"

#include <math.h>
#include <string.h>

#include "render/cpu/parallel.h"
#include "render/cpu/rng.h"

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
    lr_cpu_rng rng = lr_cpu_rng_init(lr_cpu_key(t->set.seed, 0xD1EC, p, 0));
    double ju = lr_cpu_rng_next(&rng), jv = lr_cpu_rng_next(&rng);
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

static void dl_item(void *vctx, long item)
{
    dl_ctx *c = vctx;
    lr_tr_direct_patch(c->t, (size_t)item, point_irradiance, c);
}

int lr_tr_direct(lr_tr *t, const lr_light *light, lr_err *e)
{
    if (lr_light_is_area(light))
        return lr_tr_direct_area(t, light, e);
    dl_ctx c = {t, light, lr_tr_eps(t)};
    lr_cpu_parallel_for((long)t->n, t->set.threads, dl_item, &c);
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
