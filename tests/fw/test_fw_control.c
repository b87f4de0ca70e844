/* firmware/rig/control_map: event sequences through curves, ranges, steps, acceleration and
 * fades give the expected scene parameter values over time, against the real scene API
 * (configs/scenes/candle.json); the lamp driver gets the same curved level as the scene. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "firmware/control/accel.h"
#include "firmware/control/curve.h"
#include "firmware/rig/config.h"
#include "firmware/rig/control_map.h"
#include "render/scene/scene.h"
#include "tests/support/near.h"

#define MS 1000000LL
#define SCENE LR_SOURCE_CONFIGS "/scenes/candle.json"

typedef struct fx {
    lr_rig_config *cfg;
    lr_scene *scene;
    lr_control_map *map;
} fx;

static void fx_make(fx *f, const char *controls)
{
    char text[8192];
    /* A sim device may speak for any source ("panel/dimmer"). */
    snprintf(text, sizeof text,
             "{\"scene\": \"%s\", \"devices\": [{\"type\": \"sim\", \"text\": \"0 x press\"}], "
             "\"controls\": %s}",
             SCENE, controls);
    lr_err e = {0};
    if (lr_rig_config_parse(text, "test-rig.json", &f->cfg, &e))
        fail_msg("config: %s", e.msg);
    if (lr_scene_load(SCENE, NULL, &f->scene, &e))
        fail_msg("scene: %s", e.msg);
    if (lr_control_map_create(f->cfg, f->scene, true, 0, &f->map, &e))
        fail_msg("control map: %s", e.msg);
}

static void fx_free(fx *f)
{
    lr_control_map_destroy(f->map);
    lr_scene_destroy(f->scene);
    lr_rig_config_destroy(f->cfg);
}

static double get(fx *f, const char *key)
{
    char buf[256];
    lr_err e = {0};
    if (lr_scene_get(f->scene, key, buf, sizeof buf, &e))
        fail_msg("%s", e.msg);
    return strtod(buf, NULL);
}

static void get_vec(fx *f, const char *key, double out[3])
{
    char buf[256];
    lr_err e = {0};
    if (lr_scene_get(f->scene, key, buf, sizeof buf, &e))
        fail_msg("%s", e.msg);
    if (sscanf(buf, "%lf,%lf,%lf", &out[0], &out[1], &out[2]) != 3)
        fail_msg("%s = '%s' is not a vector", key, buf);
}

static unsigned update(fx *f, int64_t t)
{
    unsigned dirty = 0;
    lr_err e = {0};
    if (lr_control_map_update(f->map, f->scene, t, &dirty, &e))
        fail_msg("update: %s", e.msg);
    return dirty;
}

static lr_event ev(const char *source, const char *control, lr_event_kind kind, double v,
                   int64_t t)
{
    lr_event x;
    lr_event_set(&x, source, control, kind, v, t);
    return x;
}

/* A dimmer on a square-law curve fades linearly in *level* from where it was to curve(x); the
 * scene's intensity and the lamp driver's level are the same level at every instant. */
