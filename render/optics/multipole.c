/* The multipole of Donner & Jensen 2005 ("Light Diffusion in Multi-Layered Translucent
 * Materials", SIGGRAPH 2005, Sec. 3.2) for one slab of thickness d with the same index on both
 * faces: the standard dipole (Jensen et al. 2001) mirrored about both extrapolated boundaries.
 *
 * With L = d + 2 z_b, z_b = 2 A D (the dipole's extrapolation distance: its virtual source
 * sits at z_r + 2 z_b = mfp + 4 A D, lr_coeffs.z_v) and l = 1 / sigma_t' (lr_coeffs.z_r),
 * pole pair i = -n..n has a positive source at z_r,i = 2 i L + l and a negative one at
 * z_v,i = 2 i L - l - 2 z_b (depths below the lit face). The diffuse reflectance and
 * transmittance profiles are the fluxes through the two faces,
 *
 *   R(r) = alpha'/(4 pi) sum_i [ P(z_r,i) - P(z_v,i) ],
 *   T(r) = alpha'/(4 pi) sum_i [ P(d - z_r,i) - P(d - z_v,i) ],
 *   P(z) = z (sigma_tr s + 1) e^{-sigma_tr s} / s^3,  s = sqrt(r^2 + z^2),
 *
 * and i = 0 alone is exactly lr_dipole_rd. Over the plane, 2 pi int P(z) r dr =
 * 2 pi sgn(z) e^{-sigma_tr |z|} (d/ds of -e^{-sigma_tr s}/s is (sigma_tr s + 1) e^{-sigma_tr s}
 * / s^2), so the totals are closed sums too. Truncation: see optics.h (lr_multipole_pairs). */
#include "render/optics/optics.h"

#include <math.h>

/* Signed source term P(z); 0 when it underflows (as dipole.c's source_term). */
static double pole(double sigma_tr, double z, double r)
{
    double s = r < 1e150 ? sqrt(r * r + z * z) : hypot(r, z);
    if (!(s > 0.0))
        return 0.0;
    double a = sigma_tr * s;
    return z * (a + 1.0) * exp(-a) / (s * s * s);
}

/* The real source's depth: one reduced mean free path (Jensen 2001; Donner & Jensen 2005), but
 * at most half the slab. A slab thinner than 2 mfp is outside diffusion's validity anyway; the
 * cap keeps the source inside it, where R, T >= 0 and R + T <= alpha' (lr_multipole_total). */
static double source_depth(const lr_coeffs *c, int band, double d)
{
    return fmin(c->z_r[band], 0.5 * d);
}

static double sgn_exp(double sigma_tr, double z)
{
    return (z > 0.0 ? 1.0 : z < 0.0 ? -1.0 : 0.0) * exp(-sigma_tr * fabs(z));
}

double lr_multipole_tail(const lr_coeffs *c, int band, double d, int n)
{
    double s = c->sigma_tr[band], l = c->z_r[band], zb = 0.5 * (c->z_v[band] - c->z_r[band]);
    double L = d + 2.0 * zb, q = exp(-2.0 * s * L);
    if (!(q < 1.0))
        return INFINITY; /* sigma_tr == 0: the image series does not converge absolutely */
    /* Every pole of pairs +-i (i >= 1) lies at least 2 i L - L - l from either face (L > l since
     * 2 z_b >= (4/3) l), so its plane total is at most alpha'/2 e^{-sigma_tr ((2i - 1) L - l)};
     * 4 poles per i, geometric in q = e^{-2 sigma_tr L}. */
    return 2.0 * c->albedo_prime[band] * exp(s * (L + l)) * pow(q, n + 1) / (1.0 - q);
}

int lr_multipole_pairs(const lr_coeffs *c, double d)
{
    int n = 0;
    for (int j = 0; j < 3; j++) {
        double s = c->sigma_tr[j], l = c->z_r[j], zb = 0.5 * (c->z_v[j] - c->z_r[j]);
        double L = d + 2.0 * zb, a = 2.0 * s * L;
        if (!(c->albedo_prime[j] > 0.0))
            continue; /* nothing scatters: every pole is 0 */
        if (!(a > 0.0))
            return LR_MULTIPOLE_MAX_PAIRS;
        /* Smallest n with lr_multipole_tail <= LR_MULTIPOLE_TAIL, solved for q^{n+1}; the loop
         * below only corrects the rounding of the logarithms. */
        double q = exp(-a), k = 2.0 * c->albedo_prime[j] * exp(s * (L + l)) / -expm1(-a);
        double m = ceil(log(LR_MULTIPOLE_TAIL / k) / -a) - 1.0;
        int nj = m > LR_MULTIPOLE_MAX_PAIRS ? LR_MULTIPOLE_MAX_PAIRS : m > 0.0 ? (int)m : 0;
        while (nj < LR_MULTIPOLE_MAX_PAIRS && k * pow(q, nj + 1) > LR_MULTIPOLE_TAIL)
            nj++;
        if (nj > n)
            n = nj;
    }
    return n;
}

