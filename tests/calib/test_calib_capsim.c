/* The capture simulator's sensor model (calib/capture_sim.h): the noise-free chain inverts
 * through the rig's own linearisation (lr_rig_camera_to_linear) to the radiance times
 * gain * t * V; noise statistics match shot + read noise; vignetting; determinism per seed;
 * bad parameters are refused naming the field. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calib/capture_sim.h"
#include "calib/compare.h"
#include "calib/fit_captures.h"
#include "calib/rig.h"
#include "tests/support/fs.h"
#include "tests/support/near.h"

/* A w x h image of one colour. */
static lr_image flat(int w, int h, float r, float g, float b)
{
    lr_image img;
    lr_err e = {0};
    assert_int_equal(lr_image_alloc(&img, w, h, &e), LR_OK);
    for (int i = 0; i < w * h; i++) {
        img.rgb[3 * i] = r;
        img.rgb[3 * i + 1] = g;
        img.rgb[3 * i + 2] = b;
    }
    return img;
}

/* Noise-free, 8-bit, through a fitted-style response (the gamma curve as lr_camresp) and a
 * colour matrix: the rig's linearisation gives back gain * t * L. The only error is 8-bit
 * quantisation, half a step: |dX| <= 0.5 * max slope of the curve between neighbours. */
static void test_chain_inverts_through_rig(void **state)
{
    (void)state;
    lr_rig_calib *rig = calloc(1, sizeof *rig);
    assert_non_null(rig);
    lr_camresp_gamma(&rig->camresp, 2.2);
    rig->has_camresp = true;
    const double M[9] = {1.2, -0.1, -0.1, -0.05, 1.1, -0.05, 0.0, -0.2, 1.2};
    memcpy(rig->color.m, M, sizeof M);
    rig->has_color = true;
    lr_sensor s = {.exposure_s = 0.5, .gain = 3.0, .response = &rig->camresp,
                   .color = &rig->color};
    lr_image L = flat(8, 8, 0, 0, 0);
    for (int i = 0; i < 64; i++)
        for (int c = 0; c < 3; c++)
            L.rgb[3 * i + c] = (float)(0.05 + 0.012 * i + 0.03 * c); /* X from 0.07 to 1.4 */
    lr_img cap;
    lr_err e = {0};
    assert_int_equal(lr_sensor_capture(&s, &L, &cap, &e), LR_OK);
    assert_int_equal(cap.depth, 1);
    /* Largest step of the curve over the range used, times |M| row sum (the matrix mixes
     * the three channels' quantisation errors). */
    double step = 0;
    for (int z = 1; z < 256; z++)
        step = fmax(step, rig->camresp.curve[0][z] - rig->camresp.curve[0][z - 1]);
    for (int i = 0; i < 64; i++) {
        double lin[3];
        lr_rig_camera_to_linear(rig, (const uint8_t *)cap.px + 3 * i, lin);
        for (int c = 0; c < 3; c++) {
            double want = 1.5 * L.rgb[3 * i + c];
            double rowsum = fabs(M[3 * c]) + fabs(M[3 * c + 1]) + fabs(M[3 * c + 2]);
            assert_near(lin[c], want, 0.5 * step * rowsum + 1e-9);
        }
    }
    lr_img_free(&cap);
    lr_image_free(&L);
    free(rig);
}

/* The analytic gamma path (no response given) and the lr_camresp_gamma table agree, and
 * 16-bit output resolves what 8 bits cannot. */
static void test_gamma_and_16bit(void **state)
{
    (void)state;
    lr_sensor s = {.gamma = 2.2, .bits = 16};
    lr_camresp table;
    lr_camresp_gamma(&table, 2.2);
    for (double X = 0.01; X < 4.0; X *= 1.37) {
        double z = lr_sensor_encode(&s, 1, X);
        /* Inverting through the table (linear between entries) is exact at the nodes and
         * off by at most the curvature between them: relative 2 % is far above that for
         * z > 10 and far below any value a wrong exponent would give. */
        if (z > 10)
            assert_near_rel(lr_camresp_linear(&table, 1, z), X, 0.02);
    }
    lr_image L = flat(4, 4, 0.2f, 0.2f, 0.2f);
    lr_img cap;
    lr_err e = {0};
    assert_int_equal(lr_sensor_capture(&s, &L, &cap, &e), LR_OK);
    assert_int_equal(cap.depth, 2);
    double z = lr_sensor_encode(&s, 0, 0.2);
    assert_near(((uint16_t *)cap.px)[0], z * 65535.0 / 255.0, 0.5 + 1e-9);
    lr_img_free(&cap);
    lr_image_free(&L);
}

