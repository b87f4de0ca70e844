/* Henyey-Greenstein phase function, direction sampling and the local frame. */
#include "render/reference/ref_priv.h"

/* Henyey & Greenstein 1941, normalised over the sphere:
 * p(cos) = (1 - g^2) / (4 pi (1 + g^2 - 2 g cos)^(3/2)). */
double lr_ref_hg_eval(double g, double cos_theta)
{
    double den = 1.0 + g * g - 2.0 * g * cos_theta;
    return (1.0 - g * g) / (4.0 * LR_REF_PI * den * sqrt(den));
}

/* Exact inversion of the HG cumulative distribution in cos theta (e.g. Prahl 1988 / Wang &
 * Jacques 1995 MCML manual, Eq. 3.28; pbrt-v3 Sec. 15.2.3):
 *   cos = (1 + g^2 - ((1 - g^2) / (1 - g + 2 g u))^2) / (2 g),   g != 0
 *   cos = 2u - 1,                                                 g == 0.
 * For tiny |g| the first form loses digits to cancellation (~eps/|g| absolute), which is
 * still far below a sampling error; it is exact HG in exact arithmetic for every g != 0. */
static double hg_cos(double g, double u)
{
    if (g == 0.0)
        return 2.0 * u - 1.0;
    double f = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
    double c = (1.0 + g * g - f * f) / (2.0 * g);
    return c < -1.0 ? -1.0 : (c > 1.0 ? 1.0 : c);
}

void lr_ref_frame(lr_vec3 n, lr_vec3 *t1, lr_vec3 *t2)
{
    /* Duff, Burgess, Christensen, Hery, Kensler, Liani, Villemin 2017, Listing 3. */
    double sign = copysign(1.0, n.z);
    double a = -1.0 / (sign + n.z);
    double b = n.x * n.y * a;
    *t1 = lr_v3(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    *t2 = lr_v3(b, sign + n.y * n.y * a, -n.y);
}

/* Direction with polar cosine c and azimuth 2 pi u about unit axis a. */
static lr_vec3 around(lr_vec3 a, double c, double u)
{
    lr_vec3 t1, t2;
    lr_ref_frame(a, &t1, &t2);
    double s = sqrt(fmax(0.0, 1.0 - c * c));
    double phi = 2.0 * LR_REF_PI * u;
    lr_vec3 v = lr_v3_add(lr_v3_scale(a, c),
                          lr_v3_add(lr_v3_scale(t1, s * cos(phi)), lr_v3_scale(t2, s * sin(phi))));
    return lr_v3_normalize(v);
}

lr_vec3 lr_ref_hg_sample(double g, lr_vec3 d, double u1, double u2)
{
    return around(d, hg_cos(g, u1), u2);
}

lr_vec3 lr_ref_cosine_sample(lr_vec3 n, double u1, double u2)
{
    /* Malley's method: cos theta = sqrt(u) has density cos / pi over the hemisphere. */
    return around(n, sqrt(u1), u2);
}

bool lr_ref_refract(lr_vec3 d, lr_vec3 n, double eta_rel, lr_vec3 *out)
{
    /* Snell's law in vector form (e.g. pbrt-v3 Sec. 8.2.3): with cos_i = -d.n,
     * t = eta d + (eta cos_i - cos_t) n, sin_t^2 = eta^2 (1 - cos_i^2). */
    double ci = -lr_v3_dot(d, n);
    double s2 = eta_rel * eta_rel * (1.0 - ci) * (1.0 + ci);
    if (s2 >= 1.0)
        return false;
    double ct = sqrt(1.0 - s2);
    *out = lr_v3_normalize(lr_v3_add(lr_v3_scale(d, eta_rel), lr_v3_scale(n, eta_rel * ci - ct)));
    return true;
}
