/* render/photometry: the CIE 1931 table, Planckian colours against the CIE illuminants, the
 * renderer's RGB primaries and the photometric scale (photometry.h). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "render/photometry/photometry.h"
#include "tests/support/near.h"

static void planck_xy(double t_k, double *x, double *y)
{
    double xyz[3];
    lr_planck_xyz(t_k, xyz);
    double s = xyz[0] + xyz[1] + xyz[2];
    *x = xyz[0] / s;
    *y = xyz[1] / s;
}

/* The CIE publishes the column sums of its 5 nm table (21.371524, 21.371327, 21.371540); a
 * sum of 81 six-decimal numbers is itself exact at six decimals, so any mistyped entry moves
 * it by >= 1e-6: tolerance 4e-7 (double rounding of the sum is ~1e-14). */
static void test_table_sums(void **state)
{
    (void)state;
    double s[3] = {0, 0, 0};
    for (int i = 0; i < LR_CIE_N; i++)
        for (int c = 0; c < 3; c++)
            s[c] += lr_cie1931_cmf[i][c];
    assert_near(s[0], 21.371524, 4e-7);
    assert_near(s[1], 21.371327, 4e-7);
    assert_near(s[2], 21.371540, 4e-7);
    /* y-bar is 1 at 555 nm (row 35), where K_m is defined. */
    assert_near(lr_cie1931_cmf[35][1], 1.0, 0.0);
}

/* The matrix is built from the primaries, so the sRGB standard's 4-decimal luminance row
 * (0.2126, 0.7152, 0.0722) must come out within its rounding, 5e-5; D65 (Y = 1) is RGB 1,1,1
 * up to the double rounding of two 3x3 inverses (~1e-15; 1e-12). */
static void test_primaries(void **state)
{
    (void)state;
    const double r[3] = {1, 0, 0}, g[3] = {0, 1, 0}, b[3] = {0, 0, 1};
    assert_near(lr_rgb_luminance(r), 0.2126, 5e-5);
    assert_near(lr_rgb_luminance(g), 0.7152, 5e-5);
    assert_near(lr_rgb_luminance(b), 0.0722, 5e-5);
    double w[3] = {0.3127 / 0.3290, 1.0, (1.0 - 0.3127 - 0.3290) / 0.3290}, rgb[3];
    lr_xyz_to_rgb(w, rgb);
    for (int c = 0; c < 3; c++)
        assert_near(rgb[c], 1.0, 1e-12);
}

/* Illuminant A is Planck's law at 2848 K with c2 = 1.435e-2, i.e. 2848 * 1.4388 / 1.435 K at
 * our c2; CIE 015:2004 gives its chromaticity as x 0.44757, y 0.40745. Tolerance: the
 * published five decimals (5e-6) plus what the 5 nm summation and the table's end at 780 nm
 * (the CIE's 1 nm table runs to 830 nm) change: the x-bar entries beyond 780 nm sum to ~1e-4
 * against a column sum of 21, weighted by A's spectrum (about twice as strong at 800 as at
 * 600 nm) ~1e-5 of X, dx = x (1 - x) 1e-5 ~ 3e-6; the summation error of a smooth spectrum
 * is of the same order. 5e-6 + 3e-6 + 3e-6 -> 1.2e-5, 2e-5 allowed.
 * At the nominal 2856 K against the four-decimal values (0.4476, 0.4074): the rounding 5e-5,
 * plus 0.46 K of nominal offset at |dx/dT| ~ 7.5e-5/K (3.5e-5; dy/dT is ~10x smaller), plus
 * the 2e-5 above: 1.05e-4 in x, 7e-5 in y. */
static void test_illuminant_a(void **state)
{
    (void)state;
    double x, y;
    planck_xy(2848.0 * 1.4388 / 1.435, &x, &y);
    assert_near(x, 0.44757, 2e-5);
    assert_near(y, 0.40745, 2e-5);
    planck_xy(2856.0, &x, &y);
    assert_near(x, 0.4476, 1.05e-4);
    assert_near(y, 0.4074, 7e-5);
}

/* D65 is a daylight phase, not a Planckian radiator: it lies above the locus (Duv 0.0032), so
 * the 6504 K radiator's xy (0.3135, 0.3236) is not D65's (0.3127, 0.3290) -- the test is
 * the one that defines D65's 6504 K: the Planckian colour nearest to D65 in CIE 1960 uv (its
 * correlated colour temperature) is 6504 K, at distance Duv = 0.0032. Tolerance on the CCT:
 * the locus moves 8.7e-6 in uv per K there; D65's five-decimal xy (0.31271, 0.32902) is
 * good to 5e-6 (3.5e-6 in uv: 0.4 K), the 5 nm table's chromaticity to ~1e-5 (as for A:
 * 7e-6 in uv, 0.8 K), the published 6504 K to 0.5 K: 1.7 K, 2 K allowed. Duv: 0.0032 is
 * rounded to 5e-5, plus the table's 1e-5. */
