/* A light's photometric profile (render/photometry/profile.h, render/scene "profile"): the
 * resampled table against the file, the flux a profiled light states, its shape in the
 * light's frame and under rotation, an area light with a Lambertian profile against the plain
 * one, the sampler the physical reference emits by, and the loader's refusals. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "render/base/rng.h"
#include "render/photometry/photometry.h"
#include "render/photometry/profile.h"
#include "render/scene/scene.h"
#include "tests/support/near.h"

#define EX LR_SOURCE_CONFIGS "/photometry/"

static const char *const examples[] = {"led_bulb_2700k.ies", "led_spot_3000k.ies",
                                       "led_strip_4000k.ldt"};

static void load_profile(const char *name, lr_light_profile *p, lr_luminaire *lum)
{
    char path[512];
    snprintf(path, sizeof path, EX "%s", name);
    lr_err e = {0};
    if (lr_light_profile_load(path, p, &e) || (lum && lr_luminaire_load(path, lum, &e)))
        fail_msg("%s", e.msg);
}

/* The table's flux, max_cd * omega, against the file's stated lumens. The examples'
 * distributions are exact (configs/photometry/README.md) and the grid's bilinear interpolant
 * of a smooth f errs by at most h^2/8 max|f''| per axis: with h = 2.5 degrees = 0.044 rad and
 * |f''| <= 16 (cos^4's), 3.8e-3 of the peak, so the flux is within 1 % (the bound). */
static void test_flux_of_the_table(void **state)
{
    (void)state;
    for (size_t i = 0; i < sizeof examples / sizeof *examples; i++) {
        lr_light_profile p;
        load_profile(examples[i], &p, NULL);
        assert_true(p.on && p.lumens > 0.0);
        double flux = p.max_cd * p.omega;
        if (fabs(flux / p.lumens - 1.0) > 0.01)
            fail_msg("%s: table flux %g lm against the file's %g", examples[i], flux, p.lumens);
        assert_true(p.omega_down <= p.omega + 1e-12);
    }
}

/* At the grid's nodes the table holds the file's intensity over its largest, to float
 * rounding (6e-8 relative); between them the two interpolants differ by the curvature bound
 * above. */
static void test_table_matches_the_file(void **state)
{
    (void)state;
    for (size_t i = 0; i < sizeof examples / sizeof *examples; i++) {
        lr_light_profile p;
        lr_luminaire lum;
        load_profile(examples[i], &p, &lum);
        double mx = lr_luminaire_max_cd(&lum);
        for (int c = 0; c < LR_PROFILE_NC; c += 7)
            for (int g = 0; g < LR_PROFILE_NG; g += 5) {
                double want = lr_luminaire_cd(&lum, c * LR_PROFILE_DC, g * LR_PROFILE_DG) / mx;
                double got = lr_light_profile_at(&p, cos(g * LR_PROFILE_DG * M_PI / 180.0),
                                                 c * LR_PROFILE_DC);
                assert_near(got, want, 1e-6 + 1e-9 * g);
            }
        for (int k = 0; k < 50; k++) {
            double h = 7.3 * k + 1.1, v = fmod(3.7 * k + 0.6, 180.0);
            double want = lr_luminaire_cd(&lum, h, v) / mx;
            assert_near(lr_light_profile_at(&p, cos(v * M_PI / 180.0), h), want, 4e-3);
        }
        lr_luminaire_free(&lum);
    }
}

/* A scene with one sphere and the light `light` (a JSON object's members). */
static const lr_light *parse_light(const char *light, lr_scene **s, lr_err *e)
{
    char t[2048];
    snprintf(t, sizeof t,
             "{\"objects\": [{\"material\": \"candle_wax\", \"mesh\": {\"type\": \"sphere\"}}],\n"
             " \"lights\": [{%s}],\n"
             " \"camera\": {\"position\": [0,-400,0], \"target\": [0,0,0]}}\n", light);
    if (lr_scene_parse(t, strlen(t), "t.json", NULL, s, e))
        return NULL;
    return lr_scene_light_at(*s, 0);
}

/* Without a strength the light takes the file's flux, and the shape's integral times its
 * peak intensity gives it back: flux_lm = K_m Y(color) intensity omega. With an intensity_cd
 * instead the peak is that, and the flux follows from the table's omega. */
