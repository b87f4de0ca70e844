/* Sampling: the truncated exponential radius sampler of seed 003 Eq. 11-12 (histogram against
 * its density by chi-square, density against quadrature, inverse-CDF consistency, the
 * sigma_tr -> 0 cases), the Monte Carlo estimator of Eq. 9 it feeds, and the Halton sequence. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "tests/support/near.h"
#include <limits.h>
#include <math.h>
#include <string.h>

#include "render/optics/optics.h"
#include "tests/support/quadrature.h"

static uint64_t splitmix64(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/* Uniform in [0, 1) with 53 random bits. */
static double uniform01(uint64_t *s) { return (double)(splitmix64(s) >> 11) * 0x1.0p-53; }

struct pdf_ctx {
    double sigma_tr, r_max;
};

static double pdf_fn(double r, void *p)
{
    const struct pdf_ctx *c = p;
    return lr_exp_radius_pdf(c->sigma_tr, c->r_max, r);
}

/* integral of the pdf over [a, b] (b finite), adaptive Simpson to 1e-13. */
static double pdf_mass(const struct pdf_ctx *c, double a, double b)
{
    return lrt_simpson(pdf_fn, (void *)c, a, b, 1e-13);
}

/* Chi-square of N samples in `nbins` bins with edges e[0..nbins] (e[nbins] may be INFINITY,
 * whose expected mass is 1 - the rest), expected counts from integrating the density. */
static double chi_square(double sigma_tr, double r_max, const double *edges, int nbins, int n,
                         uint64_t seed)
{
    struct pdf_ctx c = {sigma_tr, r_max};
    double expected[64], count[64] = {0}, mass = 0.0;
    for (int k = 0; k < nbins; k++) {
        if (isinf(edges[k + 1]))
            expected[k] = 1.0 - mass;
        else
            expected[k] = pdf_mass(&c, edges[k], edges[k + 1]);
        mass += expected[k];
    }
    for (int i = 0; i < n; i++) {
        double r = lr_exp_radius_sample(sigma_tr, r_max, uniform01(&seed));
        int k = 0;
        while (k < nbins - 1 && r >= edges[k + 1])
            k++;
        count[k] += 1.0;
    }
    double chi2 = 0.0;
    for (int k = 0; k < nbins; k++) {
        double e = expected[k] * n;
        /* The usual validity condition of the chi-square approximation. */
        assert_true(e >= 5.0);
        chi2 += (count[k] - e) * (count[k] - e) / e;
    }
    return chi2;
}

/* Histogram of 100000 samples against the density, three regimes. If the sampler draws from
 * the density, the statistic follows chi-square with (bins - 1) degrees of freedom; the
 * thresholds are its 0.999 quantiles (df 19: 43.82, df 20: 45.31; mpmath), so with a random
 * seed each assertion would fail falsely with probability 1e-3 (3e-3 for the three). The seed
 * is fixed, so the outcome is deterministic. A sampler using the untruncated inverse CDF on
 * [0, r_max] piles the excess mass into the last bin and scores in the thousands. */
static void test_chi_square(void **state)
{
    (void)state;
    double edges[32];
    /* Truncated: sigma_tr = 2 mm^-1 on [0, 1.5] mm (e^{-3} = 5 % of the untruncated mass cut). */
    for (int k = 0; k <= 20; k++)
        edges[k] = 1.5 * k / 20.0;
    double chi2 = chi_square(2.0, 1.5, edges, 20, 100000, 42);
    if (!(chi2 < 43.82))
        fail_msg("truncated: chi2 = %g, df 19", chi2);
    /* Seed 003 Eq. 12 exactly (r_max = Inf): 20 bins of 0.3 mm then the tail [6, Inf). */
    for (int k = 0; k <= 20; k++)
        edges[k] = 0.3 * k;
    edges[21] = INFINITY;
    chi2 = chi_square(1.0, INFINITY, edges, 21, 100000, 43);
    if (!(chi2 < 45.31))
        fail_msg("untruncated: chi2 = %g, df 20", chi2);
    /* sigma_tr = 0 (albedo' = 1): uniform on [0, 3]. */
    for (int k = 0; k <= 20; k++)
        edges[k] = 3.0 * k / 20.0;
    chi2 = chi_square(0.0, 3.0, edges, 20, 100000, 44);
    if (!(chi2 < 43.82))
        fail_msg("sigma_tr = 0: chi2 = %g, df 19", chi2);
}

