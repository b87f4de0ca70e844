/* The per-model property table (lr_sss_model_props_of, render/optics/model.c) against what the
 * code does with each model: no_profile exactly when lr_sss_sd_fresnel gives 0 where the
 * dipole gives a positive S_d; needs_thickness / needs_closed exactly when
 * lr_scene_object_model_unmet refuses an object without them (with the table's text); the
 * cavity closure applied to the candle's flame exactly for the models without no_closure;
 * max_sigma_tr exactly where lr_sss_model_check_medium refuses a medium. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "render/models/cavity_gains.h"
#include "render/material/material.h"
#include "render/optics/optics.h"
#include "render/scene/fields.h"
#include "render/scene/scene.h"

static void test_profile(void **state)
{
    (void)state;
    lr_material mat;
    lr_coeffs c;
    lr_err e = {0};
    if (lr_material_find("marble", &mat, &e) || lr_coeffs_derive(&mat.medium, &c, &e))
        fail_msg("%s", e.msg);
    lr_vec3 xi = lr_v3(0, 0, 0), n = lr_v3(0, 0, 1), wi = lr_v3(0, 0, 1), xo = lr_v3(1, 0, 0);
    for (int m = 0; m < LR_SSS_MODEL_COUNT; m++) {
        const lr_sss_model_props *p = lr_sss_model_props_of((enum lr_sss_model)m);
        double out[3] = {-1, -1, -1};
        lr_sss_sd_fresnel((enum lr_sss_model)m, &c, 5.0, xi, n, wi, xo, n, out);
        for (int b = 0; b < 3; b++) {
            if (p->no_profile)
                assert_true(out[b] == 0.0);
            else
                assert_true(out[b] > 0.0 && isfinite(out[b]));
        }
    }
    /* outside the enum: the all-zero row */
    const lr_sss_model_props *none = lr_sss_model_props_of((enum lr_sss_model)LR_SSS_MODEL_COUNT);
    assert_false(none->no_profile);
    assert_null(none->needs_thickness);
    assert_null(none->needs_closed);
    assert_null(none->no_closure);
    assert_null(none->no_openings);
    assert_true(none->max_sigma_tr == 0.0);
}

static lr_scene *load(const char *name)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/scenes/%s.json", LR_SOURCE_CONFIGS, name);
    lr_scene *s = NULL;
    lr_err e = {0};
    if (lr_scene_load(path, NULL, &s, &e))
        fail_msg("%s", e.msg);
    return s;
}

static void test_needs_and_closure(void **state)
{
    (void)state;
    /* the candle: closed, no thickness_mm, its flame in the melt pool (HULL) */
    lr_scene *s = load("candle");
    const lr_scene_object *o = lr_scene_object_at(s, 0);
    assert_true(o->closed);
    assert_false(o->thickness_mm > 0.0);
    int obj = -1;
    assert_int_equal(lr_scene_light_enclosure(s, 0, &obj), LR_ENCLOSURE_HULL);
    for (int m = 0; m < LR_SSS_MODEL_COUNT; m++) {
        const lr_sss_model_props *p = lr_sss_model_props_of((enum lr_sss_model)m);
        const char *why = lr_scene_object_model_unmet(o, (enum lr_sss_model)m);
        if (p->needs_thickness) {
            assert_string_equal(why, p->needs_thickness);
            continue;
        }
        assert_null(why);
        /* a closed mesh satisfies needs_closed; the cavity closure by the table */
        char key[32], val[64];
        snprintf(key, sizeof key, "objects[0].model");
        snprintf(val, sizeof val, "%s", lr_sss_model_name((enum lr_sss_model)m));
        lr_err e = {0};
        if (lr_scene_set(s, key, val, NULL, &e))
            fail_msg("%s", e.msg);
        o = lr_scene_object_at(s, 0);
        lr_cavity cav;
        assert_int_equal(lr_cavity_measure(o, lr_scene_light_at(s, 0), LR_ENCLOSURE_HULL,
                                               &(lr_cavity_desc){.directions = 64,
                                                                     .points = 16, .N = 4,
                                                                     .threads = 1},
                                               &cav, &e),
                         LR_OK);
        assert_int_equal(cav.applies, p->no_closure == NULL);
    }
    lr_scene_destroy(s);

    /* the shade without rims: open, so the grid (needs_closed) is refused with the text */
    s = load("lampshade");
    lr_err e = {0};
    if (lr_scene_set(s, "objects[0].mesh.rims", "false", NULL, &e))
        fail_msg("%s", e.msg);
    o = lr_scene_object_at(s, 0);
    assert_false(o->closed);
    for (int m = 0; m < LR_SSS_MODEL_COUNT; m++) {
        const lr_sss_model_props *p = lr_sss_model_props_of((enum lr_sss_model)m);
        const char *why = lr_scene_object_model_unmet(o, (enum lr_sss_model)m);
        if (p->needs_closed)
            assert_string_equal(why, p->needs_closed);
        else
            assert_null(why); /* the shade has thickness_mm */
    }
    lr_scene_destroy(s);
}

