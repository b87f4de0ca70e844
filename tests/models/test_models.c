/* The per-object models' registry (render/models/model.h): every id has one table whose name
 * parses back to it and whose hooks agree with its properties; the GLSL dispatch generated from
 * it names only functions the shaders define and fits the renderer's defines; and the property
 * table against what the code does with each model: no_profile exactly when lr_sss_sd_fresnel gives 0 where the
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
#include <stdlib.h>
#include <string.h>

#include "render/models/model.h"
#include "render/models/twin/cavity_gains.h"
#include "render/passes/defines.h"
#include "render/material/material.h"
#include "render/optics/optics.h"
#include "render/scene/fields.h"
#include "render/scene/scene.h"
#include "tests/support/fs.h"

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

/* Every id has a table; names are unique and parse back; a model without a profile has no S_d
 * hook (and one with a profile has one, or borrows another's through the profile hook); the
 * GLSL expressions exist exactly where the CPU ones do; B from a solved field or the lights'
 * environments is exactly what has a GLSL B of its own. */
static void test_registry(void **state)
{
    (void)state;
    for (int m = 0; m < LR_SSS_MODEL_COUNT; m++) {
        const lr_model_ops *o = lr_model_of((enum lr_sss_model)m);
        assert_non_null(o);
        assert_non_null(o->name);
        enum lr_sss_model back = (enum lr_sss_model)-1;
        assert_true(lr_sss_model_parse(o->name, &back));
        assert_int_equal(back, m);
        assert_string_equal(lr_sss_model_name((enum lr_sss_model)m), o->name);
        for (int k = 0; k < m; k++)
            assert_string_not_equal(lr_model_of((enum lr_sss_model)k)->name, o->name);
        const lr_sss_model_props *p = &o->props;
        if (p->no_profile) {
            assert_null(o->sd_fresnel);
            assert_null(o->profile);
        } else {
            assert_true(o->sd_fresnel != NULL || o->profile != NULL);
        }
        assert_int_equal(o->glsl_sd != NULL, o->sd_fresnel != NULL);
        assert_int_equal(o->glsl_B != NULL, p->grid_field || p->light_env);
        assert_int_equal(p->no_profile, p->grid_field || p->light_env);
        /* a borrowed profile is a model with one of its own */
        for (int th = 0; th < 2 && o->profile; th++) {
            enum lr_sss_model q = o->profile(th ? 2.0 : 0.0);
            assert_true((unsigned)q < LR_SSS_MODEL_COUNT);
            assert_non_null(lr_model_of(q)->sd_fresnel);
            assert_null(lr_model_of(q)->profile);
        }
    }
    assert_null(lr_model_of((enum lr_sss_model)LR_SSS_MODEL_COUNT));
    assert_string_equal(lr_sss_model_name((enum lr_sss_model)LR_SSS_MODEL_COUNT), "?");
    enum lr_sss_model x;
    assert_false(lr_sss_model_parse("dipole", &x));
    assert_false(lr_sss_model_parse(NULL, &x));

    /* Translucent radiosity integrates the multipole over a wall, else the standard dipole;
     * its own S_d is that profile's (seed 000 with the profiles of seed 003 Eq. 4). */
    assert_int_equal(lr_sss_profile_of(LR_SSS_TRANSLUCENT_RADIOSITY, 2.0), LR_SSS_MULTIPOLE);
    assert_int_equal(lr_sss_profile_of(LR_SSS_TRANSLUCENT_RADIOSITY, 0.0),
                     LR_SSS_STANDARD_DIPOLE);
    assert_int_equal(lr_sss_profile_of(LR_SSS_MULTIPOLE, 2.0), LR_SSS_MULTIPOLE);
    lr_material mat;
    lr_coeffs c;
    lr_err e = {0};
    if (lr_material_find("marble", &mat, &e) || lr_coeffs_derive(&mat.medium, &c, &e))
        fail_msg("%s", e.msg);
    lr_vec3 xi = lr_v3(0, 0, 0), n = lr_v3(0, 0, 1), xo = lr_v3(1, 0, 0);
    double a[3], b[3];
    lr_sss_sd_fresnel(LR_SSS_TRANSLUCENT_RADIOSITY, &c, 2.0, xi, n, n, xo, n, a);
    lr_sss_sd_fresnel(LR_SSS_MULTIPOLE, &c, 2.0, xi, n, n, xo, n, b);
    for (int k = 0; k < 3; k++)
        assert_true(a[k] == b[k] && a[k] > 0.0);
    assert_int_equal(lr_sss_pairs(LR_SSS_TRANSLUCENT_RADIOSITY, &c, 2.0),
                     lr_multipole_pairs(&c, 2.0));
    assert_int_equal(lr_sss_pairs(LR_SSS_STANDARD_DIPOLE, &c, 2.0), 0);

    /* S_d's normalisation (PIPELINE.md "Energy"): the directional dipole's per-band factor,
     * 1 / t_hem for the profiles the standard dipole anchors, 1 for the rest and when raw. */
    for (int k = 0; k < 3; k++) {
        assert_true(lr_sss_sd_norm(LR_SSS_DIRECTIONAL_DIPOLE, &c, false, k) == c.sd_norm[k]);
        assert_true(lr_sss_sd_norm(LR_SSS_STANDARD_DIPOLE, &c, false, k) == 1.0 / c.t_hem);
        assert_true(lr_sss_sd_norm(LR_SSS_MULTIPOLE, &c, false, k) == 1.0 / c.t_hem);
        for (int m = 0; m < LR_SSS_MODEL_COUNT; m++) {
            assert_true(lr_sss_sd_norm((enum lr_sss_model)m, &c, true, k) == 1.0);
            if (m > LR_SSS_MULTIPOLE)
                assert_true(lr_sss_sd_norm((enum lr_sss_model)m, &c, false, k) == 1.0);
        }
    }
}