static void test_light_strength_from_the_file(void **state)
{
    (void)state;
    lr_scene *s = NULL;
    lr_err e = {0};
    const lr_light *l = parse_light("\"type\": \"point\", \"position\": [0,0,200], "
                                    "\"color_temperature_k\": 2700, "
                                    "\"profile\": \"" EX "led_bulb_2700k.ies\"", &s, &e);
    if (!l)
        fail_msg("%s", e.msg);
    assert_near_rel(l->flux_lm, 806.0, 1e-12);
    assert_near_rel(l->intensity_cd, 806.0 / l->profile.omega, 1e-9);
    /* The file's own peak within the table's flux error (1 %). */
    assert_near_rel(l->intensity_cd, l->profile.max_cd, 0.01);
    lr_scene_destroy(s);

    l = parse_light("\"type\": \"point\", \"position\": [0,0,200], \"intensity_cd\": 50, "
                    "\"profile\": \"" EX "led_bulb_2700k.ies\"", &s, &e);
    if (!l)
        fail_msg("%s", e.msg);
    assert_near_rel(l->flux_lm, 50.0 * l->profile.omega, 1e-9);
    lr_scene_destroy(s);
}

/* A profiled point light's shape is rel in its frame: straight down the nadir the bulb's
 * (1 + cos 0) / 2 = 1, sideways 1/2, straight up 0 (the file's formula,
 * configs/photometry/README.md). */
static void test_shape_in_the_frame(void **state)
{
    (void)state;
    lr_scene *s = NULL;
    lr_err e = {0};
    const lr_light *l = parse_light("\"type\": \"point\", \"position\": [0,0,200], "
                                    "\"intensity\": 1, \"profile\": \"" EX "led_bulb_2700k.ies\"",
                                    &s, &e);
    if (!l)
        fail_msg("%s", e.msg);
    assert_near(lr_light_shape(l, lr_v3(0, 0, -1)), 1.0, 1e-6);
    assert_near(lr_light_shape(l, lr_v3(1, 0, 0)), 0.5, 1e-6);
    assert_near(lr_light_shape(l, lr_v3(0, 0, 1)), 0.0, 1e-6);
    lr_scene_destroy(s);
}

static lr_vec3 rot(const double R[3][3], lr_vec3 v)
{
    return lr_v3(R[0][0] * v.x + R[0][1] * v.y + R[0][2] * v.z,
                 R[1][0] * v.x + R[1][1] * v.y + R[1][2] * v.z,
                 R[2][0] * v.x + R[2][1] * v.y + R[2][2] * v.z);
}

/* A rotated light rotates its pattern: with nadir and C0 turned by R, the shape along R w is
 * the unrotated shape along w (to rounding: the local coordinates agree to ~1e-15, and the
 * lookup is continuous). The oval spot (1 + 0.3 cos 2C) tells C0 from C90, so a light that
 * only turned its nadir and kept C0 would fail. Both a spot (its cone turns too) and a quad. */