/* max_sigma_tr: lr_sss_model_check_medium refuses a medium exactly when some band's sigma_tr
 * is over the row's limit, naming both coefficients, the band, the model and the limit; a row
 * without a limit takes every valid medium; and every shipped preset is within every model's
 * limit (a limit that refused a preset would be a regression, not a validity range). The
 * band that crosses is the blue one only, so the message must name it and not the others. */
static void test_sigma_tr_limit(void **state)
{
    (void)state;
    const double sa[] = {1.0, 100.0, 1e4}, ssp[] = {1.0, 1e6};
    for (int m = 0; m < LR_SSS_MODEL_COUNT; m++) {
        const lr_sss_model_props *p = lr_sss_model_props_of((enum lr_sss_model)m);
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < 2; k++) {
                /* red and green well inside any limit, blue the sweep's value */
                lr_medium med = {.sigma_a = {0.01, 0.01, sa[i]},
                                 .sigma_s_prime = {1.0, 1.0, ssp[k]}, .eta = 1.3};
                lr_err e = {0};
                assert_int_equal(lr_medium_validate(&med, &e), LR_OK);
                double str = sqrt(3.0 * sa[i] * (sa[i] + ssp[k]));
                int rc = lr_sss_model_check_medium((enum lr_sss_model)m, &med, &e);
                bool over = p->max_sigma_tr > 0.0 && str > p->max_sigma_tr;
                assert_int_equal(rc, over ? LR_EINVAL : LR_OK);
                if (!over)
                    continue;
                assert_non_null(strstr(e.msg, "sigma_a = "));
                assert_non_null(strstr(e.msg, "sigma_s_prime = "));
                assert_non_null(strstr(e.msg, "(blue)"));
                assert_non_null(strstr(e.msg, lr_sss_model_name((enum lr_sss_model)m)));
                assert_non_null(strstr(e.msg, p->max_sigma_tr_why));
                char lim[64];
                snprintf(lim, sizeof lim, "sigma_tr <= %g /mm", p->max_sigma_tr);
                assert_non_null(strstr(e.msg, lim));
            }
    }
    /* translucent radiosity has a limit, and the sweep crosses it (else this tests nothing) */
    assert_true(lr_sss_model_props_of(LR_SSS_TRANSLUCENT_RADIOSITY)->max_sigma_tr > 0.0);
    assert_true(sqrt(3.0 * 1e4 * (1e4 + 1.0)) >
                lr_sss_model_props_of(LR_SSS_TRANSLUCENT_RADIOSITY)->max_sigma_tr);
    /* the scene reference (`lamprig render --help-scene`, objects[i].model) states the limit */
    const lr_field *fm = lr_field_find(&lr_scene_object_desc, 0, "model");
    assert_non_null(fm);
    char lim[64];
    snprintf(lim, sizeof lim, "<= %g /mm",
             lr_sss_model_props_of(LR_SSS_TRANSLUCENT_RADIOSITY)->max_sigma_tr);
    if (!strstr(fm->help, lim))
        fail_msg("objects[i].model's help lacks '%s': %s", lim, fm->help);
    char **names;
    int n = 0;
    lr_err e = {0};
    if (lr_material_names(&names, &n, &e))
        fail_msg("%s", e.msg);
    assert_true(n > 0);
    for (int i = 0; i < n; i++) {
        lr_material mat;
        if (lr_material_find(names[i], &mat, &e))
            fail_msg("%s", e.msg);
        for (int m = 0; m < LR_SSS_MODEL_COUNT; m++)
            if (lr_sss_model_check_medium((enum lr_sss_model)m, &mat.medium, &e))
                fail_msg("preset %s: %s", names[i], e.msg);
    }
    lr_material_names_free(names, n);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_profile),
        cmocka_unit_test(test_needs_and_closure),
        cmocka_unit_test(test_sigma_tr_limit),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