/* Linear response (gamma 1), flat field. z = 255 X / X_sat and X = el / FW * X_sat, so
 * z = 255 el / FW and
 *   var(z) = (255 / FW)^2 (e + read^2) + 1/12     (shot + read noise, then rounding).
 * 40000 samples estimate a standard deviation to 1/sqrt(2 * 40000) = 0.35 %; 3 % is ~8
 * sigma, and a missing noise term (read or shot) would change it by > 10 %. */
static void test_noise_statistics(void **state)
{
    (void)state;
    const int W = 200, H = 200;
    lr_sensor s = {.gamma = 1.0, .full_well_e = 2000, .read_noise_e = 12, .seed = 7, .bits = 8};
    double sat = lr_sensor_saturation(&s, 0);
    double X = 0.4 * sat; /* 40 % of full scale: 800 electrons */
    lr_image L = flat(W, H, (float)X, (float)X, (float)X);
    lr_img cap;
    lr_err e = {0};
    assert_int_equal(lr_sensor_capture(&s, &L, &cap, &e), LR_OK);
    double sum = 0, sum2 = 0;
    int n = W * H;
    for (int i = 0; i < n; i++) {
        double z = ((uint8_t *)cap.px)[3 * i + 1];
        sum += z;
        sum2 += z * z;
    }
    double mean = sum / n, var = sum2 / n - mean * mean;
    double el = 0.4 * 2000;
    double want_var = (255.0 / 2000) * (255.0 / 2000) * (el + 12.0 * 12.0) + 1.0 / 12.0;
    assert_near(mean, 0.4 * 255, 0.05);
    assert_near_rel(sqrt(var), sqrt(want_var), 0.03);

    /* Same seed: identical capture; another seed: a different one. */
    lr_img again, other;
    assert_int_equal(lr_sensor_capture(&s, &L, &again, &e), LR_OK);
    assert_memory_equal(cap.px, again.px, (size_t)n * 3);
    s.seed = 8;
    assert_int_equal(lr_sensor_capture(&s, &L, &other, &e), LR_OK);
    assert_true(memcmp(cap.px, other.px, (size_t)n * 3) != 0);
    lr_img_free(&cap);
    lr_img_free(&again);
    lr_img_free(&other);
    lr_image_free(&L);
}

/* Low signal: exact Poisson, mean = variance = lambda (3 electrons), read noise off. With
 * 40000 samples the mean is known to sqrt(3/40000) = 0.009 and the variance to
 * ~ sqrt((lambda + 2 lambda^2)/n) = 0.023; tolerances 0.05 and 0.12 are > 5 sigma. A 16-bit
 * linear sensor with FW 65535 e: one electron is one digital step. */
static void test_poisson_low_light(void **state)
{
    (void)state;
    const int W = 200, H = 200;
    lr_sensor s = {.gamma = 1.0, .full_well_e = 65535, .seed = 3, .bits = 16};
    double sat = lr_sensor_saturation(&s, 0);
    double X = 3.0 / 65535 * sat;
    lr_image L = flat(W, H, (float)X, (float)X, (float)X);
    lr_img cap;
    lr_err e = {0};
    assert_int_equal(lr_sensor_capture(&s, &L, &cap, &e), LR_OK);
    double sum = 0, sum2 = 0;
    int n = W * H;
    for (int i = 0; i < n; i++) {
        double z = ((uint16_t *)cap.px)[3 * i];
        sum += z;
        sum2 += z * z;
    }
    double mean = sum / n, var = sum2 / n - mean * mean;
    assert_near(mean, 3.0, 0.05);
    assert_near(var, 3.0, 0.12);
    lr_img_free(&cap);
    lr_image_free(&L);
}

