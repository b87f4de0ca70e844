/* The per-object models: the only list (render/models/model.h), and the evaluations that
 * dispatch through it. A new model is a folder defining its lr_model_ops, one line here and one
 * id in model.h's enum (render/models/README.md, "Adding a model"). */
#include "render/models/model.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* Each defined in its model's folder. Declared here, not in a header of theirs: nothing but this
 * list names a model's table. */
extern const lr_model_ops lr_model_directional_dipole, lr_model_standard_dipole,
    lr_model_multipole, lr_model_translucent_radiosity, lr_model_diffusion_grid,
    lr_model_sh_translucency;

static const lr_model_ops *const registry[LR_SSS_MODEL_COUNT] = {
    [LR_SSS_DIRECTIONAL_DIPOLE] = &lr_model_directional_dipole,
    [LR_SSS_STANDARD_DIPOLE] = &lr_model_standard_dipole,
    [LR_SSS_MULTIPOLE] = &lr_model_multipole,
    [LR_SSS_TRANSLUCENT_RADIOSITY] = &lr_model_translucent_radiosity,
    [LR_SSS_DIFFUSION_GRID] = &lr_model_diffusion_grid,
    [LR_SSS_SH_TRANSLUCENCY] = &lr_model_sh_translucency,
};

const lr_model_ops *lr_model_of(enum lr_sss_model m)
{
    return (unsigned)m < LR_SSS_MODEL_COUNT ? registry[m] : NULL;
}

const char *lr_sss_model_name(enum lr_sss_model m)
{
    const lr_model_ops *o = lr_model_of(m);
    return o ? o->name : "?";
}

bool lr_sss_model_parse(const char *name, enum lr_sss_model *out)
{
    for (int i = 0; name && i < LR_SSS_MODEL_COUNT; i++)
        if (strcmp(name, registry[i]->name) == 0) {
            *out = (enum lr_sss_model)i;
            return true;
        }
    return false;
}

const lr_sss_model_props *lr_sss_model_props_of(enum lr_sss_model m)
{
    static const lr_sss_model_props none;
    const lr_model_ops *o = lr_model_of(m);
    return o ? &o->props : &none;
}

enum lr_sss_model lr_sss_profile_of(enum lr_sss_model m, double thickness_mm)
{
    const lr_model_ops *o = lr_model_of(m);
    return o && o->profile ? o->profile(thickness_mm) : m;
}

int lr_sss_model_check_medium(enum lr_sss_model m, const lr_medium *med, lr_err *e)
{
    static const char *const band[3] = {"red", "green", "blue"};
    const lr_sss_model_props *p = lr_sss_model_props_of(m);
    if (!(p->max_sigma_tr > 0.0))
        return LR_OK;
    for (int b = 0; b < 3; b++) {
        double sa = med->sigma_a[b], ssp = med->sigma_s_prime[b];
        double str = sqrt(3.0 * sa * (sa + ssp)); /* as lr_coeffs_derive's sigma_tr */
        if (!(str <= p->max_sigma_tr))
            return lr_err_set(e, LR_EINVAL,
                              "sigma_a = %g, sigma_s_prime = %g (%s): sigma_tr = sqrt(3 sigma_a "
                              "(sigma_a + sigma_s_prime)) = %.3g /mm, outside %s's valid range "
                              "sigma_tr <= %g /mm (%s)",
                              sa, ssp, band[b], str, lr_sss_model_name(m), p->max_sigma_tr,
                              p->max_sigma_tr_why);
    }
    return LR_OK;
}

int lr_sss_pairs(enum lr_sss_model m, const lr_coeffs *c, double thickness_mm)
{
    const lr_model_ops *o = lr_model_of(lr_sss_profile_of(m, thickness_mm));
    return o && o->pairs ? o->pairs(c, thickness_mm) : 0;
}

void lr_sss_sd_fresnel(enum lr_sss_model m, const lr_coeffs *c, double thickness_mm, lr_vec3 xi,
                       lr_vec3 ni, lr_vec3 wi, lr_vec3 xo, lr_vec3 no, double out[3])
{
    lr_sss_sd_fresnel_n(m, c, thickness_mm, lr_sss_pairs(m, c, thickness_mm), xi, ni, wi, xo, no,
                        out);
}