/* The density integrates to 1 and the sampler is its inverse CDF: for xi on a grid,
 * integral_0^{r(xi)} p = xi. Adaptive Simpson to 1e-13 absolute; the density is smooth, so the
 * assertion 1e-10 leaves three orders for the quadrature. For r_max = Inf the mass beyond
 * 60 / sigma_tr is e^{-60} = 1e-26. */
static void test_density_and_inverse(void **state)
{
    (void)state;
    const struct pdf_ctx cs[] = {{2.0, 1.5}, {1.0, INFINITY}, {0.0, 3.0}, {1e-10, 10.0},
                                 {1e3, 0.01}, {0.117517, 50.0}, {5.0, 1e3}};
    for (size_t k = 0; k < sizeof cs / sizeof cs[0]; k++) {
        const struct pdf_ctx *c = &cs[k];
        double top = isinf(c->r_max) ? 60.0 / c->sigma_tr : c->r_max;
        /* Split at a few decay lengths so the adaptive rule sees the peak. */
        double knee = c->sigma_tr > 0.0 ? fmin(top, 5.0 / c->sigma_tr) : top;
        double total = pdf_mass(c, 0.0, knee) + (knee < top ? pdf_mass(c, knee, top) : 0.0);
        if (!(fabs(total - 1.0) <= 1e-10))
            fail_msg("sigma_tr %g r_max %g: density integrates to %.15g", c->sigma_tr, c->r_max, total);
        for (int i = 0; i < 10; i++) {
            double xi = (i + 0.5) / 10.0;
            double r = lr_exp_radius_sample(c->sigma_tr, c->r_max, xi);
            assert_true(r >= 0.0 && r <= c->r_max);
            assert_near(pdf_mass(c, 0.0, r), xi, 1e-10);
        }
    }
}

/* Closed forms: the untruncated density is Eq. 11's sigma_tr e^{-sigma_tr r} exactly; the
 * truncated one renormalises by 1 - e^{-sigma_tr r_max}. Evaluated in long double with expm1l:
 * 1e-15 relative. Endpoints: xi = 0 gives r = 0, xi -> 1 stays within [0, r_max] (finite with
 * r_max = Inf: -log(2^-53) / sigma_tr = 36.7 / sigma_tr). Outside [0, r_max] the density is 0. */
static void test_closed_forms_and_ends(void **state)
{
    (void)state;
    for (int i = 0; i <= 20; i++) {
        double r = 0.25 * i;
        assert_near_rel(lr_exp_radius_pdf(1.3, INFINITY, r), (1.3 * exp(-1.3 * r)), 1e-15);
        long double ref = 2.0L * expl(-2.0L * r) / -expm1l(-2.0L * 4.0L);
        if (r <= 4.0)
            assert_near_rel(lr_exp_radius_pdf(2.0, 4.0, r), (double)ref, 1e-15);
    }
    double last = nextafter(1.0, 0.0);
    assert_true(lr_exp_radius_sample(2.0, 1.5, 0.0) == 0.0);
    assert_true(lr_exp_radius_sample(2.0, 1.5, last) <= 1.5);
    double r = lr_exp_radius_sample(1.0, INFINITY, last);
    assert_true(isfinite(r) && fabs(r - 53.0 * log(2.0)) <= 1e-12);
    assert_true(lr_exp_radius_pdf(2.0, 1.5, 1.6) == 0.0);
    assert_true(lr_exp_radius_pdf(2.0, 1.5, -1e-12) == 0.0);
    assert_true(lr_exp_radius_pdf(1.0, INFINITY, INFINITY) == 0.0);
}