static void test_vignetting(void **state)
{
    (void)state;
    lr_sensor s = {.vignette = LR_VIGNETTE_COS4, .focal_px = 100};
    /* At r = f from the centre theta = 45 deg: cos^4 = 1/4. */
    assert_near(lr_sensor_vignette(&s, 101, 101, 50, 50), 1.0, 1e-12);
    assert_near(lr_sensor_vignette(&s, 101, 101, 150, 50), 0.25, 1e-12);
    s = (lr_sensor){.vignette = LR_VIGNETTE_POLY, .vignette_poly = {-0.3, 0.05, 0},
                    .cx = 10, .cy = 10};
    /* Corner of a 20 x 20 image measured from (10, 10): rho = |(10,10)| / |(10,10)| = 1. */
    assert_near(lr_sensor_vignette(&s, 20, 20, 20, 20), 1 - 0.3 + 0.05, 1e-12);
    /* Through the whole chain: exposure at the corner is V times the centre's. */
    lr_image L = flat(20, 20, 0.5f, 0.5f, 0.5f);
    double *X = malloc(20 * 20 * 3 * sizeof *X);
    lr_err e = {0};
    assert_int_equal(lr_sensor_exposure(&s, &L, X, &e), LR_OK);
    assert_near(X[3 * (19 * 20 + 19)] / X[3 * (10 * 20 + 10)],
                lr_sensor_vignette(&s, 20, 20, 19, 19), 1e-12);
    free(X);
    lr_image_free(&L);
}

static void test_bad_parameters(void **state)
{
    (void)state;
    lr_err e = {0};
    lr_sensor s = {.gain = -1};
    assert_int_equal(lr_sensor_check(&s, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "sensor.gain"));
    s = (lr_sensor){.vignette = LR_VIGNETTE_COS4};
    assert_int_equal(lr_sensor_check(&s, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "sensor.focal_px"));
    s = (lr_sensor){.read_noise_e = 3};
    assert_int_equal(lr_sensor_check(&s, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "full_well_e"));
    s = (lr_sensor){.bits = 12};
    assert_int_equal(lr_sensor_check(&s, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "sensor.bits"));
    lr_colormatrix singular = {{1, 2, 3, 2, 4, 6, 0, 0, 1}, 0, 0, 0, ""};
    s = (lr_sensor){.color = &singular};
    assert_int_equal(lr_sensor_check(&s, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "singular"));
    lr_image L = flat(2, 2, 0.1f, 0.1f, 0.1f);
    lr_img cap;
    assert_int_equal(lr_sensor_capture(&s, &L, &cap, &e), LR_EINVAL);
    assert_null(cap.px);
    lr_image_free(&L);
}

/* ONE rule for 8-bit captures without camera_response.json (issue 10 item 4): a noise-free
 * 8-bit PNG from the simulator as lamprig-capsim makes it (the rig's response table,
 * lr_rig_camera_response) reads back, from a calibration folder without a response file,
 * to the same values through lamprig fit's reader (lr_fit_load_captures), lamprig compare's
 * (lr_compare_linearise) and the per-pixel conversion calib albedo uses
 * (lr_rig_camera_to_linear), and those values are the radiance x gain x t up to 8-bit
 * quantisation: the simulator inverts the table (linear between codes) and rounds to the
 * nearest code z, so X is off by at most half the curve's step on the side it was rounded
 * from: relative to X, 0.5 a with a = (1 + 1/z)^g - 1 (rounded down), or 0.5 b / (1 - 0.5 b)
 * with b = 1 - (1 - 1/z)^g (rounded up; the larger one for g < 2), 2.8 % at z = 40, g = 2.2.
 * The old fit read such captures as value / 255: off by a factor 1.2-4.5 across this range.
 * Also with --gamma 1.8, and --gamma refused beside a measured response. */
