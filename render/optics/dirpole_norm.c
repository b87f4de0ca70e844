/* Energy normalisation of the directional dipole (issue 3, PIPELINE.md "Energy").
 *
 * [14]'s S_d is not energy conserving: on a half-space at albedo' = 1 the power it sends back
 * out, T_hem pi int S_d dA, is 1.340 (eta 1), 1.240 (1.3) and 1.197 (1.5) times the power that
 * entered, where the standard dipole's total diffuse reflectance (Jensen 2001, closed form in
 * lr_dipole_rd_total) is exactly 1. The factor computed here rescales S_d per band so that its
 * half-space total at normal incidence equals the standard dipole's R_d total, at every albedo'
 * (the profile's shape is [14]'s; only its integral is the standard dipole's). */
#include <math.h>

#include "render/optics/optics.h"

/* 8-point Gauss-Legendre on [-1, 1]. */
static const double gl_x[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267,
                               0.9602898564975363};
static const double gl_w[4] = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745,
                               0.1012285362903763};

double lr_hemi_transmittance(double eta)
{
    /* 2 int_0^1 F_t(mu) mu d(mu); 64 panels resolve the kink at the critical angle (eta < 1). */
    const int panels = 64;
    double h = 1.0 / panels, sum = 0.0;
    for (int p = 0; p < panels; p++) {
        double mid = (p + 0.5) * h;
        for (int q = 0; q < 4; q++)
            for (int s = -1; s <= 1; s += 2) {
                double mu = mid + s * gl_x[q] * 0.5 * h;
                sum += gl_w[q] * 0.5 * h * lr_fresnel_transmittance(mu, eta) * mu;
            }
    }
    return 2.0 * sum;
}

void lr_dirpole_halfspace_albedo(const lr_coeffs *c, double out[3])
{
    /* int_0^inf 2 pi r S_d(r) dr = int 2 pi r^2 S_d d(ln r), light at normal incidence at the
     * origin, x_o at distance r on the same plane. S_d is finite at r -> 0 and falls as r^-3
     * (albedo' 1) or exponentially far out, so 1e-8 .. 1e7 mean free paths lose < 1e-6. */
    double lo = INFINITY, hi = 0.0;
    for (int j = 0; j < 3; j++) {
        lo = fmin(lo, c->mfp[j]);
        hi = fmax(hi, c->mfp[j]);
    }
    double a = log(1e-8 * lo), b = log(1e7 * hi);
    const int panels = 320;
    double h = (b - a) / panels, sum[3] = {0};
    lr_vec3 z = lr_v3(0, 0, 1), o = lr_v3(0, 0, 0);
    for (int p = 0; p < panels; p++) {
        double mid = a + (p + 0.5) * h;
        for (int q = 0; q < 4; q++)
            for (int s = -1; s <= 1; s += 2) {
                double r = exp(mid + s * gl_x[q] * 0.5 * h), sd[3];
                lr_dirpole_sd(c, lr_v3(r, 0, 0), z, z, o, z, sd);
                for (int j = 0; j < 3; j++)
                    sum[j] += gl_w[q] * 0.5 * h * 2.0 * M_PI * r * r * sd[j];
            }
    }
    double t = lr_hemi_transmittance(c->eta);
    for (int j = 0; j < 3; j++)
        out[j] = M_PI * t * sum[j];
}

void lr_dirpole_energy_norm(const lr_coeffs *c, double out[3])
{
    double dir[3], rd[3];
    lr_dirpole_halfspace_albedo(c, dir);
    lr_dipole_rd_total(c, rd);
    for (int j = 0; j < 3; j++) {
        double f = rd[j] / dir[j];
        out[j] = isfinite(f) && f > 0.0 ? f : 1.0; /* albedo' 0: both totals vanish */
    }
}
