/* The directional dipole of Frisvad, Hachisuka and Kjeldsen 2014 [14]: seed 003's profile
 * (its Eq. 4 integrand with this S_d), normalised per band so that its half-space total is the
 * standard dipole's (render/optics/dirpole_norm.c, PIPELINE.md "Energy"). */
#include "render/models/model.h"

static void sd_fresnel(const lr_coeffs *c, double thickness_mm, int pairs, lr_vec3 xi, lr_vec3 ni,
                       lr_vec3 wi, lr_vec3 xo, lr_vec3 no, double out[3])
{
    (void)thickness_mm, (void)pairs; /* a half-space profile */
    lr_dirpole_sd_fresnel(c, xi, ni, wi, xo, no, out);
}

static double sd_norm(const lr_coeffs *c, int band)
{
    return c->sd_norm[band];
}

const lr_model_ops lr_model_directional_dipole = {
    .name = "directional_dipole",
    /* its raw (unnormalised) total exceeds 1, so a one-gain closure would amplify */
    .props = {.raw_no_closure = "the raw directional dipole's total exceeds 1"},
    .sd_fresnel = sd_fresnel,
    .sd_norm = sd_norm,
    .glsl_sd = "lr_dirpole_sd_band(c, j, xi, ni, wi, xo, no)",
};