static void test_dimmer_curve_range_fade(void **state)
{
    (void)state;
    fx f;
    fx_make(&f, "[{\"control\": \"panel/dimmer\", \"param\": \"light.intensity\", "
                "\"range\": [0, 0.01], \"curve\": \"square\", \"fade_s\": 0.5, \"lamp\": true}]");
    /* The start position reproduces the scene's 0.005 W/sr: level 0.5, x = sqrt(0.5). */
    assert_near(lr_control_map_position(f.map, 0), sqrt(0.5), 1e-12);
    assert_int_equal(update(&f, 0), LR_DIRTY_INTENSITY); /* first write */
    assert_near(get(&f, "light.intensity"), 0.005, 1e-9);

    int64_t t0 = 1000 * MS;
    lr_event e1 = ev("panel", "dimmer", LR_EV_ABSOLUTE, 0.5, t0);
    assert_int_equal(lr_control_map_event(f.map, &e1, t0), 0);
    /* Level target 0.25; halfway through the fade 0.375; at the end 0.25. */
    const struct { int64_t t; double level; } at[] = {
        {t0, 0.5}, {t0 + 125 * MS, 0.4375}, {t0 + 250 * MS, 0.375}, {t0 + 500 * MS, 0.25},
        {t0 + 900 * MS, 0.25}};
    for (size_t i = 0; i < sizeof at / sizeof at[0]; i++) {
        unsigned d = update(&f, at[i].t);
        assert_true(d == 0 || d == LR_DIRTY_INTENSITY); /* only composition is redone */
        assert_near(get(&f, "light.intensity"), 0.01 * at[i].level, 1e-9);
        double lamp;
        assert_true(lr_control_map_lamp_level(f.map, at[i].t, &lamp));
        assert_near(lamp, at[i].level, 1e-12);
        /* One place: the lamp level is exactly the level the scene value came from. */
        assert_near(lamp * 0.01, get(&f, "light.intensity"), 1e-9);
        assert_int_equal(lr_control_map_fading(f.map, at[i].t), at[i].t < t0 + 500 * MS);
    }
    /* A new target mid-fade starts from the value shown then (no jump). */
    int64_t t1 = 2000 * MS;
    lr_event e2 = ev("panel", "dimmer", LR_EV_ABSOLUTE, 1.0, t1);
    assert_int_equal(lr_control_map_event(f.map, &e2, t1), 0);
    update(&f, t1 + 100 * MS);
    assert_near(get(&f, "light.intensity"), 0.01 * (0.25 + 0.75 * 0.2), 1e-9);
    lr_event e3 = ev("panel", "dimmer", LR_EV_ABSOLUTE, 0.0, t1 + 100 * MS);
    lr_control_map_event(f.map, &e3, t1 + 100 * MS);
    update(&f, t1 + 100 * MS);
    assert_near(get(&f, "light.intensity"), 0.01 * 0.4, 1e-9);
    update(&f, t1 + 350 * MS);
    assert_near(get(&f, "light.intensity"), 0.01 * 0.2, 1e-9);
    update(&f, t1 + 600 * MS);
    assert_near(get(&f, "light.intensity"), 0.0, 1e-12);
    /* Same position again: nothing moves. Another source's "dimmer": not this binding. */
    lr_event same = ev("panel", "dimmer", LR_EV_ABSOLUTE, 0.0, t1 + 700 * MS);
    assert_int_equal(lr_control_map_event(f.map, &same, t1 + 700 * MS), -1);
    lr_event other = ev("gpio", "dimmer", LR_EV_ABSOLUTE, 0.7, t1 + 700 * MS);
    assert_int_equal(lr_control_map_event(f.map, &other, t1 + 700 * MS), -1);
    fx_free(&f);
}

/* The four curves at one position, through the range [min, max] with max < min (reversed). */
static void test_curves_and_reversed_range(void **state)
{
    (void)state;
    static const char *const curves[] = {"linear", "square", "s-curve", "log"};
    for (int c = 0; c < 4; c++) {
        char ctl[512];
        snprintf(ctl, sizeof ctl,
                 "[{\"control\": \"dimmer\", \"param\": \"light.intensity\", \"range\": [0.02, "
                 "0.01], \"curve\": \"%s\", \"initial\": 0}]",
                 curves[c]);
        fx f;
        fx_make(&f, ctl);
        update(&f, 0);
        assert_near(get(&f, "light.intensity"), 0.02, 1e-12);
        lr_event e = ev("sim", "dimmer", LR_EV_ABSOLUTE, 0.3, 10 * MS);
        assert_int_equal(lr_control_map_event(f.map, &e, 10 * MS), 0);
        update(&f, 10 * MS);
        double y = lr_curve_apply((enum lr_curve)c, 0.3);
        assert_near(get(&f, "light.intensity"), 0.02 - 0.01 * y, 1e-9);
        fx_free(&f);
    }
}

/* Encoder detents move the position by step; slow turns are not accelerated, a fast spin is
 * (the same factor lr_accel computes), and the position stops at the ends. */
