/* Fresnel: exact dielectric reflectance against closed forms at special angles, and the diffuse
 * moment fits against numerical quadrature of the exact reflectance. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "tests/support/near.h"
#include <math.h>
#include <string.h>

#include "render/optics/optics.h"
#include "tests/support/quadrature.h"

/* At normal incidence rs = (1 - eta)/(1 + eta), rp = (eta - 1)/(eta + 1), so R is
 * ((eta - 1)/(eta + 1))^2 (Born & Wolf 1.5.(27)). Same algebra, a few roundings: 1e-15. Published
 * anchors: glass 1.5 reflects exactly 4 %, water 1.333 about 2.0 %. */
static void test_normal_incidence(void **state)
{
    (void)state;
    const double etas[] = {1.333, 1.5, 2.4, 0.5, 1.0 / 1.5, 1.0001};
    for (size_t k = 0; k < sizeof etas / sizeof etas[0]; k++) {
        double eta = etas[k], expect = pow((eta - 1.0) / (eta + 1.0), 2.0);
        assert_near(lr_fresnel_reflectance(1.0, eta), expect, 1e-15);
        assert_near(lr_fresnel_transmittance(1.0, eta), (1.0 - expect), 1e-15);
    }
    assert_near(lr_fresnel_reflectance(1.0, 1.5), 0.04, 1e-15);
    assert_near(lr_fresnel_reflectance(1.0, 1.333), 0.0204, 1e-4);
}

/* Brewster angle tan(theta_B) = eta: rp = 0, and since theta_i + theta_t = 90 deg there,
 * R_s = cos^2(2 theta_B) = ((1 - eta^2)/(1 + eta^2))^2, so R = R_s / 2. For glass 1.5 that is
 * 0.0739645 (R_s = 14.8 %, the textbook figure). Trig roundings: 1e-14. */
static void test_brewster(void **state)
{
    (void)state;
    const double etas[] = {1.5, 1.333, 2.0, 1.0 / 1.5};
    for (size_t k = 0; k < sizeof etas / sizeof etas[0]; k++) {
        double eta = etas[k];
        double cos_b = cos(atan(eta));
        double rs = (1.0 - eta * eta) / (1.0 + eta * eta);
        assert_near(lr_fresnel_reflectance(cos_b, eta), 0.5 * rs * rs, 1e-14);
    }
    assert_near(lr_fresnel_reflectance(cos(atan(1.5)), 1.5), 0.0739645, 1e-7);
}

/* Total internal reflection for eta < 1 (light leaving glass): sin_c = eta. Below the critical
 * cosine R is exactly 1. Just above it, with delta = cos_i - cos_c, the transmitted cosine is
 * cos_t ~ sqrt(2 cos_c delta) / eta and the Fresnel transmittances to first order are
 * T_s = 4 eta cos_t / cos_i, T_p = 4 cos_t / (eta cos_i), so
 * T ~ 2 (eta + 1/eta) sqrt(2 cos_c delta) / (eta cos_c). The next order is O(sqrt(delta)) relative,
 * 1e-5 for delta = 1e-10: assert 1e-3. */
static void test_critical_angle(void **state)
{
    (void)state;
    const double etas[] = {1.0 / 1.5, 1.0 / 1.33, 0.5};
    for (size_t k = 0; k < sizeof etas / sizeof etas[0]; k++) {
        double eta = etas[k];
        double cos_c = sqrt(1.0 - eta * eta);
        assert_true(lr_fresnel_reflectance(cos_c * (1.0 - 1e-12), eta) == 1.0);
        assert_true(lr_fresnel_reflectance(0.0, eta) == 1.0);
        assert_true(lr_fresnel_reflectance(0.5 * cos_c, eta) == 1.0);
        double delta = 1e-10;
        double t = lr_fresnel_transmittance(cos_c + delta, eta);
        double expect = 2.0 * (eta + 1.0 / eta) * sqrt(2.0 * cos_c * delta) / (eta * cos_c);
        assert_true(t > 0.0);
        assert_near_rel(t, expect, 1e-3);
    }
}

/* Grazing incidence from the thin side (eta > 1): R -> 1 with
 * 1 - R ~ 2 cos_i (1 + eta^2) / (eta cos_t0), cos_t0 = sqrt(1 - 1/eta^2) (first order in
 * cos_i / cos_t0 of rs^2 and rp^2). The neglected order is relative O(cos_i / cos_t0) (observed
 * 2 cos_i / cos_t0 for eta = 1.0001, where cos_t0 = 0.014), and 1 - R carries a cancellation
 * error of 1e-16 / (1 - R) <= 2e-9: assert 4 cos_i / cos_t0 + 1e-8. At cos_i = 0, R = 1. */