static void test_rotated_light_rotates_its_pattern(void **state)
{
    (void)state;
    double a = 0.7, b = -0.4; /* R = Rz(a) Rx(b) */
    double ca = cos(a), sa = sin(a), cb = cos(b), sb = sin(b);
    const double R[3][3] = {{ca, -sa * cb, sa * sb}, {sa, ca * cb, -ca * sb}, {0, sb, cb}};
    lr_vec3 n0 = lr_v3(0, 0, -1), c0 = lr_v3(1, 0, 0);
    lr_vec3 n1 = rot(R, n0), c1 = rot(R, c0);
    char t0[512], t1[512];
    snprintf(t0, sizeof t0, "\"type\": \"spot\", \"position\": [0,0,200], \"intensity\": 1, "
             "\"direction\": [%.17g,%.17g,%.17g], \"profile_c0\": [%.17g,%.17g,%.17g], "
             "\"inner_deg\": 50, \"outer_deg\": 80, \"profile\": \"" EX "led_spot_3000k.ies\"",
             n0.x, n0.y, n0.z, c0.x, c0.y, c0.z);
    snprintf(t1, sizeof t1, "\"type\": \"spot\", \"position\": [0,0,200], \"intensity\": 1, "
             "\"direction\": [%.17g,%.17g,%.17g], \"profile_c0\": [%.17g,%.17g,%.17g], "
             "\"inner_deg\": 50, \"outer_deg\": 80, \"profile\": \"" EX "led_spot_3000k.ies\"",
             n1.x, n1.y, n1.z, c1.x, c1.y, c1.z);
    lr_scene *s0 = NULL, *s1 = NULL;
    lr_err e = {0};
    const lr_light *l0 = parse_light(t0, &s0, &e);
    if (!l0)
        fail_msg("%s", e.msg);
    const lr_light *l1 = parse_light(t1, &s1, &e);
    if (!l1)
        fail_msg("%s", e.msg);
    lr_rng rng = lr_rng_init(7);
    int lit = 0, differs = 0;
    for (int k = 0; k < 400; k++) {
        double u = lr_rng_next(&rng), v = lr_rng_next(&rng);
        double ct = 1.0 - 2.0 * u, st = sqrt(1.0 - ct * ct), ph = 2.0 * M_PI * v;
        lr_vec3 w = lr_v3(st * cos(ph), st * sin(ph), ct);
        double s_0 = lr_light_shape(l0, w), s_1 = lr_light_shape(l1, rot(R, w));
        assert_near(s_1, s_0, 1e-9);
        lit += s_0 > 0.01;
        /* The unrotated light along the rotated direction: a different value somewhere. */
        differs += fabs(lr_light_shape(l0, rot(R, w)) - s_0) > 0.05;
    }
    assert_true(lit > 50);
    assert_true(differs > 50);
    /* C0 against C90 at 30 degrees from nadir: cos^4 (1 +- 0.3). */
    double g = 30.0 * M_PI / 180.0, c4 = pow(cos(g), 4);
    assert_near(lr_light_shape(l0, lr_v3(sin(g), 0, -cos(g))), c4, 5e-3);
    assert_near(lr_light_shape(l0, lr_v3(0, sin(g), -cos(g))), c4 * 0.7 / 1.3, 5e-3);
    lr_scene_destroy(s0);
    lr_scene_destroy(s1);
}

/* A quad whose profile is Lambert's (rel = cos gamma, 0 above the horizon) is the plain quad:
 * A rel against A cos within the grid's interpolation error h^2/8 = 2.4e-4 (|cos''| <= 1,
 * h = 2.5 degrees), on both faces when two-sided; its flux per unit radiance is pi A (the
 * table's omega_down is pi to the same order). */
static void test_lambertian_profile_is_the_plain_quad(void **state)
{
    (void)state;
    lr_scene *s = NULL;
    lr_err e = {0};
    const lr_light *q = parse_light("\"type\": \"quad\", \"position\": [0,0,200], "
                                    "\"edge_u\": [5,0,0], \"edge_v\": [0,-3,0], "
                                    "\"two_sided\": true, \"radiance\": 1", &s, &e);
    if (!q)
        fail_msg("%s", e.msg);
    lr_light plain = *q, prof = *q;
    lr_scene_destroy(s);
    prof.profile.on = true;
    for (int c = 0; c < LR_PROFILE_NC; c++)
        for (int g = 0; g < LR_PROFILE_NG; g++)
            prof.profile.rel[c * LR_PROFILE_NG + g] =
                (float)fmax(0.0, cos(g * LR_PROFILE_DG * M_PI / 180.0));
    lr_rng rng = lr_rng_init(3);
    double A = lr_light_area(&plain);
    for (int k = 0; k < 300; k++) {
        double u = lr_rng_next(&rng), v = lr_rng_next(&rng);
        double ct = 1.0 - 2.0 * u, st = sqrt(1.0 - ct * ct), ph = 2.0 * M_PI * v;
        lr_vec3 w = lr_v3(st * cos(ph), st * sin(ph), ct);
        assert_near(lr_light_shape(&prof, w), lr_light_shape(&plain, w), A * 3e-4);
    }
    prof.two_sided = plain.two_sided = false;
    assert_near(lr_light_shape(&prof, lr_v3(0, 0, 1)), 0.0, 0.0);
    lr_err ie = {0};
    lr_light_profile *p = &prof.profile;
    lr_profile_sampler smp;
    assert_int_equal(lr_profile_sampler_init(p, true, &smp, &ie), LR_OK);
    /* The sampler's total weight over the lower hemisphere: each cell's corner-mean rel
     * (cos g0 + cos g1) / 2 times its solid angle 5 deg (cos g0 - cos g1) telescopes to
     * pi (cos^2 0 - cos^2 90) = pi, exact but for the table's float rounding (6e-8). */
    assert_near(smp.total, M_PI, 1e-6);
}