static void test_encoder_step_accel_clamp(void **state)
{
    (void)state;
    fx f;
    fx_make(&f, "[{\"control\": \"knob1\", \"param\": \"lights[0].flicker.amplitude\", "
                "\"range\": [0, 0.5], \"step\": 0.05, \"initial\": 0.2, "
                "\"accel\": {\"gain\": 1, \"rate0\": 5, \"max\": 4}}]");
    update(&f, 0);
    assert_near(get(&f, "lights[0].flicker.amplitude"), 0.1, 1e-12);
    /* Three slow detents (400 ms apart: the estimate resets): exactly 3 steps. */
    int64_t t = 1000 * MS;
    for (int i = 0; i < 3; i++, t += 400 * MS) {
        lr_event e = ev("gpio", "knob1", LR_EV_DELTA, +1, t);
        assert_int_equal(lr_control_map_event(f.map, &e, t), 0);
    }
    assert_near(lr_control_map_position(f.map, 0), 0.35, 1e-12);
    unsigned d = update(&f, t);
    assert_near(get(&f, "lights[0].flicker.amplitude"), 0.175, 1e-9);
    assert_int_equal(d, LR_DIRTY_INTENSITY); /* the wobble's size only rescales */
    /* A fast spin back: 8 detents 10 ms apart. Expected = the accel model's own factors. */
    lr_accel ref;
    lr_accel_init(&ref, 1, 5, 4);
    double x = 0.35, moved = 0;
    for (int i = 0; i < 8; i++, t += 10 * MS) {
        lr_event e = ev("gpio", "knob1", LR_EV_DELTA, -1, t);
        lr_control_map_event(f.map, &e, t);
        double dx = lr_accel_apply(&ref, -1, t) * 0.05;
        moved += dx;
        x = fmax(0, x + dx);
    }
    assert_true(-moved > 8 * 0.05 * 1.5); /* accelerated well beyond 8 steps */
    assert_near(lr_control_map_position(f.map, 0), x, 1e-12);
    assert_near(x, 0.0, 1e-12); /* clamped at the bottom end */
    update(&f, t);
    assert_near(get(&f, "lights[0].flicker.amplitude"), 0.0, 1e-12);
    /* Buttons and releases do not move a level. */
    lr_event p = ev("gpio", "knob1", LR_EV_PRESS, 1, t);
    assert_int_equal(lr_control_map_event(f.map, &p, t), -1);
    fx_free(&f);
}

/* A button cycles material presets (dirtying the material), wrapping; an encoder steps both
 * ways; an absolute position picks floor(x * n); the translucency scale on the same object
 * survives a preset change (a preset replaces the whole material, scale included). */
static void test_material_cycle_keeps_scale(void **state)
{
    (void)state;
    fx f;
    fx_make(&f, "[{\"control\": \"button1\", \"param\": \"objects[0].material\", "
                "\"values\": [\"candle_wax\", \"marble\", \"porcelain\"]},"
                " {\"control\": \"knob2\", \"param\": \"objects[0].material.scale\", "
                "\"range\": [0.25, 4], \"curve\": \"log\", \"initial\": 0.5}]");
    update(&f, 0);
    double s0 = 0.25 + 3.75 * log10(1 + 9 * 0.5);
    assert_near(get(&f, "objects[0].material.scale"), s0, 1e-6);
    char buf[64];
    lr_event press = ev("gpio", "button1", LR_EV_PRESS, 1, 10 * MS);
    lr_event rel = ev("gpio", "button1", LR_EV_RELEASE, 0, 20 * MS);
    const char *expect[] = {"marble", "porcelain", "candle_wax", "marble"};
    for (int i = 0; i < 4; i++) {
        assert_int_equal(lr_control_map_event(f.map, &press, 10 * MS), 0);
        assert_int_equal(lr_control_map_event(f.map, &rel, 20 * MS), -1);
        unsigned d = update(&f, 30 * MS);
        assert_true(d & LR_DIRTY_MATERIAL);
        assert_int_equal(lr_scene_get(f.scene, "objects[0].material.base", buf, sizeof buf, NULL),
                         LR_OK);
        assert_string_equal(buf, expect[i]);
        assert_near(get(&f, "objects[0].material.scale"), s0, 1e-6);
    }
    lr_event back = ev("gpio", "button1", LR_EV_DELTA, -1, 40 * MS);
    assert_int_equal(lr_control_map_event(f.map, &back, 40 * MS), 0);
    assert_int_equal(lr_control_map_index(f.map, 0), 0);
    lr_event abs = ev("sim", "button1", LR_EV_ABSOLUTE, 0.99, 50 * MS);
    assert_int_equal(lr_control_map_event(f.map, &abs, 50 * MS), 0);
    assert_int_equal(lr_control_map_index(f.map, 0), 2);
    update(&f, 60 * MS);
    lr_scene_get(f.scene, "objects[0].material.base", buf, sizeof buf, NULL);
    assert_string_equal(buf, "porcelain");
    fx_free(&f);
}

