/* Real spherical harmonics up to l = 2 and the irradiance they imply for a convex Lambertian
 * receiver (Ramamoorthi & Hanrahan 2001, An Efficient Representation for Irradiance
 * Environment Maps; seed 002 Eq. 10-11). */
#include "render/optics/optics.h"

#include <math.h>

void lr_sh9_basis(lr_vec3 d, double out[9])
{
    /* Normalisation constants K_lm of seed 002 Eq. 8 with the real combinations of Eq. 9:
     * 1/(2 sqrt(pi)), sqrt(3/(4 pi)), sqrt(15/pi)/2, sqrt(5/pi)/4, sqrt(15/pi)/4
     * (0.282095, 0.488603, 1.092548, 0.315392, 0.546274 in Ramamoorthi & Hanrahan). */
    const double k00 = 0.5 / sqrt(M_PI);
    const double k1 = sqrt(3.0 / (4.0 * M_PI));
    const double k2 = 0.5 * sqrt(15.0 / M_PI);
    const double k20 = 0.25 * sqrt(5.0 / M_PI);
    const double k22 = 0.25 * sqrt(15.0 / M_PI);
    out[0] = k00;
    out[1] = k1 * d.y;
    out[2] = k1 * d.z;
    out[3] = k1 * d.x;
    out[4] = k2 * d.x * d.y;
    out[5] = k2 * d.y * d.z;
    out[6] = k20 * (3.0 * d.z * d.z - 1.0);
    out[7] = k2 * d.x * d.z;
    out[8] = k22 * (d.x * d.x - d.y * d.y);
}

double lr_sh9_irradiance(const double coeffs[9], lr_vec3 n)
{
    /* Funk-Hecke: convolving with the clamped cosine max(0, n.w) scales band l by A_l:
     * A_0 = pi, A_1 = 2 pi / 3, A_2 = pi / 4 (Ramamoorthi & Hanrahan 2001). */
    static const double A[9] = {M_PI,
                                2.0 * M_PI / 3.0, 2.0 * M_PI / 3.0, 2.0 * M_PI / 3.0,
                                M_PI / 4.0, M_PI / 4.0, M_PI / 4.0, M_PI / 4.0, M_PI / 4.0};
    double y[9];
    lr_sh9_basis(n, y);
    double e = 0.0;
    for (int k = 0; k < 9; k++)
        e += A[k] * coeffs[k] * y[k];
    return e;
}
