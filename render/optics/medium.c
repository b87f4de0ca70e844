/* A homogeneous medium's optical properties, their validation, and the per-band coefficients
 * derived from them once per material for both dipole models. */
#include "render/optics/optics.h"

#include <math.h>

static const char *const band_name[3] = {"red", "green", "blue"};

static int check_coeff(const char *field, int band, double v, lr_err *e)
{
    if (!isfinite(v) || v < 0.0)
        return lr_err_set(e, LR_EINVAL, "medium: %s[%d] (%s) = %g: must be finite and >= 0",
                          field, band, band_name[band], v);
    return LR_OK;
}

int lr_medium_validate(const lr_medium *m, lr_err *e)
{
    if (!m)
        return lr_err_set(e, LR_EINVAL, "medium: NULL medium");
    for (int j = 0; j < 3; j++) {
        int rc = check_coeff("sigma_a", j, m->sigma_a[j], e);
        if (rc)
            return rc;
        rc = check_coeff("sigma_s_prime", j, m->sigma_s_prime[j], e);
        if (rc)
            return rc;
        double st = m->sigma_a[j] + m->sigma_s_prime[j];
        if (!(st >= LR_SIGMA_T_PRIME_MIN && st <= LR_SIGMA_T_PRIME_MAX))
            return lr_err_set(e, LR_EINVAL,
                              "medium: sigma_t_prime[%d] (%s) = sigma_a + sigma_s_prime = %g: must "
                              "be in [%g, %g] mm^-1",
                              j, band_name[j], st, LR_SIGMA_T_PRIME_MIN, LR_SIGMA_T_PRIME_MAX);
    }
    if (!isfinite(m->eta) || m->eta < LR_ETA_MIN || m->eta > LR_ETA_MAX)
        return lr_err_set(e, LR_EINVAL,
                          "medium: eta = %g: must be in [%g, %g], where the diffuse Fresnel "
                          "fits hold",
                          m->eta, LR_ETA_MIN, LR_ETA_MAX);
    if (!isfinite(m->g) || m->g <= -1.0 || m->g >= 1.0)
        return lr_err_set(e, LR_EINVAL, "medium: g = %g: must be in (-1, 1)", m->g);
    return LR_OK;
}

int lr_coeffs_derive(const lr_medium *m, lr_coeffs *out, lr_err *e)
{
    int rc = lr_medium_validate(m, e);
    if (rc)
        return rc;
    lr_coeffs c;
    double eta = m->eta;
    double F_dr = lr_fresnel_diffuse_reflectance(eta);
    /* Jensen et al. 2001: boundary condition constant of the standard dipole. */
    c.A = (1.0 + F_dr) / (1.0 - F_dr);
    /* [14] Frisvad et al. 2014: C_phi, C_E from the diffuse Fresnel moments (d'Eon & Irving
     * 2011); C_phi_norm = 1 / (4 C_phi(1/eta)) normalises S'_d; A_dir is the boundary constant
     * that places the virtual source at 2 A de. */
    c.C_phi_norm = 1.0 / (1.0 - 2.0 * lr_fresnel_moment1(1.0 / eta));
    c.C_phi = (1.0 - 2.0 * lr_fresnel_moment1(eta)) / 4.0;
    c.C_E = (1.0 - 3.0 * lr_fresnel_moment2(eta)) / 2.0;
    c.A_dir = (1.0 - c.C_E) / (2.0 * c.C_phi);
    c.eta = eta;
    for (int j = 0; j < 3; j++) {
        double sa = m->sigma_a[j], ssp = m->sigma_s_prime[j];
        double stp = sa + ssp;
        c.sigma_t_prime[j] = stp;
        c.albedo_prime[j] = ssp / stp;
        /* seed 003 Eq. 10; equals sqrt(sigma_a / D) of [14]. */
        c.sigma_tr[j] = sqrt(3.0 * sa * stp);
        c.D[j] = 1.0 / (3.0 * stp);
        c.mfp[j] = 1.0 / stp;
        /* Jensen et al. 2001: real source one reduced mean free path deep, virtual source
         * mirrored about the extrapolated boundary 2 A D above the surface. */
        c.z_r[j] = c.mfp[j];
        c.z_v[j] = c.mfp[j] + 4.0 * c.A * c.D[j];
        /* [14]: extrapolation distance. As albedo' -> 0 it diverges; Inf is represented exactly
         * and dirpole.c treats it as the limit (no virtual source). */
        c.de[j] = c.albedo_prime[j] > 0.0 ? 2.131 * c.D[j] / sqrt(c.albedo_prime[j]) : INFINITY;
        c.sigma_t[j] = sa + ssp / (1.0 - m->g);
    }
    c.t_hem = lr_hemi_transmittance(eta);
    lr_dirpole_energy_norm(&c, c.sd_norm); /* needs every other field */
    *out = c;
    return LR_OK;
}
