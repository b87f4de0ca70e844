/* The directional dipole of Frisvad, Hachisuka & Kjeldsen 2014 ([14] of seed 003: Directional
 * Dipole Model for Subsurface Scattering, ACM TOG 34(1)): the diffusive part S_d of a BSSRDF
 * built from a pair of ray sources, one along the refracted incident ray and one mirrored in a
 * modified tangent plane through x_i that contains x_o.
 *
 * The formula follows the paper and its authors' sample code; the differences are guards that
 * only act where the published expression would produce NaN or Inf: an undefined modified
 * normal, albedo' = 0 (extrapolation distance de = Inf), square roots of values that rounding
 * pushes below zero, and distances that vanish. */
#include "render/optics/optics.h"

#include <math.h>

/* A source closer to x_o than this many reduced mean free paths is moved out to it. Only the
 * real source at r -> 0 with mu0 -> 0 (eta < 1 at the critical angle) or a virtual source that
 * x_o sits on (x_o outside the medium, on the fallback normal) get this close; elsewhere
 * d_r >= D mu0 and d_v >= 2 A de keep the distances orders of magnitude larger. */
#define LR_DIRPOLE_DIST_FLOOR 1e-6
/* Smallest sin(angle(n_i, x_o - x_i)) for which the modified normal is well defined; below it
 * (x_o straight above/below x_i, or x_o == x_i) n_i is used instead. */
#define LR_DIRPOLE_PARALLEL_EPS 1e-9

/* [14] S'_d(x, w, r): the exitance at x_o due to one ray source with direction w whose origin
 * is at offset x from x_o's reference point, evaluated at distance r, for band j:
 *
 *   S'_d = C_phi_norm / (4 pi^2) e^{-s} / r^3 [ C_phi (r^2/D + 3 (1+s) x.w)
 *          - C_E (3 D (1+s) w.n - ((1+s) + 3 D (3 (1+s) + s^2) / r^2 x.w) x.n) ],  s = sigma_tr r.
 *
 * Multiplied out with u = x / r (|u| <= 1 because r >= |x| for both sources), so that no term
 * grows faster than 1/r^3 overall and none overflows for large r. */
static double sp_d(const lr_coeffs *c, int j, lr_vec3 x, lr_vec3 w, double r, lr_vec3 n)
{
    double s = c->sigma_tr[j] * r;
    /* e^{-745} is below the smallest double: the term is exactly 0 there. The test also catches
     * r = Inf (and 0 * Inf = NaN when sigma_tr = 0) before any Inf/Inf. */
    if (!(s < 745.0) || !(r < INFINITY))
        return 0.0;
    double D = c->D[j];
    double inv_r = 1.0 / r;
    double one_s = 1.0 + s;
    double uw = lr_v3_dot(x, w) * inv_r;
    double un = lr_v3_dot(x, n) * inv_r;
    double wn = lr_v3_dot(w, n);
    double phi = 1.0 / D + 3.0 * one_s * uw * inv_r;
    double E = 3.0 * D * one_s * wn * inv_r * inv_r -
               (one_s * inv_r + 3.0 * D * (3.0 * one_s + s * s) * uw * inv_r * inv_r) * un;
    return c->C_phi_norm / (4.0 * M_PI * M_PI) * exp(-s) * inv_r * (c->C_phi * phi - c->C_E * E);
}