static double uv_dist(double t_k, double u0, double v0)
{
    double x, y, u, v;
    planck_xy(t_k, &x, &y);
    lr_xy_to_uv1960(x, y, &u, &v);
    return hypot(u - u0, v - v0);
}

static void test_d65_cct(void **state)
{
    (void)state;
    double u0, v0;
    lr_xy_to_uv1960(0.31271, 0.32902, &u0, &v0);
    /* Golden-section search on [5000, 8000] K (the distance is unimodal there). */
    double a = 5000.0, b = 8000.0;
    while (b - a > 0.01) {
        double m1 = a + 0.381966 * (b - a), m2 = a + 0.618034 * (b - a);
        if (uv_dist(m1, u0, v0) < uv_dist(m2, u0, v0))
            b = m2;
        else
            a = m1;
    }
    assert_near(0.5 * (a + b), 6504.0, 2.0);
    assert_near(uv_dist(0.5 * (a + b), u0, v0), 0.0032, 6e-5);
    /* And so the 6504 K radiator itself is off D65 by ~0.005 in y: not within any tolerance
     * of the tabulation, which is why the CCT is the comparison. */
    double x, y;
    planck_xy(6504.0, &x, &y);
    assert_true(fabs(y - 0.3290) > 0.004);
}

/* lr_cct_color: K_m Y(rgb) is the radiator's visible efficacy K(T) (so intensity in W/sr is
 * the visible watts), K(T) < K_m (y-bar <= 1, equality only for 555 nm light), and the
 * chromaticity is the radiator's (no band clipped at 2700 K: xyz round trip to 1e-9). */
static void test_cct_color(void **state)
{
    (void)state;
    const double ts[] = {1000, 1900, 2700, 6504, 20000};
    for (int i = 0; i < 5; i++) {
        double rgb[3];
        lr_cct_color(ts[i], rgb);
        double k = lr_planck_efficacy(ts[i]);
        assert_true(k > 0.0 && k < LR_KM_LM_PER_W);
        assert_near_rel(LR_KM_LM_PER_W * lr_rgb_luminance(rgb), k, 1e-12);
        for (int c = 0; c < 3; c++)
            assert_true(rgb[c] >= 0.0);
    }
    double rgb[3], xyz[3], ref[3];
    lr_cct_color(2700.0, rgb);
    lr_planck_xyz(2700.0, ref);
    double y = lr_rgb_luminance(rgb);
    /* Unclipped at 2700 K, so the colour is the radiator's RGB up to the scale. */
    lr_xyz_to_rgb(ref, xyz);
    for (int c = 0; c < 3; c++)
        assert_near_rel(rgb[c] / y, xyz[c], 1e-9);
    /* An equal-energy spectrum over the table has efficacy K_m sum(y-bar) / 81 = 180.2 lm/W;
     * the 6504 K radiator peaks at 446 nm (Wien) and falls off slowly to the red, so it has
     * more of its power mid-table than at the ends (ratio of B at 555 to the mean B over
     * 380..780: > 1), hence a higher efficacy; a 1000 K one (almost all red) a far lower. */
    assert_true(lr_planck_efficacy(6504.0) > LR_KM_LM_PER_W * 21.371327 / 81.0);
    assert_true(lr_planck_efficacy(1000.0) < 0.1 * LR_KM_LM_PER_W * 21.371327 / 81.0);
}

/* EV100: a white surface at the meter's luminance L = 12.5 2^EV / 100 cd/m^2 has radiance
 * L / (683 lm/W x 1e6 mm^2/m^2) W/(mm^2 sr) (Y(1,1,1) = 1) and must come out at 0.18; one EV
 * more halves the multiplier; the inverse returns the EV. All double arithmetic: 1e-12. */
static void test_exposure_ev(void **state)
{
    (void)state;
    for (double ev = -4.0; ev <= 16.0; ev += 2.5) {
        double l = 12.5 * pow(2.0, ev) / 100.0;
        double radiance = l / (LR_KM_LM_PER_W * 1e6);
        assert_near_rel(lr_ev_to_exposure(ev) * radiance, 0.18, 1e-12);
        assert_near_rel(lr_ev_to_exposure(ev + 1.0), 0.5 * lr_ev_to_exposure(ev), 1e-12);
        assert_near(lr_exposure_to_ev(lr_ev_to_exposure(ev)), ev, 1e-12);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_table_sums),     cmocka_unit_test(test_primaries),
        cmocka_unit_test(test_illuminant_a),   cmocka_unit_test(test_d65_cct),
        cmocka_unit_test(test_cct_color),      cmocka_unit_test(test_exposure_ev),
    };
    return cmocka_run_group_tests_name("photometry", tests, NULL, NULL);
}