static void test_grazing(void **state)
{
    (void)state;
    const double etas[] = {1.5, 1.3, 2.4, 1.0001};
    for (size_t k = 0; k < sizeof etas / sizeof etas[0]; k++) {
        double eta = etas[k], ci = 1e-8;
        double cos_t0 = sqrt(1.0 - 1.0 / (eta * eta));
        double expect = 2.0 * ci * (1.0 + eta * eta) / (eta * cos_t0);
        assert_near_rel(lr_fresnel_transmittance(ci, eta), expect, 4.0 * ci / cos_t0 + 1e-8);
        assert_true(lr_fresnel_reflectance(0.0, eta) == 1.0);
    }
}

/* Index matched: no interface, R = 0 at every angle, grazing included (where the general
 * formula would be 0/0). */
static void test_eta_one(void **state)
{
    (void)state;
    for (int k = 0; k <= 100; k++) {
        double ci = k / 100.0;
        assert_true(lr_fresnel_reflectance(ci, 1.0) == 0.0);
        assert_true(lr_fresnel_transmittance(ci, 1.0) == 1.0);
    }
}

/* Stokes reciprocity: the reflectance of an interface is the same from both sides for a ray
 * and its refracted partner, R(cos_i, eta) = R(cos_t, 1/eta). An identity of the formulas; the
 * two evaluations differ by roundings: 1e-14, plus, near grazing, the reverse evaluation
 * recovers cos_i = sqrt(1 - sin^2) from a sin^2 ~ 1 with an absolute error ~5e-16, i.e.
 * cos_i off by 2.5e-16 / cos_i, times |dR/dcos_i| <= 2 (1 + eta^2) / (eta cos_t0) <= 14 for these
 * eta: + 4e-15 / cos_i. (cos_i = 0 maps onto the critical angle, where the map is singular:
 * skipped.) Also 0 <= R <= 1 and R non-increasing in cos_i for eta > 1. */
static void test_reciprocity_and_range(void **state)
{
    (void)state;
    const double etas[] = {1.5, 1.33, 2.0, 1.05};
    for (size_t k = 0; k < sizeof etas / sizeof etas[0]; k++) {
        double eta = etas[k], prev = 2.0;
        for (int i = 0; i <= 1000; i++) {
            double ci = i / 1000.0;
            double ct = sqrt(1.0 - (1.0 - ci * ci) / (eta * eta));
            double r = lr_fresnel_reflectance(ci, eta);
            if (i > 0)
                assert_near(r, lr_fresnel_reflectance(ct, 1.0 / eta), 1e-14 + 4e-15 / ci);
            assert_true(r >= 0.0 && r <= 1.0);
            assert_true(r <= prev + 1e-15);
            prev = r;
        }
    }
}

/* Out-of-range cosines are clamped, NaN propagates (hot path); the checked entry point rejects
 * them and names the field. */
static void test_checked(void **state)
{
    (void)state;
    lr_err e;
    double r = -1.0, t = -1.0;
    assert_int_equal(lr_fresnel_checked(0.5, 1.5, &r, &t, &e), LR_OK);
    assert_true(r == lr_fresnel_reflectance(0.5, 1.5) && t == 1.0 - r);
    const double bad_cos[] = {NAN, INFINITY, -0.1, 1.0000001};
    for (size_t k = 0; k < 4; k++) {
        lr_err_clear(&e);
        assert_int_equal(lr_fresnel_checked(bad_cos[k], 1.5, &r, NULL, &e), LR_EINVAL);
        assert_int_equal(e.code, LR_EINVAL);
        assert_non_null(strstr(e.msg, "cos_i"));
    }
    const double bad_eta[] = {NAN, INFINITY, -INFINITY, 0.0, -1.5};
    for (size_t k = 0; k < 5; k++) {
        lr_err_clear(&e);
        assert_int_equal(lr_fresnel_checked(0.5, bad_eta[k], NULL, NULL, &e), LR_EINVAL);
        assert_non_null(strstr(e.msg, "eta"));
    }
    assert_true(isnan(lr_fresnel_reflectance(NAN, 1.5)));
    assert_true(lr_fresnel_reflectance(1.5, 1.5) == lr_fresnel_reflectance(1.0, 1.5));
    assert_true(lr_fresnel_reflectance(-0.5, 1.5) == 1.0);
}

/* ---- Diffuse moments ---------------------------------------------------------------------- */

struct moment_ctx {
    double eta;   /* medium index; the reflectance seen from inside uses 1/eta */
    double mu_c;  /* critical cosine (0 when there is no total internal reflection) */
    int n;
};

/* Integrand on [mu_c, 1] after mu = mu_c + (1 - mu_c) t^2, which turns the square-root onset of
 * transmission at mu_c into a smooth function of t, so Gauss-Legendre converges geometrically. */
static double moment_integrand(double t, void *p)
{
    const struct moment_ctx *c = p;
    double mu = c->mu_c + (1.0 - c->mu_c) * t * t;
    return lr_fresnel_reflectance(mu, 1.0 / c->eta) * pow(mu, c->n) * 2.0 * (1.0 - c->mu_c) * t;
}

