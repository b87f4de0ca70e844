/* Fresnel reflectance of a smooth dielectric interface: the exact unpolarised formula and the
 * polynomial fits of its hemispherical moments used by the dipole models. */
#include "render/optics/optics.h"

#include <math.h>

double lr_fresnel_reflectance(double cos_i, double eta)
{
    /* Index-matched: there is no interface. Special-cased because at cos_i = 0 the general
     * formula below would be 0/0. */
    if (eta == 1.0)
        return 0.0;
    /* Explicit comparisons rather than fmin/fmax so that a NaN cosine propagates. */
    if (cos_i > 1.0)
        cos_i = 1.0;
    if (cos_i < 0.0)
        cos_i = 0.0;
    /* Snell: sin_t = sin_i / eta. (1 - c)(1 + c) keeps sin_i^2 accurate near normal incidence. */
    double sin_t2 = (1.0 - cos_i) * (1.0 + cos_i) / (eta * eta);
    if (sin_t2 >= 1.0)
        return 1.0; /* total internal reflection (only possible for eta < 1) */
    double cos_t = sqrt(1.0 - sin_t2);
    /* Fresnel equations for s and p amplitudes (Born & Wolf Sec. 1.5.2); unpolarised light
     * reflects the mean of the two intensities. Denominators vanish only for cos_i = cos_t = 0,
     * which the branch above has taken. */
    double rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    double rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

double lr_fresnel_transmittance(double cos_i, double eta)
{
    return 1.0 - lr_fresnel_reflectance(cos_i, eta);
}

int lr_fresnel_checked(double cos_i, double eta, double *reflectance, double *transmittance,
                       lr_err *e)
{
    if (!isfinite(cos_i) || cos_i < 0.0 || cos_i > 1.0)
        return lr_err_set(e, LR_EINVAL, "fresnel: cos_i = %g: must be finite and in [0, 1]", cos_i);
    if (!isfinite(eta) || eta <= 0.0)
        return lr_err_set(e, LR_EINVAL, "fresnel: eta = %g: must be finite and > 0", eta);
    double r = lr_fresnel_reflectance(cos_i, eta);
    if (reflectance)
        *reflectance = r;
    if (transmittance)
        *transmittance = 1.0 - r;
    return LR_OK;
}

/* d'Eon & Irving 2011 (A quantized-diffusion model for rendering translucent materials), fits
 * of 2 C1(eta); the eta > 1 branch as in [14]'s sample code, eta <= 1 the companion fit. */
double lr_fresnel_moment1(double eta)
{
    double n = eta, r;
    if (n > 1.0)
        r = -9.23372 +
            n * (22.2272 + n * (-20.9292 + n * (10.2291 + n * (-2.54396 + 0.254913 * n))));
    else
        r = 0.919317 + n * (-3.4793 + n * (6.75335 + n * (-7.80989 + n * (4.98554 - 1.36881 * n))));
    return 0.5 * r;
}

/* d'Eon & Irving 2011, fits of 3 C2(eta). [14]'s sample code uses the eta > 1 branch for every
 * eta; below 1 that branch is an extrapolation (3C2 = 0.057 at 0.9 and 58 at 0.5, against
 * exact values 0.011 and 0.13), so the
 * eta < 1 fit of the same paper is used there. Identical to [14] for eta > 1. */
double lr_fresnel_moment2(double eta)
{
    double n = eta, r;
    if (n > 1.0) {
        r = -1641.1 + n * (1213.67 + n * (-568.556 + n * (164.798 + n * (-27.0181 + 1.91826 * n))));
        r += (((135.926 / n) - 656.175) / n + 1376.53) / n;
    } else {
        r = 0.828421 +
            n * (-2.62051 + n * (3.36231 + n * (-1.95284 + n * (0.236494 + 0.145787 * n))));
    }
    return r / 3.0;
}

/* Egan & Hilgeman 1979 fit of the internal diffuse reflectance, as in Jensen et al. 2001 for
 * eta >= 1; for eta < 1 the companion fit of the same source (the eta >= 1 polynomial goes
 * negative there: F_dr(0.8) = -0.64). */
double lr_fresnel_diffuse_reflectance(double eta)
{
    if (eta >= 1.0)
        return -1.440 / (eta * eta) + 0.710 / eta + 0.668 + 0.0636 * eta;
    double inv = 1.0 / eta;
    return -0.4399 + inv * (0.7099 + inv * (-0.3319 + inv * 0.0636));
}
