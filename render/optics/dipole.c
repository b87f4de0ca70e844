/* The standard dipole of Jensen et al. 2001 (A Practical Model for Subsurface Light Transport):
 * diffuse reflectance profile R_d(r) and its integral over the plane. */
#include "render/optics/optics.h"

#include <math.h>

/* One source's term z (sigma_tr d + 1) e^{-sigma_tr d} / d^3 with d = sqrt(r^2 + z^2).
 * z <= 1e10 mm (medium validation), so r^2 + z^2 can only overflow for huge r, where hypot
 * (3x slower) takes over; when d^3 overflows the term correctly becomes 0. */
static double source_term(double sigma_tr, double z, double r)
{
    double d = r < 1e150 ? sqrt(r * r + z * z) : hypot(r, z);
    double s = sigma_tr * d;
    return z * (s + 1.0) * exp(-s) / (d * d * d);
}

void lr_dipole_rd(const lr_coeffs *c, double r, double out[3])
{
    for (int j = 0; j < 3; j++) {
        /* Jensen et al. 2001, R_d(r) = alpha'/(4 pi) [z_r (sigma_tr d_r + 1) e^{-sigma_tr d_r}
         * / d_r^3 + z_v (sigma_tr d_v + 1) e^{-sigma_tr d_v} / d_v^3]. Both terms are positive
         * (Jensen's sign convention measures z_v upward), and d_r >= z_r > 0, so R_d(0) is
         * finite. */
        double tr = c->sigma_tr[j];
        out[j] = c->albedo_prime[j] / (4.0 * M_PI) *
                 (source_term(tr, c->z_r[j], r) + source_term(tr, c->z_v[j], r));
    }
}

int lr_dipole_rd_checked(const lr_coeffs *c, double r, double out[3], lr_err *e)
{
    if (!c)
        return lr_err_set(e, LR_EINVAL, "dipole: NULL coefficients");
    if (!isfinite(r) || r < 0.0)
        return lr_err_set(e, LR_EINVAL, "dipole: r = %g: must be finite and >= 0 (mm)", r);
    lr_dipole_rd(c, r, out);
    return LR_OK;
}

void lr_dipole_rd_total(const lr_coeffs *c, double out[3])
{
    for (int j = 0; j < 3; j++) {
        /* Jensen et al. 2001, R_d = (alpha'/2)(1 + e^{-(4/3) A sqrt(3(1-alpha'))})
         * e^{-sqrt(3(1-alpha'))}. Integrating each source term of R_d(r) over the plane gives
         * 2 pi e^{-sigma_tr z}, and sigma_tr z_r = sigma_tr / sigma_t' = sqrt(3 sigma_a / sigma_t')
         * = sqrt(3 (1 - alpha')) exactly; this form avoids the cancellation in 1 - alpha' when
         * sigma_a << sigma_s'. */
        double s = c->sigma_tr[j] / c->sigma_t_prime[j];
        out[j] = 0.5 * c->albedo_prime[j] * (1.0 + exp(-(4.0 / 3.0) * c->A * s)) * exp(-s);
    }
}

void lr_dipole_sd(const lr_coeffs *c, lr_vec3 xi, lr_vec3 xo, double out[3])
{
    /* Jensen et al. 2001, Eq. 5: S_d = (1/pi) F_t(w_i) R_d(|x_i - x_o|) F_t(w_o); the Fresnel
     * factors are applied by the caller (F_t(w_i): lr_dipole_sd_fresnel; F_t(w_o): composition). */
    lr_dipole_rd(c, lr_v3_len(lr_v3_sub(xo, xi)), out);
    for (int j = 0; j < 3; j++)
        out[j] /= M_PI;
}

void lr_dipole_sd_fresnel(const lr_coeffs *c, lr_vec3 xi, lr_vec3 ni, lr_vec3 wi, lr_vec3 xo,
                          double out[3])
{
    double cos_i = lr_v3_dot(wi, ni);
    double t = cos_i > 0.0 ? lr_fresnel_transmittance(cos_i, c->eta) : 0.0;
    if (!(t > 0.0)) {
        out[0] = out[1] = out[2] = 0.0;
        return;
    }
    lr_dipole_sd(c, xi, xo, out);
    for (int j = 0; j < 3; j++)
        out[j] *= t;
}