void lr_sss_sd_fresnel_n(enum lr_sss_model m, const lr_coeffs *c, double thickness_mm, int pairs,
                         lr_vec3 xi, lr_vec3 ni, lr_vec3 wi, lr_vec3 xo, lr_vec3 no, double out[3])
{
    const lr_model_ops *o = lr_model_of(lr_sss_profile_of(m, thickness_mm));
    if (!o || !o->sd_fresnel) {
        /* no S_d: the grid's field (render/diffusion), SH's B (sh_translucency.h) */
        out[0] = out[1] = out[2] = 0.0;
        return;
    }
    o->sd_fresnel(c, thickness_mm, pairs, xi, ni, wi, xo, no, out);
}

void lr_sss_total(enum lr_sss_model m, const lr_coeffs *c, double thickness_mm, double out[3])
{
    const lr_model_ops *o = lr_model_of(lr_sss_profile_of(m, thickness_mm));
    if (o && o->total)
        o->total(c, thickness_mm, out);
    else
        lr_dipole_rd_total(c, out);
}

double lr_sss_sd_norm(enum lr_sss_model m, const lr_coeffs *c, bool raw, int band)
{
    const lr_model_ops *o = lr_model_of(m);
    return !raw && o && o->sd_norm ? o->sd_norm(c, band) : 1.0;
}

/* Appends one define line to buf at *at; false when it does not fit. */
static bool put(char *buf, size_t cap, size_t *at, const char **lines, int *n, int max,
                const char *text)
{
    size_t len = strlen(text);
    if (*n >= max || *at + len + 1 > cap)
        return false;
    memcpy(buf + *at, text, len + 1);
    lines[(*n)++] = buf + *at;
    *at += len + 1;
    return true;
}

int lr_models_glsl_defines(char *buf, size_t cap, const char **lines, int max_lines)
{
    /* A chain of ?: over the ids, one arm per model that has the expression; GLSL evaluates
     * only the arm taken. The parameter lists carry no blank: the shader loader's define is
     * "NAME VALUE", split at the first blank (render/gl/shader.h). */
    char sd[2048], has[256], b[1024];
    int w0 = snprintf(sd, sizeof sd, "LR_MODEL_SD_BAND(c,s,j,xi,ni,wi,xo,no) (");
    int w1 = snprintf(has, sizeof has, "LR_MODEL_HAS_B(m) (false");
    int w2 = snprintf(b, sizeof b, "LR_MODEL_B(m,obj,mat,xo,no) (");
    size_t ls = (size_t)w0, lh = (size_t)w1, lb = (size_t)w2;
    for (int i = 0; i < LR_SSS_MODEL_COUNT; i++) {
        const lr_model_ops *o = registry[i];
        if (o->glsl_sd)
            ls += (size_t)snprintf(sd + ls, ls < sizeof sd ? sizeof sd - ls : 0,
                                   "s.model == %d ? %s : ", i, o->glsl_sd);
        if (o->glsl_B) {
            lh += (size_t)snprintf(has + lh, lh < sizeof has ? sizeof has - lh : 0,
                                   " || (m) == %d", i);
            lb += (size_t)snprintf(b + lb, lb < sizeof b ? sizeof b - lb : 0,
                                   "(m) == %d ? %s : ", i, o->glsl_B);
        }
    }
    ls += (size_t)snprintf(sd + ls, ls < sizeof sd ? sizeof sd - ls : 0, "0.0)");
    lh += (size_t)snprintf(has + lh, lh < sizeof has ? sizeof has - lh : 0, ")");
    lb += (size_t)snprintf(b + lb, lb < sizeof b ? sizeof b - lb : 0, "vec3(0.0))");
    if (ls >= sizeof sd || lh >= sizeof has || lb >= sizeof b)
        return -1;
    size_t at = 0;
    int n = 0;
    if (!put(buf, cap, &at, lines, &n, max_lines, sd) ||
        !put(buf, cap, &at, lines, &n, max_lines, has) ||
        !put(buf, cap, &at, lines, &n, max_lines, b))
        return -1;
    return n;
}