/* C_n(eta) = integral_0^1 R(mu; 1/eta) mu^n dmu; on [0, mu_c] R = 1 exactly. 40 panels x 16
 * points on a smooth integrand: error below 1e-13 (checked against 50-digit mpmath). */
static double moment_exact(double eta, int n)
{
    struct moment_ctx c = {eta, eta > 1.0 ? sqrt(1.0 - 1.0 / (eta * eta)) : 0.0, n};
    return pow(c.mu_c, n + 1) / (n + 1) + lrt_gl_integrate(moment_integrand, &c, 0.0, 1.0, 16, 40);
}

/* Quadrature sanity: for eta -> large the interior is almost all TIR; at eta = 1 C_n = 0; and
 * one value against an mpmath evaluation (2 C1(1.5) = 0.596346, 3 C2(1.5) = 0.464431). */
static void test_moment_quadrature(void **state)
{
    (void)state;
    assert_near(moment_exact(1.0, 1), 0.0, 1e-15);
    assert_near(2.0 * moment_exact(1.5, 1), 0.596346, 1e-6);
    assert_near(3.0 * moment_exact(1.5, 2), 0.464431, 1e-6);
}

/* The d'Eon & Irving fits (and Egan & Hilgeman's F_dr) against the exact moments on a 0.005
 * grid of eta over the supported range. Tolerance = each fit's own residual: its supremum over
 * the range, measured independently in 50-digit mpmath on a 0.0025 grid, rounded up ~5 %:
 *              2C1      3C2      F_dr - 2C1
 *   [0.5, 1]   2.07e-4  3.38e-4  1.60e-3
 *   (1, 2]     4.33e-3  6.84e-3  1.60e-3   (worst at eta -> 1+, where the eta > 1 branch
 *   (2, 2.5]   1.38e-3  6.92e-3  5.10e-3    leaves 2C1(1) = 4.4e-3 instead of 0)
 * A wrong coefficient or branch would show errors of 1e-2 or more. */
static void test_moment_fits(void **state)
{
    (void)state;
    for (int k = 0; k <= 400; k++) {
        double eta = 0.5 + 0.005 * k;
        double c1 = moment_exact(eta, 1), c2 = moment_exact(eta, 2);
        double tol1, tol2, tolf;
        if (eta <= 1.0) {
            tol1 = 2.2e-4, tol2 = 3.6e-4, tolf = 1.7e-3;
        } else if (eta <= 2.0) {
            tol1 = 4.6e-3, tol2 = 7.2e-3, tolf = 1.7e-3;
        } else {
            tol1 = 1.5e-3, tol2 = 7.3e-3, tolf = 5.4e-3;
        }
        double e1 = fabs(2.0 * lr_fresnel_moment1(eta) - 2.0 * c1);
        double e2 = fabs(3.0 * lr_fresnel_moment2(eta) - 3.0 * c2);
        double ef = fabs(lr_fresnel_diffuse_reflectance(eta) - 2.0 * c1);
        if (e1 > tol1 || e2 > tol2 || ef > tolf)
            fail_msg("eta %.3f: |2C1 err| %.3g (tol %.3g), |3C2 err| %.3g (tol %.3g), "
                     "|F_dr err| %.3g (tol %.3g)", eta, e1, tol1, e2, tol2, ef, tolf);
    }
}

/* eta = 1: the exact moments vanish; the fits give 2C1(1) = 2.07e-4 and 3C2(1) = -3.38e-4 (the
 * eta <= 1 branches), F_dr(1) = 1.6e-3: zero within the fits' residual above. */
static void test_moments_eta_one(void **state)
{
    (void)state;
    assert_near(2.0 * lr_fresnel_moment1(1.0), 0.0, 2.1e-4);
    assert_near(3.0 * lr_fresnel_moment2(1.0), 0.0, 3.4e-4);
    assert_near(lr_fresnel_diffuse_reflectance(1.0), 0.0, 1.61e-3);
    /* Continuity across the branch switch of 2C1 is only as good as the fit: the jump at 1 is
     * 4.2e-3, within the (1, 2] tolerance. */
    assert_near(2.0 * (lr_fresnel_moment1(1.0 + 1e-12) - lr_fresnel_moment1(1.0)), 0.0, 4.5e-3);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_normal_incidence),
        cmocka_unit_test(test_brewster),
        cmocka_unit_test(test_critical_angle),
        cmocka_unit_test(test_grazing),
        cmocka_unit_test(test_eta_one),
        cmocka_unit_test(test_reciprocity_and_range),
        cmocka_unit_test(test_checked),
        cmocka_unit_test(test_moment_quadrature),
        cmocka_unit_test(test_moment_fits),
        cmocka_unit_test(test_moments_eta_one),
    };
    return cmocka_run_group_tests_name("optics_fresnel", tests, NULL, NULL);
}