/* sigma_tr -> 0 (albedo' -> 1): with truncation the density tends to uniform 1/r_max. Exactly
 * 0 and anything with sigma_tr r_max < 1e-150 use the uniform formulas (exact: r = xi r_max).
 * At sigma_tr = 1e-10, r_max = 10 the density is 1/r_max (1 + sigma_tr (r_max/2 - r)) to
 * O((sigma_tr r_max)^2) = 1e-18: compare to 1e-15 relative. */
static void test_sigma_tr_to_zero(void **state)
{
    (void)state;
    const double sig[] = {0.0, 1e-200, 1e-160};
    for (int k = 0; k < 3; k++) {
        assert_true(lr_exp_radius_sample(sig[k], 10.0, 0.375) == 3.75);
        assert_true(lr_exp_radius_pdf(sig[k], 10.0, 7.0) == 0.1);
    }
    for (int i = 0; i <= 10; i++) {
        double rr = i;
        double expect = 0.1 * (1.0 + 1e-10 * (5.0 - rr));
        assert_near_rel(lr_exp_radius_pdf(1e-10, 10.0, rr), expect, 1e-15);
        /* inverse: r(xi) = xi r_max + O(sigma_tr r_max^2) */
        double xi = i / 10.0;
        assert_near(lr_exp_radius_sample(1e-10, 10.0, xi * (1.0 - 1e-16)), 10.0 * xi, 1e-8);
    }
}

/* Bad parameters: the validator names the field; the unchecked functions return NaN instead of a
 * plausible number. */
static void test_validate(void **state)
{
    (void)state;
    lr_err e;
    struct {
        double sigma_tr, r_max;
        const char *field;
    } bad[] = {{NAN, 1.0, "sigma_tr"},       {INFINITY, 1.0, "sigma_tr"}, {-1.0, 1.0, "sigma_tr"},
               {1.0, NAN, "r_max"},          {1.0, 0.0, "r_max"},         {1.0, -2.0, "r_max"},
               {0.0, INFINITY, "r_max"}};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        lr_err_clear(&e);
        assert_int_equal(lr_exp_radius_validate(bad[k].sigma_tr, bad[k].r_max, &e), LR_EINVAL);
        if (!strstr(e.msg, bad[k].field))
            fail_msg("message '%s' does not name '%s'", e.msg, bad[k].field);
        assert_true(isnan(lr_exp_radius_sample(bad[k].sigma_tr, bad[k].r_max, 0.5)));
        assert_true(isnan(lr_exp_radius_pdf(bad[k].sigma_tr, bad[k].r_max, 0.5)));
    }
    assert_int_equal(lr_exp_radius_validate(0.0, 3.0, &e), LR_OK);
    assert_int_equal(lr_exp_radius_validate(2.0, INFINITY, &e), LR_OK);
}

/* Seed 003 Eq. 9 on a plane at normal incidence reduces to estimating integral 2 pi r R_d(r) dr
 * with r ~ p: the mean of 2 pi r R_d(r) / p(r) over N = 200000 samples (marble, red band, the
 * band's own sigma_tr, untruncated) must match the closed-form total (test_optics_dipole checks
 * that one against quadrature). Asserted within 4 standard errors estimated from the same
 * samples: false-failure probability 6e-5 for a random seed (normal approximation; the weights
 * are bounded, so the CLT applies). The observed relative standard error is ~0.2 %. */