void lr_dirpole_sd(const lr_coeffs *c, lr_vec3 xi, lr_vec3 ni, lr_vec3 wi, lr_vec3 xo,
                   lr_vec3 no, double out[3])
{
    lr_vec3 x = lr_v3_sub(xo, xi);
    double r = lr_v3_len(x);

    /* [14]: modified tangent-plane normal n_i* = x^ x (n_i x x) / |n_i x x|, i.e. the part of
     * n_i orthogonal to x^, normalised: the plane through x_i with this normal contains x_o. */
    lr_vec3 nis = ni;
    if (r > 0.0 && r < INFINITY) {
        lr_vec3 xh = lr_v3_scale(x, 1.0 / r);
        lr_vec3 p = lr_v3_sub(ni, lr_v3_scale(xh, lr_v3_dot(ni, xh)));
        double lp = lr_v3_len(p);
        if (lp > LR_DIRPOLE_PARALLEL_EPS)
            nis = lr_v3_scale(p, 1.0 / lp);
    }

    /* Refract w_i into the medium about the true normal n_i (Snell, relative index eta).
     * Under total internal reflection (eta < 1, grazing light) the sqrt argument is negative:
     * take the grazing limit cos_t = 0 instead of NaN. */
    double inv_eta = 1.0 / c->eta;
    double cos_i = lr_v3_dot(wi, ni);
    double sin_t2 = inv_eta * inv_eta * (1.0 - cos_i) * (1.0 + cos_i);
    double cos_t = sin_t2 < 1.0 ? sqrt(1.0 - sin_t2) : 0.0;
    lr_vec3 wr = lr_v3_add(lr_v3_scale(wi, -inv_eta), lr_v3_scale(ni, inv_eta * cos_i - cos_t));
    double lwr = lr_v3_len(wr);
    wr = lwr > 0.0 ? lr_v3_scale(wr, 1.0 / lwr) : lr_v3_scale(ni, -1.0);
    /* [14]: the virtual ray source runs along w_r mirrored in the modified tangent plane. */
    lr_vec3 wv = lr_v3_sub(wr, lr_v3_scale(nis, 2.0 * lr_v3_dot(wr, nis)));

    double mu0 = -lr_v3_dot(no, wr);
    /* |x x w_r|^2 = r^2 - (x.w_r)^2 without the cancellation that can make the latter < 0. */
    double x_perp_wr = lr_v3_len(lr_v3_cross(x, wr));

    for (int j = 0; j < 3; j++) {
        double D = c->D[j], de = c->de[j];
        double floor_d = LR_DIRPOLE_DIST_FLOOR * c->mfp[j];
        double dr;
        if (mu0 > 0.0) {
            /* [14]: cos_beta = -sqrt((r^2 - (x.w_r)^2) / (r^2 + de^2)),
             * d_r^2 = D mu0 (D mu0 - 2 de cos_beta) + r^2. With q = -de cos_beta
             * = |x x w_r| / sqrt(1 + (r/de)^2), which stays finite as de -> Inf. */
            double rd = r / de;
            double q = x_perp_wr / sqrt(1.0 + rd * rd);
            dr = sqrt(D * mu0 * (D * mu0 + 2.0 * q) + r * r);
        } else {
            /* [14]: d_r^2 = 1 / (3 sigma_t)^2 + r^2 when the refracted ray leaves through n_o. */
            double z = 1.0 / (3.0 * c->sigma_t[j]);
            dr = sqrt(z * z + r * r);
        }
        if (dr < floor_d)
            dr = floor_d;
        double real = sp_d(c, j, x, wr, dr, no);

        /* [14]: virtual source at x_v = x_i + 2 A de n_i*. When albedo' -> 0, de -> Inf and the
         * virtual source recedes to infinity: its term is 0 (sp_d also returns 0 once
         * sigma_tr d_v exceeds the exp range). */
        double virt = 0.0;
        double zv = 2.0 * c->A_dir * de;
        if (zv < INFINITY) {
            lr_vec3 xv = lr_v3_sub(x, lr_v3_scale(nis, zv)); /* x_o - x_v */
            double dv = lr_v3_len(xv);
            if (dv < floor_d)
                dv = floor_d;
            virt = sp_d(c, j, xv, wv, dv, no);
        }
        double sd = real - virt;
        out[j] = sd > 0.0 ? sd : 0.0; /* [14] clamps negative values to zero */
    }
}

void lr_dirpole_sd_fresnel(const lr_coeffs *c, lr_vec3 xi, lr_vec3 ni, lr_vec3 wi, lr_vec3 xo,
                           lr_vec3 no, double out[3])
{
    /* seed 003 Eq. 2/4: S_d F_t(w_i); light from behind the surface does not enter. */
    double cos_i = lr_v3_dot(wi, ni);
    double t = cos_i > 0.0 ? lr_fresnel_transmittance(cos_i, c->eta) : 0.0;
    if (!(t > 0.0)) {
        out[0] = out[1] = out[2] = 0.0;
        return;
    }
    lr_dirpole_sd(c, xi, ni, wi, xo, no, out);
    for (int j = 0; j < 3; j++)
        out[j] *= t;
}

static int check_point(const char *field, lr_vec3 p, lr_err *e)
{
    if (!lr_v3_isfinite(p))
        return lr_err_set(e, LR_EINVAL, "dirpole: %s = (%g, %g, %g): must be finite (mm)", field,
                          p.x, p.y, p.z);
    return LR_OK;
}

static int check_dir(const char *field, lr_vec3 *d, lr_err *e)
{
    if (!lr_v3_isfinite(*d))
        return lr_err_set(e, LR_EINVAL, "dirpole: %s = (%g, %g, %g): must be finite", field,
                          d->x, d->y, d->z);
    double l = lr_v3_len(*d);
    /* A length that underflows or overflows when squared cannot be normalised reliably. */
    if (!(l > 1e-150 && l < 1e150))
        return lr_err_set(e, LR_EINVAL, "dirpole: %s = (%g, %g, %g): zero-length direction", field,
                          d->x, d->y, d->z);
    *d = lr_v3_scale(*d, 1.0 / l);
    return LR_OK;
}

int lr_dirpole_sd_checked(const lr_coeffs *c, lr_vec3 xi, lr_vec3 ni, lr_vec3 wi, lr_vec3 xo,
                          lr_vec3 no, int with_fresnel, double out[3], lr_err *e)
{
    int rc;
    if (!c || !out)
        return lr_err_set(e, LR_EINVAL, "dirpole: NULL %s", !c ? "coefficients" : "output");
    if ((rc = check_point("x_i", xi, e)) || (rc = check_point("x_o", xo, e)) ||
        (rc = check_dir("n_i", &ni, e)) || (rc = check_dir("w_i", &wi, e)) ||
        (rc = check_dir("n_o", &no, e)))
        return rc;
    if (with_fresnel)
        lr_dirpole_sd_fresnel(c, xi, ni, wi, xo, no, out);
    else
        lr_dirpole_sd(c, xi, ni, wi, xo, no, out);
    return LR_OK;
}