/* A shade colour and a translucency knob on the same parameter multiply: scale * colour. */
static void test_colour_times_scale(void **state)
{
    (void)state;
    fx f;
    fx_make(&f, "[{\"control\": \"knob2\", \"param\": \"objects[0].material.scale\", "
                "\"range\": [0.5, 2.5]},"
                " {\"control\": \"tint\", \"param\": \"objects[0].material.scale\", "
                "\"colors\": [[1, 1, 1], [0.5, 1, 2]], \"initial\": 0}]");
    /* Shared parameter: the knob starts where it gives a factor of 1 (x = 0.25). */
    assert_near(lr_control_map_position(f.map, 0), 0.25, 1e-12);
    lr_event a = ev("sim", "knob2", LR_EV_ABSOLUTE, 0.75, 0);
    lr_event b = ev("sim", "tint", LR_EV_ABSOLUTE, 0.5, 0);
    lr_control_map_event(f.map, &a, 0);
    lr_control_map_event(f.map, &b, 0);
    assert_int_equal(update(&f, 0), LR_DIRTY_MATERIAL);
    double v[3];
    get_vec(&f, "objects[0].material.scale", v);
    assert_near(v[0], 2.0 * 0.75, 1e-6);
    assert_near(v[1], 2.0 * 1.0, 1e-6);
    assert_near(v[2], 2.0 * 1.5, 1e-6);
    fx_free(&f);
}

/* Garbage never reaches the scene: NaN/Inf values are counted and ignored; a huge delta is
 * clamped to the range. */
static void test_garbage_ignored(void **state)
{
    (void)state;
    fx f;
    fx_make(&f, "[{\"control\": \"dimmer\", \"param\": \"light.intensity\", "
                "\"range\": [0, 0.01], \"step\": 0.1},"
                " {\"control\": \"button1\", \"param\": \"objects[0].material\", "
                "\"values\": [\"marble\", \"porcelain\"]}]");
    update(&f, 0);
    lr_event bad[] = {ev("sim", "dimmer", LR_EV_ABSOLUTE, NAN, 0),
                      ev("sim", "dimmer", LR_EV_DELTA, INFINITY, 0),
                      ev("sim", "button1", LR_EV_DELTA, -INFINITY, 0)};
    for (int i = 0; i < 3; i++)
        assert_int_equal(lr_control_map_event(f.map, &bad[i], 0), -1);
    assert_int_equal(lr_control_map_garbage(f.map), 3);
    assert_int_equal(update(&f, 0), 0);
    assert_near(get(&f, "light.intensity"), 0.005, 1e-12);
    lr_event huge = ev("sim", "dimmer", LR_EV_DELTA, 1e300, 0);
    assert_int_equal(lr_control_map_event(f.map, &huge, 0), 0);
    lr_event big = ev("sim", "button1", LR_EV_DELTA, 1e18, 0);
    lr_control_map_event(f.map, &big, 0);
    update(&f, 0);
    assert_near(get(&f, "light.intensity"), 0.01, 1e-12);
    fx_free(&f);
}

/* A scene-switch binding asks the rig to load the next file (resolved path). */
static void test_scene_request(void **state)
{
    (void)state;
    fx f;
    fx_make(&f, "[{\"control\": \"button2\", \"param\": \"scene\", \"values\": [\"" LR_SOURCE_CONFIGS
                "/scenes/candle.json\", \"" LR_SOURCE_CONFIGS "/scenes/votive.json\"]}]");
    assert_null(lr_control_map_scene_request(f.map));
    lr_event p = ev("sim", "button2", LR_EV_PRESS, 1, 0);
    assert_int_equal(lr_control_map_event(f.map, &p, 0), 0);
    const char *req = lr_control_map_scene_request(f.map);
    assert_non_null(req);
    assert_string_equal(req, LR_SOURCE_CONFIGS "/scenes/votive.json");
    assert_null(lr_control_map_scene_request(f.map));
    fx_free(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_dimmer_curve_range_fade),
        cmocka_unit_test(test_curves_and_reversed_range),
        cmocka_unit_test(test_encoder_step_accel_clamp),
        cmocka_unit_test(test_material_cycle_keeps_scale),
        cmocka_unit_test(test_colour_times_scale),
        cmocka_unit_test(test_garbage_ignored),
        cmocka_unit_test(test_scene_request),
    };
    if (getenv("LR_TEST_FILTER")) /* e.g. LR_TEST_FILTER='test_soak*' to run one test */
        cmocka_set_test_filter(getenv("LR_TEST_FILTER"));
    return cmocka_run_group_tests(tests, NULL, NULL);
}
