/* Physical reference, plane-parallel validation: the published slab benchmarks and closed
 * forms, by counting photons on the renderer's transport code (lr_ref_slab_rt runs
 * lr_ref_photon_trace, which runs the same flight, Fresnel boundary and HG steps as the
 * camera paths).
 *
 * Tolerances. Each estimate comes with its Monte Carlo standard error SE (sample standard
 * deviation of the per-photon tallies / sqrt(N)). A test asserts |estimate - truth| <= 4 SE
 * (+ the rounding of the published digits): for a normal error a false failure has
 * probability 6.3e-5 per assertion (two-sided 4 sigma). Each test also asserts that SE is
 * below a bound, so a noisy (or broken) estimator cannot pass by a wide error bar. Seeds
 * are fixed, so a run is reproducible; the probabilities are over the choice of seed.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "render/reference/ref_priv.h"

#define K_SIGMA 4.0

static void assert_within(const char *what, lr_ref_estimate x, double truth, double rounding,
                          double max_se)
{
    double dev = fabs(x.value - truth);
    printf("  %-44s %.5f +- %.5f  (truth %.5f, %+.2f SE)\n", what, x.value, x.se, truth,
           x.se > 0.0 ? (x.value - truth) / x.se : 0.0);
    assert_true(x.se > 0.0 && x.se <= max_se);
    assert_true(dev <= K_SIGMA * x.se + rounding);
}

/* Giovanelli 1955: semi-infinite medium, albedo 0.9, isotropic scattering, n = 1.5 (outside
 * 1), collimated normal incidence: total reflectance 0.2600, the specular reflection of the
 * first surface included. 10^6 photons: SE about 3.3e-4 (measured), so the tolerance is
 * 4 SE + 5e-5 (published to 4 digits) = 0.0014, about 0.5% of R. */
static void test_giovanelli_semi_infinite(void **state)
{
    (void)state;
    lr_ref_slab_problem p = {.albedo = 0.9, .g = 0.0, .eta = 1.5, .optical_depth = INFINITY,
                             .photons = 1000000, .seed = 11};
    lr_ref_slab_result r;
    lr_err e = {0};
    assert_int_equal(lr_ref_slab_rt(&p, &r, &e), LR_OK);
    assert_within("R total (Giovanelli 0.2600)", r.r_total, 0.2600, 5e-5, 5e-4);
    /* The specular part alone is the normal-incidence Fresnel reflectance
     * ((n - 1) / (n + 1))^2 = 0.04 exactly; its tally is binomial (SE 2e-4). */
    assert_within("R specular (Fresnel 0.04)", r.r_specular, 0.04, 0.0, 3e-4);
    /* Nothing is transmitted by a half-space, and the tallies add up (each photon is
     * reflected, transmitted or absorbed). */
    assert_true(r.t_total.value == 0.0);
    assert_true(fabs(r.r_total.value + r.t_total.value + r.absorbed.value - 1.0) < 1e-9);
    assert_int_equal(r.stats.truncated, 0);
    assert_int_equal(r.stats.medium_mismatch, 0);
}

/* van de Hulst 1980 (Multiple Light Scattering, vol. 2), as used to validate MCML (Wang,
 * Jacques, Zheng 1995): slab of optical thickness 2, albedo 0.9, Henyey-Greenstein g = 0.75,
 * index-matched (n = 1), normal incidence: R = 0.09739, T = 0.66096. T is the total
 * transmittance, the unscattered exp(-2) = 0.13534 included: our unscattered tally is
 * asserted to be that value, and T only matches with it added (without it T would be 0.5256,
 * hundreds of SE away). 10^6 photons: SE(R) about 2.3e-4, SE(T) about 3.3e-4. */
static void test_van_de_hulst_slab(void **state)
{
    (void)state;
    lr_ref_slab_problem p = {.albedo = 0.9, .g = 0.75, .eta = 1.0, .optical_depth = 2.0,
                             .photons = 1000000, .seed = 12};
    lr_ref_slab_result r;
    lr_err e = {0};
    assert_int_equal(lr_ref_slab_rt(&p, &r, &e), LR_OK);
    assert_within("R (van de Hulst 0.09739)", r.r_total, 0.09739, 5e-6, 3.5e-4);
    assert_within("T total (van de Hulst 0.66096)", r.t_total, 0.66096, 5e-6, 5e-4);
    assert_within("T unscattered (exp(-2))", r.t_unscattered, exp(-2.0), 0.0, 5e-4);
    /* Index-matched: no specular reflection at all. */
    assert_true(r.r_specular.value == 0.0);
}

/* A pure absorber (albedo 0) between two Fresnel interfaces: the photon bounces specularly
 * between the faces, and the series of internal reflections sums to closed forms. With
 * R0 = ((n-1)/(n+1))^2 at normal incidence and a = exp(-tau):
 *   T = (1 - R0)^2 a / (1 - R0^2 a^2),   R = R0 + (1 - R0)^2 R0 a^2 / (1 - R0^2 a^2).
 * Tallies are binomial; 10^6 photons give SE <= 5e-4. */