/* The name of the function an expression calls: "lr_dgrid_B(xo)" -> "lr_dgrid_B". */
static void callee(const char *expr, char *out, size_t cap)
{
    size_t n = strcspn(expr, "(");
    snprintf(out, cap, "%.*s", (int)n, expr);
}

/* Whether some shader under render/shaders defines function f ("float f(" or "vec3 f("). */
static bool shaders_define(const char *f)
{
    static const char *const files[] = {"lib/optics.glsl", "lib/dgrid.glsl",
                                        "lib/sh_translucency.glsl"};
    char def1[128], def2[128];
    snprintf(def1, sizeof def1, "float %s(", f);
    snprintf(def2, sizeof def2, "vec3 %s(", f);
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        char path[1024];
        snprintf(path, sizeof path, "%s/../render/shaders/%s", LR_SOURCE_CONFIGS, files[i]);
        size_t len = 0;
        char *text = (char *)lr_test_read(path, &len);
        if (!text)
            fail_msg("cannot read %s", path);
        bool yes = strstr(text, def1) || strstr(text, def2);
        free(text);
        if (yes)
            return true;
    }
    return false;
}

static void test_glsl_dispatch(void **state)
{
    (void)state;
    char buf[2048];
    const char *lines[LR_MODELS_GLSL_DEFINES];
    assert_int_equal(lr_models_glsl_defines(buf, sizeof buf, lines, LR_MODELS_GLSL_DEFINES),
                     LR_MODELS_GLSL_DEFINES);
    assert_true(strncmp(lines[0], "LR_MODEL_SD_BAND(c,s,j,xi,ni,wi,xo,no) (", 40) == 0);
    assert_true(strncmp(lines[1], "LR_MODEL_HAS_B(m) (", 19) == 0);
    assert_true(strncmp(lines[2], "LR_MODEL_B(m,obj,mat,xo,no) (", 29) == 0);
    for (int m = 0; m < LR_SSS_MODEL_COUNT; m++) {
        const lr_model_ops *o = lr_model_of((enum lr_sss_model)m);
        char arm[512], f[96];
        if (o->glsl_sd) {
            snprintf(arm, sizeof arm, "s.model == %d ? %s : ", m, o->glsl_sd);
            assert_non_null(strstr(lines[0], arm));
            callee(o->glsl_sd, f, sizeof f);
            if (!shaders_define(f))
                fail_msg("%s's glsl_sd calls %s, which no shader defines", o->name, f);
        } else {
            snprintf(arm, sizeof arm, "== %d ?", m);
            assert_null(strstr(lines[0], arm));
        }
        snprintf(arm, sizeof arm, "(m) == %d", m);
        assert_int_equal(strstr(lines[1], arm) != NULL, o->glsl_B != NULL);
        if (o->glsl_B) {
            callee(o->glsl_B, f, sizeof f);
            if (!shaders_define(f))
                fail_msg("%s's glsl_B calls %s, which no shader defines", o->name, f);
        }
    }
    /* too small a buffer is refused, not cut */
    assert_int_equal(lr_models_glsl_defines(buf, 64, lines, LR_MODELS_GLSL_DEFINES), -1);
    assert_int_equal(lr_models_glsl_defines(buf, sizeof buf, lines, 2), -1);
    /* the renderer's defines carry all three, after the constants */
    lr_shader_defines d;
    const char *const *list = lr_passes_defines(&d);
    int found = 0;
    for (int i = 0; list[i]; i++)
        found += strncmp(list[i], "LR_MODEL_", 9) == 0;
    assert_int_equal(found, LR_MODELS_GLSL_DEFINES);
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
        cmocka_unit_test(test_registry),
        cmocka_unit_test(test_glsl_dispatch),
        cmocka_unit_test(test_profile),
        cmocka_unit_test(test_needs_and_closure),
        cmocka_unit_test(test_sigma_tr_limit),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
