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

#include <glob.h>
#include <limits.h>

#include "firmware/control/accel.h"
#include "firmware/control/curve.h"
#include "firmware/rig/ahead.h"
#include "firmware/rig/config.h"
#include "firmware/rig/control_map.h"
#include "render/cpu/frame.h"
#include "render/image/image.h"
#include "render/passes/passes.h"
#include "render/photometry/photometry.h"
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

/* A reload's map takes over the old map's level positions (the Modbus demo's lamp went back to
 * the config's initial level and faded to the panel again: 51 -> 128 -> 51 of 255 after every
 * SIGHUP): the dimmer stays at the panel's position, shown at once, and the panel's next read
 * of the same value is no event. A binding the old map lacks starts as configured; cycles
 * start as configured. */
static void test_reload_carries_positions(void **state)
{
    (void)state;
    const char *ctl = "[{\"name\": \"dimmer\", \"control\": \"panel/dimmer\", "
                      "\"param\": \"light.level\", \"range\": [0, 2], \"fade_s\": 0.15, "
                      "\"initial\": 0.5, \"lamp\": true}, "
                      "{\"name\": \"material\", \"control\": \"button1\", "
                      "\"param\": \"objects[0].material\", \"values\": [\"candle_wax\", "
                      "\"marble\"]}]";
    fx a, b;
    fx_make(&a, ctl);
    update(&a, 0);
    int64_t t0 = 1000 * MS;
    lr_event e1 = ev("panel", "dimmer", LR_EV_ABSOLUTE, 0.2, t0);
    assert_int_equal(lr_control_map_event(a.map, &e1, t0), 0);
    lr_event press = ev("", "button1", LR_EV_PRESS, 1, t0);
    assert_int_equal(lr_control_map_event(a.map, &press, t0), 1);
    update(&a, t0 + 500 * MS);
    double la;
    assert_true(lr_control_map_lamp_level(a.map, t0 + 500 * MS, &la));
    assert_near(la, 0.2, 1e-12);

    fx_make(&b, ctl); /* the reloaded config */
    assert_near(lr_control_map_position(b.map, 0), 0.5, 1e-12);
    int64_t t1 = t0 + 600 * MS;
    lr_control_map_carry(b.map, a.map, t1);
    assert_near(lr_control_map_position(b.map, 0), 0.2, 1e-12);
    double lb;
    assert_true(lr_control_map_lamp_level(b.map, t1, &lb));
    assert_near(lb, 0.2, 1e-12);
    assert_false(lr_control_map_fading(b.map, t1));
    update(&b, t1);
    assert_near(get(&b, "lights[0].intensity"), get(&a, "lights[0].intensity"), 1e-15);
    lr_event same = ev("panel", "dimmer", LR_EV_ABSOLUTE, 0.2, t1 + 50 * MS);
    assert_int_equal(lr_control_map_event(b.map, &same, t1 + 50 * MS), -1);
    assert_int_equal(lr_control_map_index(b.map, 1), 0); /* the cycle as configured */
    fx_free(&a);
    fx_free(&b);
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

/* One dimmer in a designer's units driving two parameters: the light's candela (linear) and
 * its colour temperature (warm-dim, 1800..2700 K): at 0.5 the flame is 2 cd and
 * 1800 + 900 x 0.5^(0.42/3.38) = 2624 K; the renderer's W/sr follow both (cd / K(T)). The
 * values go through lr_scene_set's %.9g text: 1e-6 relative. */
static void test_dimmer_in_candela_and_warm_dim(void **state)
{
    (void)state;
    fx f;
    fx_make(&f, "[{\"control\": \"dimmer\", \"param\": \"light.intensity_cd\", "
                "\"range\": [0, 4], \"initial\": 1},\n"
                " {\"control\": \"dimmer\", \"param\": \"light.color_temperature_k\", "
                "\"range\": [1800, 2700], \"curve\": \"warm-dim\", \"initial\": 1}]");
    update(&f, 0);
    assert_near_rel(get(&f, "light.intensity_cd"), 4.0, 1e-6);
    assert_near_rel(get(&f, "light.color_temperature_k"), 2700.0, 1e-6);
    lr_event e = ev("sim", "dimmer", LR_EV_ABSOLUTE, 0.5, 10 * MS);
    assert_int_equal(lr_control_map_event(f.map, &e, 10 * MS), 0);
    update(&f, 10 * MS);
    double t = 1800.0 + 900.0 * pow(0.5, 0.42 / 3.38);
    assert_near_rel(get(&f, "light.intensity_cd"), 2.0, 1e-6);
    assert_near_rel(get(&f, "light.color_temperature_k"), t, 1e-6);
    assert_near_rel(get(&f, "light.intensity"), 2.0 / lr_planck_efficacy(t), 1e-5);
    fx_free(&f);
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

/* A light's level (param "light.level") multiplies the light's own intensity in the scene as
 * loaded: the same dimmer position is the same fraction of each scene's light. The candle's
 * flame is 0.005 W/sr, the lamp shade's bulb 0.25 W/sr; range [0, 2] with the square curve:
 * the scene's own light at y = 0.5 (x = sqrt 0.5), twice it at full. */
static void test_light_level_follows_each_scene(void **state)
{
    (void)state;
    fx f;
    fx_make(&f, "[{\"control\": \"dimmer\", \"param\": \"light.level\", \"range\": [0, 2], "
                "\"curve\": \"square\", \"lamp\": true}]");
    assert_near(lr_control_map_position(f.map, 0), sqrt(0.5), 1e-12);
    update(&f, 0);
    assert_near(get(&f, "light.intensity"), 0.005, 1e-12);
    lr_event e1 = ev("sim", "dimmer", LR_EV_ABSOLUTE, 1.0, 0);
    assert_int_equal(lr_control_map_event(f.map, &e1, 0), 0);
    update(&f, 0);
    assert_near(get(&f, "light.intensity"), 0.01, 1e-12);

    /* The scene switch: a fresh lamp shade scene; its own bulb, not the candle's number. */
    lr_scene_destroy(f.scene);
    lr_err e = {0};
    if (lr_scene_load(LR_SOURCE_CONFIGS "/scenes/lampshade.json", NULL, &f.scene, &e))
        fail_msg("%s", e.msg);
    lr_control_map_scene_replaced(f.map);
    update(&f, 0);
    assert_near(get(&f, "light.intensity"), 0.5, 1e-12);
    lr_event e2 = ev("sim", "dimmer", LR_EV_ABSOLUTE, 0.5, 0);
    lr_control_map_event(f.map, &e2, 0);
    unsigned dirty = update(&f, 0);
    assert_true(dirty != 0);
    assert_near(get(&f, "light.intensity"), 0.25 * 2 * 0.25, 1e-12); /* y = 0.5^2 */
    double lamp;
    assert_true(lr_control_map_lamp_level(f.map, 0, &lamp));
    assert_near(lamp, 0.25, 1e-12);
    /* Back to a candle: 0.25 of twice 0.005. */
    lr_scene_destroy(f.scene);
    if (lr_scene_load(SCENE, NULL, &f.scene, &e))
        fail_msg("%s", e.msg);
    lr_control_map_scene_replaced(f.map);
    update(&f, 0);
    assert_near(get(&f, "light.intensity"), 0.0025, 1e-12);
    fx_free(&f);
}

static void expect_map_error(const char *controls, const char *msg)
{
    char text[4096];
    snprintf(text, sizeof text,
             "{\"scene\": \"%s\", \"devices\": [{\"type\": \"sim\", \"text\": \"0 x press\"}], "
             "\"controls\": %s}",
             SCENE, controls);
    lr_rig_config *cfg;
    lr_scene *scene;
    lr_control_map *map = NULL;
    lr_err e = {0};
    if (lr_rig_config_parse(text, "test-rig.json", &cfg, &e) ||
        lr_scene_load(SCENE, NULL, &scene, &e))
        fail_msg("%s", e.msg);
    assert_int_not_equal(lr_control_map_create(cfg, scene, true, 0, &map, &e), LR_OK);
    if (!strstr(e.msg, msg))
        fail_msg("'%s' does not say '%s'", e.msg, msg);
    lr_scene_destroy(scene);
    lr_rig_config_destroy(cfg);
}

static void test_light_level_errors(void **state)
{
    (void)state;
    expect_map_error("[{\"control\": \"b\", \"param\": \"light.level\", \"values\": [\"1\"]}]",
                     "test-rig.json:1: field 'controls[0].param': a light's level follows a "
                     "position: give 'range', not 'values'");
    expect_map_error("[{\"control\": \"b\", \"param\": \"light.level\", "
                     "\"colors\": [[1, 1, 1], [0, 0, 0]]}]",
                     "field 'controls[0].colors': a light's level is a number");
    expect_map_error("[{\"control\": \"b\", \"param\": \"lights[nope].level\"}]",
                     "field 'controls[0].param': 'lights[nope].level' is a light's level relative "
                     "to its own intensity or radiance: lights[nope].intensity: no lights named "
                     "'nope'");
    /* The upper end is checked against the scene's limits like any range. */
    expect_map_error("[{\"control\": \"b\", \"param\": \"light.level\", \"range\": [-1, 1]}]",
                     "field 'controls[0].range': the scene rejects the lower end = -0.005");
}

static bool same_file(const char *a, const char *b)
{
    char ra[PATH_MAX], rb[PATH_MAX];
    return realpath(a, ra) && realpath(b, rb) && strcmp(ra, rb) == 0;
}

/* The dimmer's bindings of a config: level bindings on a light's strength. */
static bool is_dimmer(const lr_rig_binding *b)
{
    size_t n = strlen(b->param);
    return b->kind == LR_BIND_LEVEL && strncmp(b->param, "light", 5) == 0 &&
           ((n > 6 && strcmp(b->param + n - 6, ".level") == 0) ||
            (n > 10 && strcmp(b->param + n - 10, ".intensity") == 0) ||
            (n > 9 && strcmp(b->param + n - 9, ".radiance") == 0));
}

static double light_strength(const lr_scene *s)
{
    char buf[128];
    if (lr_scene_get(s, "light.intensity", buf, sizeof buf, NULL) &&
        lr_scene_get(s, "light.radiance", buf, sizeof buf, NULL))
        fail_msg("%s: no light strength", lr_scene_path(s));
    return strtod(buf, NULL);
}

/* Mean display value (0..1, ACES at the scene's exposure) of the CPU twin's image of s with
 * its radiance times k: a 32 x 24 pass, one frame, direct light only (cheap). */
static double mean_display(const lr_image *img, double exposure, double k)
{
    lr_tonemap tm = {LR_RENDER_TONEMAP, (float)exposure};
    double sum = 0;
    size_t n = (size_t)img->width * (size_t)img->height * 3;
    for (size_t i = 0; i < n; i++)
        sum += lr_tonemap_apply(&tm, (float)(img->rgb[i] * k));
    return sum / (double)n;
}

/* Every scene of every shipped config's cycle (the rig configs in configs/rig, with the
 * control-map files in configs/controls they use), loaded as the rig loads it on a scene
 * switch, with the dimmer at its full level, shows a visible image: its mean display value at
 * least half of what the scene's own light gives at the scene's own exposure (the renderer is
 * linear in the light, so one render gives both; the scene's own is at least 1/255). The old
 * candle map's light.intensity 0..0.01 W/sr gave the lamp shade (0.25 W/sr, exposure 2e5)
 * 0.04 of its own light at full: 0.1/255 against 8.6/255. Every configs/controls file is
 * reached by some rig config. */
static void test_shipped_cycles_are_visible(void **state)
{
    (void)state;
    glob_t rigs, maps;
    assert_int_equal(glob(LR_SOURCE_CONFIGS "/rig/*.json", 0, NULL, &rigs), 0);
    assert_int_equal(glob(LR_SOURCE_CONFIGS "/controls/*.json", 0, NULL, &maps), 0);
    bool reached[64] = {false};
    assert_true(maps.gl_pathc <= 64);
    int checked = 0;
    for (size_t ri = 0; ri < rigs.gl_pathc; ri++) {
        lr_rig_config *cfg;
        lr_err e = {0};
        if (lr_rig_config_load(rigs.gl_pathv[ri], &cfg, &e))
            fail_msg("%s", e.msg);
        const char *scenes[LR_RIG_MAX_VALUES + 1] = {cfg->scene};
        int n_scenes = 1, dimmer = -1;
        for (int i = 0; i < cfg->n_bindings; i++) {
            const lr_rig_binding *b = &cfg->bindings[i];
            for (size_t k = 0; k < maps.gl_pathc; k++)
                reached[k] |= same_file(b->file, maps.gl_pathv[k]);
            if (strcmp(b->param, "scene") == 0)
                for (int k = 0; k < b->n_values; k++)
                    if (!same_file(b->values[k], cfg->scene))
                        scenes[n_scenes++] = b->values[k];
            if (is_dimmer(b))
                dimmer = i;
        }
        assert_true(dimmer >= 0);
        lr_scene *scene;
        lr_control_map *map;
        if (lr_scene_load(cfg->scene, NULL, &scene, &e) ||
            lr_rig_config_apply_sets(cfg, scene, &e) ||
            lr_control_map_create(cfg, scene, true, 0, &map, &e))
            fail_msg("%s: %s", rigs.gl_pathv[ri], e.msg);
        lr_event full = ev("", cfg->bindings[dimmer].control, LR_EV_ABSOLUTE, 1.0, 0);
        if (cfg->bindings[dimmer].source[0])
            snprintf(full.source, sizeof full.source, "%s", cfg->bindings[dimmer].source);
        lr_control_map_event(map, &full, 0);
        for (int si = 0; si < n_scenes; si++) {
            if (si > 0) { /* the rig's scene switch: load, the config's sets, the map again */
                lr_scene_destroy(scene);
                if (lr_scene_load(scenes[si], NULL, &scene, &e) ||
                    lr_rig_config_apply_sets(cfg, scene, &e))
                    fail_msg("%s", e.msg);
                lr_control_map_scene_replaced(map);
            }
            lr_scene *own = NULL;
            if (lr_scene_load(scenes[si], NULL, &own, &e))
                fail_msg("%s", e.msg);
            double own_strength = light_strength(own);
            lr_scene_destroy(own);
            unsigned dirty = 0;
            if (lr_control_map_update(map, scene, 60 * 1000 * MS, &dirty, &e)) /* fades done */
                fail_msg("%s", e.msg);
            double at_full = light_strength(scene);
            assert_true(at_full > 0);
            lr_cpu_render_desc d = {.scene = scene, .width = 32, .height = 24,
                                    .mode = LR_CPU_PASS, .frames = 1, .K = 4, .map_size = 32,
                                    .N = 4, .vpl_count = 8, .no_vpl = true, .threads = 1};
            lr_image img;
            lr_cpu_render_stats st;
            if (lr_cpu_render(&d, &img, NULL, &st, &e))
                fail_msg("%s", e.msg);
            double exposure = lr_scene_render(scene)->exposure;
            double mean = mean_display(&img, exposure, 1.0);
            double mean_own = mean_display(&img, exposure, own_strength / at_full);
            printf("%s: %s: light %.4g at full (own %.4g), mean %.1f/255 (own light %.1f/255), "
                   "%.2f s\n", strrchr(rigs.gl_pathv[ri], '/') + 1, strrchr(scenes[si], '/') + 1,
                   at_full, own_strength, 255 * mean, 255 * mean_own, st.seconds);
            assert_true(mean_own >= 1.0 / 255);
            assert_true(mean >= 0.5 * mean_own);
            lr_image_free(&img);
            checked++;
        }
        lr_control_map_destroy(map);
        lr_scene_destroy(scene);
        lr_rig_config_destroy(cfg);
    }
    for (size_t k = 0; k < maps.gl_pathc; k++)
        if (!reached[k])
            fail_msg("%s: no rig config uses this control map", maps.gl_pathv[k]);
    assert_true(checked >= 4);
    globfree(&rigs);
    globfree(&maps);
}

/* The control space built ahead (firmware/rig/ahead.h) of the candle's map: the keys are the
 * controls that change transport (the preset, the scale both knob and tint write) and the
 * re-planner's, not the dimmer's or the flicker's; a what-if moves one control in a copy and
 * leaves the map and the live scene as they were; the list is the state shown, the other
 * presets (next first) and the samples of each continuous control, one state per step, all
 * different states. */
static void test_states_ahead(void **state)
{
    (void)state;
    fx f;
    fx_make(&f, "[{\"control\": \"dimmer\", \"param\": \"light.level\", \"range\": [0, 2]},"
                " {\"control\": \"knob1\", \"param\": \"lights[0].flicker.amplitude\", "
                "\"range\": [0, 0.5]},"
                " {\"control\": \"button1\", \"param\": \"objects[0].material\", "
                "\"values\": [\"candle_wax\", \"marble\", \"porcelain\"]},"
                " {\"control\": \"knob2\", \"param\": \"objects[0].material.scale\", "
                "\"range\": [0.25, 4], \"curve\": \"log\", \"initial\": 0.5},"
                " {\"control\": \"tint\", \"param\": \"objects[0].material.scale\", "
                "\"colors\": [[1, 1, 1], [0.7, 1, 1.6]], \"initial\": 0}]");
    update(&f, 0);
    lr_cache_key keys[LR_CACHE_MAX_KEYS];
    int nk = 0;
    lr_err e = {0};
    assert_int_equal(lr_rig_ahead_keys(f.map, f.scene, keys, LR_CACHE_MAX_KEYS, &nk, &e), LR_OK);
    bool mat = false, scale = false, model = false, settings = false;
    for (int k = 0; k < nk; k++) {
        mat |= !strcmp(keys[k].name, "objects[0].material") && keys[k].interp == LR_CACHE_EXACT;
        scale |= !strcmp(keys[k].name, "objects[0].material.scale") &&
                 keys[k].interp == LR_CACHE_LINEAR;
        model |= !strcmp(keys[k].name, "objects[0].model");
        settings |= !strcmp(keys[k].name, "render.map_size");
        assert_null(strstr(keys[k].name, "intensity"));
        assert_null(strstr(keys[k].name, "flicker"));
    }
    assert_true(mat && scale && model && settings);
    assert_int_equal(nk, 3 + 6);

    /* A what-if on a copy: the preset moves there, the map and the live scene stay. */
    lr_scene *copy = NULL;
    assert_int_equal(lr_scene_clone(f.scene, NULL, &copy, &e), LR_OK);
    double s0 = get(&f, "objects[0].material.scale");
    unsigned d = 0;
    assert_int_equal(lr_control_map_what_if(f.map, 2, 1, copy, 0, &d, &e), LR_OK);
    assert_true(d & LR_DIRTY_MATERIAL);
    char buf[64];
    lr_scene_get(copy, "objects[0].material", buf, sizeof buf, NULL);
    assert_string_equal(buf, "marble");
    lr_scene_get(copy, "objects[0].material.scale", buf, sizeof buf, NULL);
    assert_near(strtod(buf, NULL), s0, 1e-6); /* the knob's scale written again after it */
    lr_scene_get(f.scene, "objects[0].material", buf, sizeof buf, NULL);
    assert_string_equal(buf, "candle_wax");
    assert_int_equal(lr_control_map_index(f.map, 2), 0);
    lr_scene_destroy(copy);

    lr_rig_ahead *h;
    assert_int_equal(lr_rig_ahead_create(5, &h, &e), LR_OK);
    lr_rig_ahead_changed(h, 0);
    assert_false(lr_rig_ahead_due(h, 100 * MS)); /* resting */
    assert_true(lr_rig_ahead_due(h, 400 * MS));
    const lr_async_state *st = NULL;
    int n = 0, steps = 0;
    bool done = false;
    while (!done) {
        int before = n;
        assert_int_equal(lr_rig_ahead_step(h, f.map, f.scene, NULL, 400 * MS, &st, &n, &done, &e),
                         LR_OK);
        assert_true(n <= before + 1);
        steps++;
        assert_true(steps < 100);
    }
    /* The state shown, 2 other presets, 5 knob samples and 5 tint samples, less the knob's
     * and the tint's sample at their current positions (0.5 and 0): a what-if that writes
     * nothing is the state shown, listed once, first. */
    assert_int_equal(n, 1 + 2 + 4 + 4);
    assert_int_equal(st[0].n, 0);
    assert_string_equal(st[1].key[0], "objects[0].material");
    assert_string_equal(st[1].value[0], "marble"); /* the next one first */
    assert_string_equal(st[2].value[0], "porcelain");
    /* Every state applied on a copy gives a state the copy takes, with the scale in range. */
    for (int i = 0; i < n; i++) {
        lr_scene *c = NULL;
        assert_int_equal(lr_scene_clone(f.scene, NULL, &c, &e), LR_OK);
        for (int k = 0; k < st[i].n; k++)
            if (lr_scene_set(c, st[i].key[k], st[i].value[k], NULL, &e))
                fail_msg("state %d: %s", i, e.msg);
        double v[3];
        lr_scene_get(c, "objects[0].material.scale", buf, sizeof buf, NULL);
        int nv = sscanf(buf, "%lf,%lf,%lf", &v[0], &v[1], &v[2]);
        assert_true(nv >= 1);
        assert_true(v[0] >= 0.25 * 0.7 - 1e-9 && v[0] <= 4 * 1.6 + 1e-9);
        lr_scene_destroy(c);
    }
    assert_false(lr_rig_ahead_due(h, 500 * MS)); /* done until the next change */
    lr_rig_ahead_changed(h, 600 * MS);
    assert_true(lr_rig_ahead_due(h, 1000 * MS));
    lr_rig_ahead_destroy(h);
    fx_free(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_reload_carries_positions),
        cmocka_unit_test(test_dimmer_curve_range_fade),
        cmocka_unit_test(test_curves_and_reversed_range),
        cmocka_unit_test(test_dimmer_in_candela_and_warm_dim),
        cmocka_unit_test(test_encoder_step_accel_clamp),
        cmocka_unit_test(test_material_cycle_keeps_scale),
        cmocka_unit_test(test_colour_times_scale),
        cmocka_unit_test(test_garbage_ignored),
        cmocka_unit_test(test_scene_request),
        cmocka_unit_test(test_light_level_follows_each_scene),
        cmocka_unit_test(test_light_level_errors),
        cmocka_unit_test(test_shipped_cycles_are_visible),
        cmocka_unit_test(test_states_ahead),
    };
    if (getenv("LR_TEST_FILTER")) /* e.g. LR_TEST_FILTER='test_soak*' to run one test */
        cmocka_set_test_filter(getenv("LR_TEST_FILTER"));
    return cmocka_run_group_tests(tests, NULL, NULL);
}