static void test_absorbing_slab_closed_form(void **state)
{
    (void)state;
    double n = 1.5, tau = 0.5, R0 = (n - 1) * (n - 1) / ((n + 1) * (n + 1)), a = exp(-tau);
    double T = (1 - R0) * (1 - R0) * a / (1 - R0 * R0 * a * a);
    double R = R0 + (1 - R0) * (1 - R0) * R0 * a * a / (1 - R0 * R0 * a * a);
    lr_ref_slab_problem p = {.albedo = 0.0, .eta = n, .optical_depth = tau, .photons = 1000000,
                             .seed = 13};
    lr_ref_slab_result r;
    lr_err e = {0};
    assert_int_equal(lr_ref_slab_rt(&p, &r, &e), LR_OK);
    assert_within("T (closed form)", r.t_total, T, 0.0, 6e-4);
    assert_within("R (closed form)", r.r_total, R, 0.0, 6e-4);
    assert_true(r.r_diffuse.value == 0.0); /* nothing scatters */
}

/* The result depends on the seed only: one thread and two threads give identical bits
 * (batches have their own streams and are summed in order). */
static void test_slab_independent_of_threads(void **state)
{
    (void)state;
    lr_ref_slab_problem p = {.albedo = 0.9, .g = 0.5, .eta = 1.3, .optical_depth = 1.0,
                             .photons = 20000, .seed = 5, .threads = 1};
    lr_ref_slab_result a, b;
    assert_int_equal(lr_ref_slab_rt(&p, &a, NULL), LR_OK);
    p.threads = 2;
    assert_int_equal(lr_ref_slab_rt(&p, &b, NULL), LR_OK);
    assert_memory_equal(&a.r_total, &b.r_total, sizeof a.r_total);
    assert_memory_equal(&a.t_total, &b.t_total, sizeof a.t_total);
    p.seed = 6; /* and the seed does matter */
    assert_int_equal(lr_ref_slab_rt(&p, &b, NULL), LR_OK);
    assert_true(a.r_total.value != b.r_total.value);
}

/* The HG sampler draws cos theta exactly from Henyey-Greenstein: its first two moments are
 * g and (1 + 2 g^2) / 3 (the Legendre coefficients g^l of HG: <P_2(cos)> = g^2). 10^6 draws;
 * SE from the sample variance; 4 SE. Directions stay unit. */
static void test_hg_sampling_moments(void **state)
{
    (void)state;
    const double gs[] = {-0.5, 0.0, 0.3, 0.9};
    lr_ref_rng rng;
    lr_ref_rng_seed(&rng, 77, 0);
    lr_vec3 d = lr_v3_normalize(lr_v3(0.3, -0.4, 0.8));
    for (size_t k = 0; k < sizeof gs / sizeof gs[0]; k++) {
        double g = gs[k], s1 = 0, s2 = 0, q1 = 0, q2 = 0;
        const int N = 1000000;
        for (int i = 0; i < N; i++) {
            double u1 = lr_ref_rng_uniform(&rng), u2 = lr_ref_rng_uniform(&rng);
            lr_vec3 w = lr_ref_hg_sample(g, d, u1, u2);
            assert_true(fabs(lr_v3_len(w) - 1.0) < 1e-12);
            double c = lr_v3_dot(w, d), c2 = c * c;
            s1 += c;
            q1 += c * c;
            s2 += c2;
            q2 += c2 * c2;
        }
        double m1 = s1 / N, m2 = s2 / N;
        double se1 = sqrt((q1 / N - m1 * m1) / N), se2 = sqrt((q2 / N - m2 * m2) / N);
        assert_true(fabs(m1 - g) <= K_SIGMA * se1);
        assert_true(fabs(m2 - (1.0 + 2.0 * g * g) / 3.0) <= K_SIGMA * se2);
    }
    /* The density integrates to one: midpoint rule over cos theta, 2 pi int p dcos. */
    for (size_t k = 0; k < sizeof gs / sizeof gs[0]; k++) {
        double sum = 0.0;
        const int M = 1000000;
        for (int i = 0; i < M; i++)
            sum += lr_ref_hg_eval(gs[k], -1.0 + (i + 0.5) * 2.0 / M) * 2.0 / M;
        assert_true(fabs(2.0 * LR_REF_PI * sum - 1.0) < 1e-6);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_giovanelli_semi_infinite),
        cmocka_unit_test(test_van_de_hulst_slab),
        cmocka_unit_test(test_absorbing_slab_closed_form),
        cmocka_unit_test(test_slab_independent_of_threads),
        cmocka_unit_test(test_hg_sampling_moments),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