static void test_estimator(void **state)
{
    (void)state;
    const lr_medium marble = {{0.0021, 0.0041, 0.0071}, {2.19, 2.62, 3.00}, 1.5, 0.0};
    lr_coeffs c;
    assert_int_equal(lr_coeffs_derive(&marble, &c, NULL), LR_OK);
    double total[3];
    lr_dipole_rd_total(&c, total);
    uint64_t seed = 7;
    const int n = 200000;
    for (int j = 0; j < 3; j++) {
        double sum = 0.0, sum2 = 0.0;
        for (int i = 0; i < n; i++) {
            double r = lr_exp_radius_sample(c.sigma_tr[j], INFINITY, uniform01(&seed)), rd[3];
            lr_dipole_rd(&c, r, rd);
            double w = 2.0 * M_PI * r * rd[j] / lr_exp_radius_pdf(c.sigma_tr[j], INFINITY, r);
            sum += w;
            sum2 += w * w;
        }
        double mean = sum / n, se = sqrt((sum2 / n - mean * mean) / (n - 1));
        if (!(fabs(mean - total[j]) <= 4.0 * se))
            fail_msg("band %d: estimate %.6g +- %.2g, closed form %.6g", j, mean, se, total[j]);
        assert_true(se < 0.01 * total[j]);
    }
}

/* Radical inverse known values (Halton 1964; base 2 = van der Corput): base 2 maps 1, 2, 3, 4, 5 to
 * 1/2, 1/4, 3/4, 1/8, 5/8; base 3 maps 1..5 to 1/3, 2/3, 1/9, 4/9, 7/9. Exact in binary for base
 * 2; 1 ulp for base 3. UINT_MAX in base 2 is 1 - 2^-32 exactly. */
static void test_halton(void **state)
{
    (void)state;
    const double b2[] = {0.0, 0.5, 0.25, 0.75, 0.125, 0.625};
    const double b3[] = {0.0, 1.0 / 3, 2.0 / 3, 1.0 / 9, 4.0 / 9, 7.0 / 9};
    for (unsigned i = 0; i < 6; i++) {
        assert_true(lr_halton(i, 2) == b2[i]);
        assert_near(lr_halton(i, 3), b3[i], 2e-16);
    }
    assert_true(lr_halton(1, 5) == 0.2);
    assert_true(lr_halton(UINT_MAX, 2) == 1.0 - 0x1.0p-32);
    assert_true(isnan(lr_halton(3, 1)) && isnan(lr_halton(3, 0)));
}

/* Sphere directions: unit length (1e-15), index 0 the pole. The first 4096 = 2^12 base-2 values
 * are exactly {k / 4096}, so the mean of z = 1 - 2 h2 is exactly 1/4096 (summation roundings
 * ~1e-13). The x, y means have no closed form; quasi-Monte Carlo error for these smooth
 * integrands is O(log^2 N / N) = 0.017 at N = 4096 (Koksma-Hlawka with a constant of order 1):
 * assert 0.02 (observed 3.4e-4). */
static void test_halton_sphere(void **state)
{
    (void)state;
    lr_vec3 p = lr_halton_sphere(0);
    assert_true(p.x == 0.0 && p.y == 0.0 && p.z == 1.0);
    double mx = 0.0, my = 0.0, mz = 0.0;
    for (unsigned i = 0; i < 4096; i++) {
        lr_vec3 d = lr_halton_sphere(i);
        assert_near(lr_v3_len(d), 1.0, 1e-15);
        mx += d.x;
        my += d.y;
        mz += d.z;
    }
    mx /= 4096.0;
    my /= 4096.0;
    mz /= 4096.0;
    assert_near(mz, 1.0 / 4096.0, 1e-13);
    assert_true(fabs(mx) < 0.02 && fabs(my) < 0.02);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_chi_square),
        cmocka_unit_test(test_density_and_inverse),
        cmocka_unit_test(test_closed_forms_and_ends),
        cmocka_unit_test(test_sigma_tr_to_zero),
        cmocka_unit_test(test_validate),
        cmocka_unit_test(test_estimator),
        cmocka_unit_test(test_halton),
        cmocka_unit_test(test_halton_sphere),
    };
    return cmocka_run_group_tests_name("optics_sampling", tests, NULL, NULL);
}
