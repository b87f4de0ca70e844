/* lamprig — translucent radiosity: E from an area light (quad, disk; seed 004's emitters) at
 * unit radiance L_e = 1, per patch.
 *
 * At each of a patch's direct_samples points x (normal n) the unshadowed irradiance is the
 * closed form of render/area (Lambert's polygon formula for a quad, the disk's equal-area
 * polygon), and the shadow is the visible fraction of it estimated from area_samples
 * stratified points y_j on the emitter, each a shadow ray x -> y_j against every surface:
 *
 *     E(x) = E_closed(x) * sum_j w_j V_j / sum_j w_j,
 *     w_j = cos(theta_e,j) cos(theta_x,j)^+ / |x - y_j|^2       (the integrand of
 *                                                                 render/area/emitter.h)
 *
 * the ratio estimator of Heitz, Hill & McGuire, "Combining analytic direct illumination and
 * stochastic shadows" (I3D 2018): exact where the emitter is fully visible or fully hidden,
 * and where it is partly hidden the samples only estimate the fraction, so an unoccluded patch
 * has no sampling noise at all. On a translucent patch the part that enters weights each
 * sample by the boundary's F_t(cos theta_x,j) (Ein), as direct.c does for a point light.
 * Linear in L_e, so the dimmer stays blend-only. */
#include "render/transrad/tr_priv.h"

#include <math.h>
#include <stdlib.h>

#include "render/area/frames.h"
#include "render/base/parallel.h"
#include "render/base/rng.h"

#define AREA_SAMPLES_MAX 256

typedef struct da_ctx {
    lr_tr *t;
    const lr_area_emitter *em;
    double eps;
} da_ctx;

/* Unshadowed closed form at x and the visible, entering fractions of it. */
static void point_light(const da_ctx *c, lr_vec3 x, lr_vec3 n, bool trans, double eta,
                        uint64_t key, double *e, double *ein)
{
    const lr_tr *t = c->t;
    *e = *ein = 0;
    double E0 = lr_area_irradiance(c->em, 1.0, x, n);
    if (!(E0 > 0))
        return;
    int m = t->set.area_samples;
    lr_vec3 y[AREA_SAMPLES_MAX];
    lr_area_stratified(c->em, m, key, y);
    lr_vec3 o = lr_v3_add(x, lr_v3_scale(n, c->eps));
    double ws = 0, wv = 0, wi = 0;
    for (int j = 0; j < m; j++) {
        lr_vec3 d = lr_v3_sub(y[j], x);
        double dist = lr_v3_len(d);
        if (!(dist > c->eps))
            continue;
        lr_vec3 w = lr_v3_scale(d, 1 / dist);
        double cx = lr_v3_dot(n, w), ce = lr_area_intensity_factor(c->em, lr_v3_scale(w, -1));
        if (cx <= 0 || ce <= 0)
            continue;
        double wj = ce * cx / (dist * dist);
        ws += wj;
        if (lr_tr_occluded(t, o, w, dist - c->eps))
            continue;
        wv += wj;
        wi += wj * (trans ? lr_fresnel_transmittance(cx, eta) : 1.0);
    }
    if (!(ws > 0)) {
        /* Every sample fell behind x's horizon where the clipped closed form still sees a
         * sliver: take it as visible along the emitter's centre. */
        lr_vec3 d = lr_v3_sub(c->em->center, x);
        double dist = lr_v3_len(d), cx = dist > 0 ? lr_v3_dot(n, d) / dist : 0;
        if (dist > 0 && !lr_tr_occluded(t, o, lr_v3_scale(d, 1 / dist), dist - c->eps)) {
            *e = E0;
            *ein = E0 * (trans ? lr_fresnel_transmittance(fmax(cx, 0), eta) : 1.0);
        }
        return;
    }
    *e = E0 * wv / ws;
    *ein = E0 * wi / ws;
}

static void area_point(const void *vctx, size_t p, unsigned k, lr_vec3 x, lr_vec3 n, bool trans,
                       double eta, double *e, double *ein)
{
    const da_ctx *c = vctx;
    point_light(c, x, n, trans, eta, lr_rng_key(c->t->set.seed, 0xA7EA, p, k), e, ein);
}

static void da_item(void *vctx, long item)
{
    da_ctx *c = vctx;
    lr_tr_direct_patch(c->t, (size_t)item, area_point, c);
}

int lr_tr_direct_area(lr_tr *t, const lr_light *light, lr_err *e)
{
    lr_area_emitter em;
    int rc = lr_area_from_light(light, &em, e);
    if (rc)
        return rc;
    da_ctx c = {t, &em, lr_tr_eps(t)};
    lr_parallel_for((long)t->n, t->set.threads, da_item, &c);
    return LR_OK;
}