/* The sampler's estimate of a function's integral, mean of f / pdf, is unbiased: for f = rel
 * it equals omega. N = 20000 samples; the spread of rel / pdf within a cell is the cell's
 * interpolation variation (a few %), so 4 sigma is well under 1 %. A pdf that did not match
 * its cells' weights would be off by their ratio. */
static void test_sampler_is_unbiased(void **state)
{
    (void)state;
    for (size_t i = 0; i < sizeof examples / sizeof *examples; i++) {
        lr_light_profile p;
        load_profile(examples[i], &p, NULL);
        for (int lower = 0; lower < 2; lower++) {
            lr_profile_sampler smp;
            lr_err e = {0};
            assert_int_equal(lr_profile_sampler_init(&p, lower, &smp, &e), LR_OK);
            lr_rng rng = lr_rng_init(11 + (unsigned)i);
            const int N = 20000;
            double sum = 0.0, sum2 = 0.0;
            for (int k = 0; k < N; k++) {
                double u1 = lr_rng_next(&rng), u2 = lr_rng_next(&rng),
                       u3 = lr_rng_next(&rng), pdf;
                lr_vec3 d = lr_profile_sample(&smp, u1, u2, u3, &pdf);
                assert_near(lr_v3_len(d), 1.0, 1e-12);
                if (lower)
                    assert_true(d.z >= -1e-12);
                double x = lr_light_profile_eval(&p, d) / pdf;
                sum += x;
                sum2 += x * x;
            }
            double mean = sum / N, sd = sqrt(fmax(0.0, sum2 / N - mean * mean) / N);
            double want = lower ? p.omega_down : p.omega;
            if (fabs(mean - want) > 4.0 * sd + 1e-3 * want)
                fail_msg("%s lower %d: mean %g against omega %g (sd %g)", examples[i], lower,
                         mean, want, sd);
        }
    }
}

/* The shipped example: configs/scenes/lampshade_led.json's bulb takes the IES file (a path
 * relative to the scene) and, without a strength, its 806 lm. */
static void test_shipped_scene(void **state)
{
    (void)state;
    lr_scene *s = NULL;
    lr_err e = {0};
    if (lr_scene_load(LR_SOURCE_CONFIGS "/scenes/lampshade_led.json", NULL, &s, &e))
        fail_msg("%s", e.msg);
    const lr_light *l = lr_scene_light_at(s, 0);
    assert_true(l->profile.on);
    assert_near_rel(l->flux_lm, 806.0, 1e-12);
    /* Down twice as bright as sideways: (1 + cos gamma) / 2. */
    assert_near(lr_light_shape(l, lr_v3(1, 0, 0)) / lr_light_shape(l, lr_v3(0, 0, -1)), 0.5,
                1e-6);
    lr_scene_destroy(s);
}

/* A missing or malformed file is refused naming the light's field and the file. */
static void test_refusals(void **state)
{
    (void)state;
    lr_scene *s = NULL;
    lr_err e = {0};
    assert_null(parse_light("\"type\": \"point\", \"position\": [0,0,200], \"intensity\": 1, "
                            "\"profile\": \"/nonexistent/x.ies\"", &s, &e));
    assert_non_null(strstr(e.msg, "lights[0].profile"));
    assert_non_null(strstr(e.msg, "/nonexistent/x.ies"));
    e = (lr_err){0};
    assert_null(parse_light("\"type\": \"directional\", \"radiance\": 1, "
                            "\"profile\": \"" EX "led_bulb_2700k.ies\"", &s, &e));
    assert_non_null(strstr(e.msg, "profile"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_flux_of_the_table),
        cmocka_unit_test(test_table_matches_the_file),
        cmocka_unit_test(test_light_strength_from_the_file),
        cmocka_unit_test(test_shape_in_the_frame),
        cmocka_unit_test(test_rotated_light_rotates_its_pattern),
        cmocka_unit_test(test_lambertian_profile_is_the_plain_quad),
        cmocka_unit_test(test_sampler_is_unbiased),
        cmocka_unit_test(test_shipped_scene),
        cmocka_unit_test(test_refusals),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
