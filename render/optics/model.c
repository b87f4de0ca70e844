/* The diffusion-model switch: which S_d an object's scattered-radiosity estimator evaluates
 * (directional dipole [14], seed 003's choice, or the standard dipole of Jensen et al. 2001,
 * for comparison as in seed 003 Fig. 6), or the slab multipole of Donner & Jensen 2005 for thin
 * walls (issue 12). The sampling is the same for all (seed 003 Eq. 11-12: all decay as
 * exp(-sigma_tr d)). */
#include "render/optics/optics.h"

#include <math.h>
#include <string.h>

static const char *const names[LR_SSS_MODEL_COUNT] = {"directional_dipole", "standard_dipole",
                                                       "multipole", "translucent_radiosity",
                                                       "diffusion_grid", "sh_translucency"};

/* Designated rows: a model appended to the enum without a row here is a profile model (the
 * all-zero row), which is what lr_sss_sd_fresnel_n's default branch evaluates. */
static const lr_sss_model_props props[LR_SSS_MODEL_COUNT] = {
    [LR_SSS_MULTIPOLE] = {.needs_thickness = "needs thickness_mm (the wall the multipole models)"},
    [LR_SSS_TRANSLUCENT_RADIOSITY] = {.solves = "its patch system is solved on the CPU",
                                      .no_closure = "translucent radiosity solves the cavity's "
                                                    "inter-reflection itself",
                                      .no_openings = "its receiver grid carries the inner "
                                                     "faces' light (render/transrad/tr_scene.h)",
                                      /* S integrates the profile over each entry patch with 256
                                       * points about 0.75 mm apart on the renderer's 12 mm
                                       * patches and scales each column to the profile's total
                                       * (render/transrad/subsurface.c). e^{-sigma_tr r} falls
                                       * below DBL_MIN at sigma_tr r = 708: at 500 /mm that is
                                       * r = 1.4 mm, twice the points' spacing, so every patch
                                       * keeps points whose profile is a normal double. Measured
                                       * on the candle: right at 980 /mm; Inf in S (the total
                                       * over a subnormal sum) at 1340 /mm, columns lost (sum 0:
                                       * the light that enters vanishes) at 1470 /mm. */
                                      .max_sigma_tr = 500.0,
                                      .max_sigma_tr_why =
                                          "a diffusion length of at least 2 um: its S samples "
                                          "the profile about 0.75 mm apart on each 12 mm patch, "
                                          "and a narrower profile underflows between the "
                                          "points"},
    [LR_SSS_DIFFUSION_GRID] = {.no_profile = true,
                               .solves = "the diffusion equation is solved on the CPU grid",
                               .needs_closed = "needs a closed mesh (the grid diffusion solves "
                                               "inside a solid body)",
                               .no_closure = "the grid closes the cavity in its own field "
                                             "(render/diffusion/dscene.h: the gain measured "
                                             "from its solved B)"},
    [LR_SSS_SH_TRANSLUCENCY] = {.no_profile = true,
                                .no_closure = "its energy is fitted, not closed",
                                .no_openings = "its energy is fitted, not closed"},
};

const lr_sss_model_props *lr_sss_model_props_of(enum lr_sss_model m)
{
    static const lr_sss_model_props none;
    return (unsigned)m < LR_SSS_MODEL_COUNT ? &props[m] : &none;
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

/* Translucent radiosity (seed 000) evaluates a profile of its own choosing: the slab multipole
 * where the object gives a wall thickness, the standard dipole otherwise. */
static enum lr_sss_model profile_of(enum lr_sss_model m, double thickness_mm)
{
    if (m != LR_SSS_TRANSLUCENT_RADIOSITY)
        return m;
    return thickness_mm > 0 ? LR_SSS_MULTIPOLE : LR_SSS_STANDARD_DIPOLE;
}

const char *lr_sss_model_name(enum lr_sss_model m)
{
    return (unsigned)m < LR_SSS_MODEL_COUNT ? names[m] : "?";
}

bool lr_sss_model_parse(const char *name, enum lr_sss_model *out)
{
    for (int i = 0; i < LR_SSS_MODEL_COUNT; i++)
        if (name && strcmp(name, names[i]) == 0) {
            *out = (enum lr_sss_model)i;
            return true;
        }
    return false;
}

void lr_sss_sd_fresnel(enum lr_sss_model m, const lr_coeffs *c, double thickness_mm, lr_vec3 xi,
                       lr_vec3 ni, lr_vec3 wi, lr_vec3 xo, lr_vec3 no, double out[3])
{
    lr_sss_sd_fresnel_n(m, c, thickness_mm, lr_sss_pairs(m, c, thickness_mm), xi, ni, wi, xo, no,
                        out);
}

int lr_sss_pairs(enum lr_sss_model m, const lr_coeffs *c, double thickness_mm)
{
    return profile_of(m, thickness_mm) == LR_SSS_MULTIPOLE ? lr_multipole_pairs(c, thickness_mm) : 0;
}

void lr_sss_sd_fresnel_n(enum lr_sss_model m, const lr_coeffs *c, double thickness_mm, int pairs,
                         lr_vec3 xi, lr_vec3 ni, lr_vec3 wi, lr_vec3 xo, lr_vec3 no, double out[3])
{
    m = profile_of(m, thickness_mm);
    if (lr_sss_model_props_of(m)->no_profile) {
        /* no S_d: the grid's field (render/diffusion), SH's B (sh_translucency.h) */
        out[0] = out[1] = out[2] = 0.0;
        return;
    }
    if (m == LR_SSS_STANDARD_DIPOLE)
        lr_dipole_sd_fresnel(c, xi, ni, wi, xo, out);
    else if (m == LR_SSS_MULTIPOLE)
        lr_multipole_sd_fresnel_n(c, thickness_mm, pairs, xi, ni, wi, xo, no, out);
    else
        lr_dirpole_sd_fresnel(c, xi, ni, wi, xo, no, out);
}

void lr_sss_total(enum lr_sss_model m, const lr_coeffs *c, double thickness_mm, double out[3])
{
    m = profile_of(m, thickness_mm);
    if (m != LR_SSS_MULTIPOLE) {
        lr_dipole_rd_total(c, out);
        return;
    }
    double R[3], T[3];
    lr_multipole_total(c, thickness_mm, R, T);
    for (int j = 0; j < 3; j++)
        out[j] = R[j] + T[j];
}