static void test_one_rule_without_response(void **state)
{
    (void)state;
    char *dir = lr_test_tmpdir();
    lr_rig_calib *rig = calloc(1, sizeof *rig);
    lr_err e = {0};
    assert_int_equal(lr_rig_calib_load(dir, rig, &e), LR_OK);
    assert_false(rig->has_camresp);
    const int w = 16, h = 4;
    const double gain = 2.5, t = 1.0;
    for (int pass = 0; pass < 2; pass++) {
        double g = pass ? 1.8 : LR_CAMRESP_DEFAULT_GAMMA;
        if (pass)
            assert_int_equal(lr_rig_set_gamma(rig, 1.8, &e), LR_OK);
        lr_camresp table;
        lr_rig_camera_response(rig, &table);
        /* the table is the gamma curve named, normalised to 1 at value 128 */
        assert_near(table.curve[1][128], 1.0, 1e-12);
        assert_near_rel(table.curve[0][255], pow(255.0 / 128.0, g), 1e-12);
        lr_sensor s = {.exposure_s = t, .gain = gain, .response = &table};
        lr_image L = flat(w, h, 0, 0, 0);
        for (int i = 0; i < w * h; i++)
            for (int c = 0; c < 3; c++) /* X = gain L from 0.06 to 3.1: value ~36 to 240,
                                          * below the clipping fit leaves out (>= 250) */
                L.rgb[3 * i + c] = (float)(0.024 * pow(1.064, i + 0.3 * c));
        lr_img cap;
        assert_int_equal(lr_sensor_capture(&s, &L, &cap, &e), LR_OK);
        char *png = lr_test_path(dir, "shot.png");
        assert_int_equal(lr_img_write(png, &cap, &e), LR_OK);
        lr_image fit, cmp;
        const char *paths[1] = {png};
        if (lr_fit_load_captures(paths, NULL, 1, rig, w, h, gain, &fit, &e))
            fail_msg("fit reader: %s", e.msg);
        lr_img back;
        assert_int_equal(lr_img_read(png, LR_IMG_AS_IS, &back, &e), LR_OK);
        if (lr_compare_linearise(rig, &back, &t, 1, gain, &cmp, &e))
            fail_msg("compare reader: %s", e.msg);
        const uint8_t *px = back.px;
        int checked = 0;
        for (int i = 0; i < w * h; i++) {
            double lin[3];
            lr_rig_camera_to_linear(rig, px + 3 * i, lin);
            for (int c = 0; c < 3; c++) {
                int z = px[3 * i + c];
                /* the same curve, three ways: equal to float storage */
                assert_near_rel(fit.rgb[3 * i + c], lin[c] / gain, 1e-6);
                assert_near_rel(cmp.rgb[3 * i + c], lin[c] / gain, 1e-6);
                assert_near_rel(lin[c], table.curve[c][z], 1e-12);
                if (z < 40 || z > 250)
                    continue;
                double a = pow(1.0 + 1.0 / z, g) - 1, b = 1 - pow(1.0 - 1.0 / z, g);
                assert_near_rel(fit.rgb[3 * i + c], L.rgb[3 * i + c],
                                fmax(0.5 * a, 0.5 * b / (1 - 0.5 * b)) + 1e-6);
                checked++;
            }
        }
        assert_true(checked > 100);
        lr_image_free(&fit);
        lr_image_free(&cmp);
        lr_img_free(&back);
        lr_img_free(&cap);
        lr_image_free(&L);
        free(png);
    }
    /* A measured response is the rule where there is one: --gamma beside it is refused. */
    rig->has_camresp = true;
    lr_camresp_gamma(&rig->camresp, 2.0);
    assert_int_equal(lr_rig_set_gamma(rig, 1.8, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "camera_response.json"));
    assert_int_equal(lr_rig_set_gamma(rig, 0.01, &e), LR_EINVAL);
    free(rig);
    lr_test_rmtree(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_chain_inverts_through_rig),
        cmocka_unit_test(test_gamma_and_16bit),
        cmocka_unit_test(test_noise_statistics),
        cmocka_unit_test(test_poisson_low_light),
        cmocka_unit_test(test_vignetting),
        cmocka_unit_test(test_bad_parameters),
        cmocka_unit_test(test_one_rule_without_response),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
