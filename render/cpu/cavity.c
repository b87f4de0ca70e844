/* Cavity gain: see cavity.h. */
#include "render/cpu/cavity.h"

#include <math.h>
#include <stdlib.h>

#include "render/cpu/parallel.h"
#include "render/cpu/radiosity.h"
#include "render/cpu/rng.h"
#include "render/cpu/vpl.h"
#include "render/optics/optics.h"

typedef struct point_ctx {
    const lr_scene_object *obj;
    const lr_light *light;
    const lr_cpu_vpl *v;
    int N;
    unsigned seed;
    double (*B)[3];
} point_ctx;

static void point_item(void *p, long i)
{
    point_ctx *k = p;
    if (!k->v[i].valid)
        return;
    lr_cpu_radiosity_desc d = {.N = k->N, .sampler = LR_CPU_REFERENCE};
    lr_cpu_estimate est;
    lr_cpu_radiosity(k->obj, k->light, k->v[i].x, k->v[i].n, &d,
                     lr_cpu_key(k->seed, 0xCA71, (uint64_t)i, 0), &est);
    for (int c = 0; c < 3; c++)
        k->B[i][c] = est.mean[c];
}

int lr_cpu_cavity_measure(const lr_scene_object *obj, const lr_light *l,
                          enum lr_enclosure enclosure, const lr_cpu_cavity_desc *d,
                          lr_cpu_cavity *out, lr_err *e)
{
    if (!obj || !l || !out)
        return lr_err_set(e, LR_EINVAL, "cavity: NULL %s", !obj ? "object" : !l ? "light" : "out");
    int ndir = d && d->directions > 0 ? d->directions : 4096;
    int npts = d && d->points > 0 ? d->points : 256;
    int N = d && d->N > 0 ? d->N : 64;
    unsigned seed = d && d->seed ? d->seed : 1;
    *out = (lr_cpu_cavity){.gain = {1.0, 1.0, 1.0}};
    out->applies = enclosure == LR_ENCLOSURE_HULL && l->type != LR_LIGHT_DIRECTIONAL &&
                   !obj->sd_raw;
    if (!out->applies)
        return LR_OK;

    /* C and R_1: the light's power per unit intensity over Halton directions (4 pi / ndir
     * each, weighted by the spot profile), where the first surface is the object's front. */
    double eta = obj->coeffs.eta, hit = 0.0, entered = 0.0, w = 4.0 * M_PI / ndir;
    for (int i = 0; i < ndir; i++) {
        lr_vec3 u = lr_halton_sphere((unsigned)i + 1), xi, ni;
        double shape = lr_light_shape(l, u);
        if (!(shape > 0.0) ||
            !lr_cpu_first_surface(obj, l->position, u, 1e-9 * obj->radius, &xi, &ni))
            continue;
        if (!obj->closed && lr_v3_dot(ni, u) > 0.0)
            ni = lr_v3_scale(ni, -1.0); /* open surfaces are two-sided */
        double mu = -lr_v3_dot(ni, u);
        if (!(mu > 0.0))
            continue; /* met from behind: no light enters (PIPELINE.md) */
        hit += w * shape;
        entered += w * shape * lr_fresnel_transmittance(mu, eta);
    }
    out->C = hit / (4.0 * M_PI);
    out->R1 = hit > 0.0 ? 1.0 - entered / hit : 0.0;
    out->entered = entered;
    if (!(entered > 0.0))
        return LR_OK;

    /* a: power out of the outer surface (the VPL placement: outermost surface from the
     * bounding-box centre, exact areas), T_hem sum B_v A_v, B from the untruncated sampler. */
    lr_cpu_vpl *v = calloc((size_t)npts, sizeof *v);
    double(*B)[3] = calloc((size_t)npts, sizeof *B);
    if (!v || !B) {
        free(v);
        free(B);
        return lr_err_set(e, LR_ENOMEM, "cavity: out of memory for %d points", npts);
    }
    lr_cpu_vpl_place(obj, npts, v);
    point_ctx pc = {obj, l, v, N, seed, B};
    lr_cpu_parallel_for(npts, d ? d->threads : 0, point_item, &pc);
    double T = lr_hemi_transmittance(eta), A[3];
    lr_dipole_rd_total(&obj->coeffs, A); /* the normalised model's half-space total */
    for (int c = 0; c < 3; c++) {
        double P = 0.0;
        for (int i = 0; i < npts; i++)
            if (v[i].valid)
                P += T * B[i][c] * v[i].area;
        out->out[c] = P;
        out->a[c] = P / entered;
        out->b[c] = fmax(0.0, A[c] - out->a[c]);
        double R1 = out->R1, C = out->C;
        double rho1 = R1 + (1.0 - R1) * out->b[c];
        double rhod = (1.0 - T) + T * out->b[c];
        double den = (1.0 - R1) * (1.0 - rhod * C);
        double g = den > 0.0 ? 1.0 + T * rho1 * C / den : LR_CAVITY_GAIN_MAX;
        out->gain[c] = isfinite(g) ? fmin(fmax(g, 1.0), LR_CAVITY_GAIN_MAX) : LR_CAVITY_GAIN_MAX;
    }
    free(v);
    free(B);
    return LR_OK;
}
