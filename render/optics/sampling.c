/* Sample generation: the exponential radius distribution of seed 003 Sec. 3.1 (one per colour
 * band) and the Halton sequence used for the scattered-radiosity map directions. */
#include "render/optics/optics.h"

#include <math.h>

/* Below this sigma_tr r_max the truncated exponential differs from the uniform density by a
 * relative O(sigma_tr r_max) < 1e-150: use the uniform formulas, which cannot lose digits. */
#define LR_EXP_UNIFORM_LIMIT 1e-150

static int params_ok(double sigma_tr, double r_max)
{
    return sigma_tr >= 0.0 && sigma_tr < INFINITY && r_max > 0.0 &&
           (sigma_tr > 0.0 || r_max < INFINITY);
}

double lr_exp_radius_sample(double sigma_tr, double r_max, double xi)
{
    if (!params_ok(sigma_tr, r_max))
        return NAN;
    double sr = sigma_tr * r_max; /* Inf when r_max is */
    if (sr < LR_EXP_UNIFORM_LIMIT)
        return xi * r_max;
    /* Inverse CDF of p(r) = sigma_tr e^{-sigma_tr r} / (1 - e^{-sigma_tr r_max}):
     * r = -log(1 - xi (1 - e^{-sigma_tr r_max})) / sigma_tr. With r_max = Inf this is seed 003
     * Eq. 12 with xi_1 = 1 - xi (same distribution; xi < 1 keeps the log finite). log1p/expm1
     * keep full precision when sigma_tr r_max is small (the nearly uniform case). */
    double mass = -expm1(-sr); /* 1 - e^{-sigma_tr r_max}, exactly 1 for r_max = Inf */
    double r = -log1p(-xi * mass) / sigma_tr;
    /* Rounding can put r a hair above r_max for xi -> 1. */
    return r < r_max ? r : r_max;
}

double lr_exp_radius_pdf(double sigma_tr, double r_max, double r)
{
    if (!params_ok(sigma_tr, r_max))
        return NAN;
    if (!(r >= 0.0 && r <= r_max))
        return r != r ? NAN : 0.0;
    double sr = sigma_tr * r_max;
    if (sr < LR_EXP_UNIFORM_LIMIT)
        return 1.0 / r_max;
    /* seed 003 Eq. 11 (radial part), renormalised to [0, r_max]. */
    return sigma_tr * exp(-sigma_tr * r) / -expm1(-sr);
}

int lr_exp_radius_validate(double sigma_tr, double r_max, lr_err *e)
{
    if (!isfinite(sigma_tr) || sigma_tr < 0.0)
        return lr_err_set(e, LR_EINVAL,
                          "exp radius: sigma_tr = %g: must be finite and >= 0 (mm^-1)", sigma_tr);
    if (isnan(r_max) || r_max <= 0.0)
        return lr_err_set(e, LR_EINVAL, "exp radius: r_max = %g: must be > 0 (mm) or INFINITY",
                          r_max);
    if (sigma_tr == 0.0 && isinf(r_max))
        return lr_err_set(e, LR_EINVAL,
                          "exp radius: r_max = inf with sigma_tr = 0: no density; truncate r_max");
    return LR_OK;
}

double lr_halton(unsigned index, unsigned base)
{
    if (base < 2)
        return NAN;
    /* Radical inverse (Halton 1964): mirror the base-b digits of index about the point. */
    double inv = 1.0 / base, f = inv, r = 0.0;
    while (index > 0) {
        r += f * (double)(index % base);
        index /= base;
        f *= inv;
    }
    return r;
}

lr_vec3 lr_halton_sphere(unsigned index)
{
    /* Uniform on the sphere (Archimedes: z uniform in [-1, 1]), driven by Halton (2, 3). */
    double z = 1.0 - 2.0 * lr_halton(index, 2);
    double phi = 2.0 * M_PI * lr_halton(index, 3);
    double s = sqrt(fmax(0.0, (1.0 - z) * (1.0 + z)));
    return lr_v3(s * cos(phi), s * sin(phi), z);
}