/* alpha'/(4 pi) times the pole sum through one face (far: the bottom, T; else the top, R),
 * band j, clamped >= 0. */
static double face(const lr_coeffs *c, double d, int n, double r, int j, bool far)
{
    double s = c->sigma_tr[j], l = source_depth(c, j, d), zb = 0.5 * (c->z_v[j] - c->z_r[j]);
    double L = d + 2.0 * zb, sum = 0.0;
    for (int i = -n; i <= n; i++) {
        double zr = 2.0 * i * L + l, zv = 2.0 * i * L - l - 2.0 * zb;
        sum += far ? pole(s, d - zr, r) - pole(s, d - zv, r) : pole(s, zr, r) - pole(s, zv, r);
    }
    /* The truncated series can dip below 0 far out (its pairs' dipole tails); the profile is a
     * flux out of the slab, so it is clamped as the directional dipole is [14]. */
    return fmax(0.0, c->albedo_prime[j] / (4.0 * M_PI) * sum);
}

void lr_multipole_profile_n(const lr_coeffs *c, double d, int n, double r, double R[3],
                            double T[3])
{
    for (int j = 0; j < 3; j++) {
        R[j] = face(c, d, n, r, j, false);
        T[j] = face(c, d, n, r, j, true);
    }
}

void lr_multipole_profile(const lr_coeffs *c, double d, double r, double R[3], double T[3])
{
    lr_multipole_profile_n(c, d, lr_multipole_pairs(c, d), r, R, T);
}

static int check_d(double d, lr_err *e)
{
    if (!isfinite(d) || !(d >= LR_MULTIPOLE_D_MIN) || d > LR_MULTIPOLE_D_MAX)
        return lr_err_set(e, LR_EINVAL,
                          "multipole: thickness_mm = %g: must be finite, in [%g, %g] mm", d,
                          LR_MULTIPOLE_D_MIN, LR_MULTIPOLE_D_MAX);
    return LR_OK;
}

int lr_multipole_profile_checked(const lr_coeffs *c, double d, double r, double R[3],
                                 double T[3], lr_err *e)
{
    if (!c || !R || !T)
        return lr_err_set(e, LR_EINVAL, "multipole: NULL %s", !c ? "coefficients" : "output");
    int rc = check_d(d, e);
    if (rc)
        return rc;
    if (!isfinite(r) || r < 0.0)
        return lr_err_set(e, LR_EINVAL, "multipole: r = %g: must be finite and >= 0 (mm)", r);
    lr_multipole_profile(c, d, r, R, T);
    return LR_OK;
}

int lr_multipole_thickness_validate(double d, lr_err *e)
{
    return check_d(d, e);
}

void lr_multipole_total_n(const lr_coeffs *c, double d, int n, double R[3], double T[3])
{
    for (int j = 0; j < 3; j++) {
        double s = c->sigma_tr[j], l = source_depth(c, j, d), zb = 0.5 * (c->z_v[j] - c->z_r[j]);
        double L = d + 2.0 * zb, sr = 0.0, st = 0.0;
        for (int i = -n; i <= n; i++) {
            double zr = 2.0 * i * L + l, zv = 2.0 * i * L - l - 2.0 * zb;
            sr += sgn_exp(s, zr) - sgn_exp(s, zv);
            st += sgn_exp(s, d - zr) - sgn_exp(s, d - zv);
        }
        R[j] = 0.5 * c->albedo_prime[j] * sr;
        T[j] = 0.5 * c->albedo_prime[j] * st;
    }
}

/* -expm1(-2 k a) / -expm1(-2 k L): sinh(k a) / sinh(k L) without the e^{k (L - a)} factor,
 * and its limit a / L at k = 0. */
static double sinh_ratio(double k, double a, double L)
{
    double x = 2.0 * k * L;
    return x > 1e-12 ? expm1(-2.0 * k * a) / expm1(-x) : a / L;
}

