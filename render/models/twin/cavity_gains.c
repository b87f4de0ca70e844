/* The models' cavity closure: see cavity_gains.h. */
#include "render/models/twin/cavity_gains.h"

#include "render/models/twin/radiosity.h"
#include "render/optics/optics.h"

static void profile_b(const void *ctx, lr_vec3 x, lr_vec3 n, int N, uint64_t key, double B[3])
{
    const lr_scene_object *o = ((const void *const *)ctx)[0];
    const lr_light *l = ((const void *const *)ctx)[1];
    lr_cpu_radiosity_desc d = {.N = N, .sampler = LR_CPU_REFERENCE};
    lr_cpu_estimate est;
    lr_cpu_radiosity(o, l, x, n, &d, key, &est);
    for (int c = 0; c < 3; c++)
        B[c] = est.mean[c];
}

int lr_cavity_measure(const lr_scene_object *obj, const lr_light *l,
                      enum lr_enclosure enclosure, const lr_cavity_desc *d, lr_cavity *out,
                      lr_err *e)
{
    if (!obj || !l || !out)
        return lr_err_set(e, LR_EINVAL, "cavity: NULL %s", !obj ? "object" : !l ? "light" : "out");
    /* Not for the raw directional dipole (its total exceeds 1); the standard dipole is the
     * normalisation's reference, so "normalize" does not change it (lr_scene_object_sd_norm). */
    bool applies = enclosure == LR_ENCLOSURE_HULL && l->type != LR_LIGHT_DIRECTIONAL &&
                   !(obj->sd_raw && lr_sss_model_props_of(obj->sss_model)->raw_no_closure) &&
                   /* the models that close the cavity themselves or are fitted
                    * (lr_sss_model_props: no_closure says why) */
                   !lr_sss_model_props_of(obj->sss_model)->no_closure;
    /* The normalised model's half-space total; for the multipole the slab's R + T total
     * (what entered and was not absorbed: a thin wall absorbs less than a half-space). */
    double A[3];
    lr_sss_total(obj->sss_model, &obj->coeffs, obj->thickness_mm, A);
    const void *ctx[2] = {obj, l};
    return lr_cavity_measure_energy(obj, l, applies, A, d, profile_b, ctx, out, e);
}

int lr_cavity_scene_gains(const lr_scene *s, int light, int threads, double (*gain)[3],
                              int nobj, lr_err *e)
{
    for (int o = 0; o < nobj; o++)
        gain[o][0] = gain[o][1] = gain[o][2] = 1.0;
    const lr_light *l = lr_scene_light_at(s, light);
    int k = -1;
    enum lr_enclosure enc = l ? lr_scene_light_enclosure(s, light, &k) : LR_ENCLOSURE_NONE;
    if (enc != LR_ENCLOSURE_HULL || k < 0 || k >= nobj)
        return LR_OK;
    lr_cavity_desc d = LR_CAVITY_SCENE_DESC;
    d.threads = threads;
    lr_cavity cav;
    int rc = lr_cavity_measure(lr_scene_object_at(s, k), l, enc, &d, &cav, e);
    if (rc)
        return rc;
    for (int c = 0; c < 3; c++)
        gain[k][c] = cav.gain[c];
    return LR_OK;
}
