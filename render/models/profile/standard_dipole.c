/* The standard dipole of Jensen et al. 2001, seed 003's comparison (its Fig. 6): a half-space
 * profile of the distance alone, scaled by 1 / t_hem so that light entering at normal incidence
 * leaves with the dipole's total (PIPELINE.md "Energy"). */
#include "render/models/model.h"

static void sd_fresnel(const lr_coeffs *c, double thickness_mm, int pairs, lr_vec3 xi, lr_vec3 ni,
                       lr_vec3 wi, lr_vec3 xo, lr_vec3 no, double out[3])
{
    (void)thickness_mm, (void)pairs, (void)no; /* a half-space profile of |x_o - x_i| */
    lr_dipole_sd_fresnel(c, xi, ni, wi, xo, out);
}

static double sd_norm(const lr_coeffs *c, int band)
{
    (void)band;
    return 1.0 / c->t_hem;
}

const lr_model_ops lr_model_standard_dipole = {
    .name = "standard_dipole",
    .sd_fresnel = sd_fresnel,
    .sd_norm = sd_norm,
    .glsl_sd = "lr_dipole_sd_band(c, s, j, xi, xo)",
};