void lr_multipole_total(const lr_coeffs *c, double d, double R[3], double T[3])
{
    for (int j = 0; j < 3; j++) {
        /* The infinite series: over the plane the slab is the 1-D problem phi'' = sigma_tr^2
         * phi on u = z + z_b in [0, L], phi = 0 at both ends, unit source at u' = l + z_b.
         * Its Green's function sinh(k u_<) sinh(k (L - u_>)) / (D k sinh(k L)) gives the fluxes
         * through the real faces u = z_b and u = L - z_b:
         *   R / alpha' = cosh(k z_b) sinh(k (L - l - z_b)) / sinh(k L),
         *   T / alpha' = cosh(k z_b) sinh(k (l + z_b)) / sinh(k L),
         * written with e^{-...} factors so that large k L does not overflow. At k = 0:
         * (L - l - z_b) / L and (l + z_b) / L, which add up to 1; for d -> inf R is
         * lr_dipole_rd_total. R + T = alpha' cosh(k z_b) cosh(k (L/2 - l - z_b)) / cosh(k L/2)
         * <= alpha' since l <= d. */
        double k = c->sigma_tr[j], l = source_depth(c, j, d), zb = 0.5 * (c->z_v[j] - c->z_r[j]);
        double L = d + 2.0 * zb, ch = 0.5 * (1.0 + exp(-2.0 * k * zb));
        R[j] = c->albedo_prime[j] * ch * exp(-k * l) * sinh_ratio(k, L - l - zb, L);
        T[j] = c->albedo_prime[j] * ch * exp(-k * (d - l)) * sinh_ratio(k, l + zb, L);
    }
}

void lr_multipole_transmission_gain(const lr_coeffs *c, double d, double out[3])
{
    for (int j = 0; j < 3; j++) {
        /* T e^{k d} with T as in lr_multipole_total: the e^{-k (d - l)} there becomes e^{k l},
         * and k l = sigma_tr min(1/sigma_t', d/2) <= sigma_tr / sigma_t' = sqrt(3 sigma_a /
         * sigma_t') <= sqrt(3): finite however large k d is (T alone underflows to 0 there,
         * and T over e^{-k d} is 0/0). */
        double k = c->sigma_tr[j], l = source_depth(c, j, d), zb = 0.5 * (c->z_v[j] - c->z_r[j]);
        double L = d + 2.0 * zb, ch = 0.5 * (1.0 + exp(-2.0 * k * zb));
        out[j] = c->albedo_prime[j] * ch * exp(k * l) * sinh_ratio(k, l + zb, L);
    }
}

void lr_multipole_sd(const lr_coeffs *c, double d, lr_vec3 xi, lr_vec3 ni, lr_vec3 xo,
                     lr_vec3 no, double out[3])
{
    lr_multipole_sd_n(c, d, lr_multipole_pairs(c, d), xi, ni, xo, no, out);
}

void lr_multipole_sd_n(const lr_coeffs *c, double d, int n, lr_vec3 xi, lr_vec3 ni, lr_vec3 xo,
                       lr_vec3 no, double out[3])
{
    lr_vec3 x = lr_v3_sub(xo, xi);
    /* Opposite faces: light crossed the wall, and the slab's lateral offset is what is left of
     * the distance once the wall's thickness is taken out, sqrt(|x|^2 - d^2): on a flat slab
     * exactly the tangent-plane distance (|h| = d there). Not the tangent-plane distance
     * itself: two faces with opposed normals are also the two sides of a shade across its
     * inside (|x| = its diameter, x along the normal), which that distance would put at
     * r_perp = 0, as if the light had crossed one wall. Same face: the distance. */
    bool far = lr_v3_dot(ni, no) < 0.0;
    double x2 = lr_v3_dot(x, x);
    double r = far ? sqrt(fmax(x2 - d * d, 0.0)) : sqrt(x2);
    for (int j = 0; j < 3; j++)
        out[j] = face(c, d, n, r, j, far) / M_PI;
}

void lr_multipole_sd_fresnel(const lr_coeffs *c, double d, lr_vec3 xi, lr_vec3 ni, lr_vec3 wi,
                             lr_vec3 xo, lr_vec3 no, double out[3])
{
    lr_multipole_sd_fresnel_n(c, d, lr_multipole_pairs(c, d), xi, ni, wi, xo, no, out);
}

void lr_multipole_sd_fresnel_n(const lr_coeffs *c, double d, int n, lr_vec3 xi, lr_vec3 ni,
                               lr_vec3 wi, lr_vec3 xo, lr_vec3 no, double out[3])
{
    double cos_i = lr_v3_dot(wi, ni);
    double t = cos_i > 0.0 ? lr_fresnel_transmittance(cos_i, c->eta) : 0.0;
    if (!(t > 0.0)) {
        out[0] = out[1] = out[2] = 0.0;
        return;
    }
    lr_multipole_sd_n(c, d, n, xi, ni, xo, no, out);
    for (int j = 0; j < 3; j++)
        out[j] *= t;
}
