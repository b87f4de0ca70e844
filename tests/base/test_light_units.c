/* Lights in photometric units (render/scene: intensity_cd, flux_lm, color_temperature_k;
 * render/photometry): what the loader derives, what it refuses, and lr_scene_set's dimmer in
 * each unit. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "render/photometry/photometry.h"
#include "render/scene/dirty.h"
#include "render/scene/scene.h"
#include "tests/support/near.h"

/* A scene with one sphere and the light `light` (a JSON object's members after "type"). */
static int parse_light(const char *light, lr_scene **s, lr_err *e)
{
    char t[1024];
    snprintf(t, sizeof t,
             "{\"objects\": [{\"material\": \"candle_wax\", \"mesh\": {\"type\": \"sphere\"}}],\n"
             " \"lights\": [{%s}],\n"
             " \"camera\": {\"position\": [0,-400,0], \"target\": [0,0,0]}}\n", light);
    return lr_scene_parse(t, strlen(t), "t.json", NULL, s, e);
}

static const lr_light *load_light(const char *light, lr_scene **s)
{
    lr_err e = {0};
    if (parse_light(light, s, &e))
        fail_msg("%s: %s", light, e.msg);
    return lr_scene_light_at(*s, 0);
}

static void expect_refused(const char *light, const char *needle)
{
    lr_scene *s = NULL;
    lr_err e = {0};
    if (parse_light(light, &s, &e) == LR_OK)
        fail_msg("accepted: %s", light);
    if (!strstr(e.msg, needle))
        fail_msg("message '%s' lacks '%s'", e.msg, needle);
}

/* Y(1, 1, 1) = 1 (D65 is RGB white), so a white 1 cd point is 1/683 W/sr and 4 pi lm; every
 * step is a product or quotient of doubles: 1e-12 relative. */
static void test_point_candela(void **state)
{
    (void)state;
    lr_scene *s;
    const lr_light *l = load_light("\"type\": \"point\", \"position\": [0,0,100], "
                                   "\"intensity_cd\": 1", &s);
    assert_near_rel(l->intensity, 1.0 / LR_KM_LM_PER_W, 1e-12);
    assert_near_rel(l->flux_lm, 4.0 * M_PI, 1e-12);
    assert_near_rel(l->intensity_cd, 1.0, 1e-12);
    lr_scene_destroy(s);
}

/* A candle: 12 lm at 1900 K. intensity_cd = 12 / 4 pi; the colour's luminous part is K(T), so
 * intensity = cd / K(1900 K), the visible W/sr. */
static void test_point_lumens_at_colour_temperature(void **state)
{
    (void)state;
    lr_scene *s;
    const lr_light *l = load_light("\"type\": \"point\", \"position\": [0,0,100], "
                                   "\"flux_lm\": 12, \"color_temperature_k\": 1900", &s);
    double k = lr_planck_efficacy(1900.0);
    assert_near_rel(l->intensity_cd, 12.0 / (4.0 * M_PI), 1e-12);
    assert_near_rel(l->intensity, 12.0 / (4.0 * M_PI) / k, 1e-12);
    assert_near_rel(LR_KM_LM_PER_W * lr_rgb_luminance(l->color), k, 1e-12);
    /* Warm: red above green above blue. */
    assert_true(l->color[0] > l->color[1] && l->color[1] > l->color[2]);
    lr_scene_destroy(s);
}

/* A spot's flux against lr_light_shape integrated over the sphere: the midpoint rule in
 * cos(theta) with 2e5 cells on the smoothstep band (the only non-constant part; the flat
 * cap and the dark rest are exact). The midpoint rule's error is h^2/24 max|f''| per unit
 * length; smoothstep's f'' <= 6 / (ci - co)^2 in t, so with h = (ci - co) / 2e5 the relative
 * error is < 6 / (24 * 4e10) ~ 1e-11: 1e-9 allowed. */
static void test_spot_lumens(void **state)
{
    (void)state;
    lr_scene *s;
    const lr_light *l = load_light("\"type\": \"spot\", \"position\": [0,0,200], "
                                   "\"direction\": [0,0,-1], \"inner_deg\": 20, "
                                   "\"outer_deg\": 35, \"flux_lm\": 500", &s);
    double ci = cos(20.0 * M_PI / 180.0), co = cos(35.0 * M_PI / 180.0);
    int n = 200000;
    double h = (ci - co) / n, band = 0.0;
    for (int i = 0; i < n; i++) {
        double c = co + (i + 0.5) * h, sn = sqrt(1.0 - c * c);
        band += lr_light_shape(l, lr_v3(sn, 0.0, -c)) * h;
    }
    double omega = 2.0 * M_PI * ((1.0 - ci) + band);
    assert_near_rel(l->intensity_cd * omega, 500.0, 1e-9);
    lr_scene_destroy(s);
}

/* A Lambertian quad of half-edges 50 and 10 mm (area 2000 mm^2), one-sided: flux = pi A L_v,
 * so L_v = 800 / (2000 pi) cd/mm^2 and the radiance L_v / 683 (white); two-sided half. */
static void test_area_lumens(void **state)
{
    (void)state;
    lr_scene *s;
    const lr_light *l = load_light("\"type\": \"quad\", \"position\": [0,0,200], "
                                   "\"edge_u\": [50,0,0], \"edge_v\": [0,10,0], "
                                   "\"flux_lm\": 800", &s);
    assert_near_rel(l->intensity, 800.0 / (2000.0 * M_PI) / LR_KM_LM_PER_W, 1e-12);
    assert_near(l->intensity_cd, 0.0, 0.0);
    lr_scene_destroy(s);
    l = load_light("\"type\": \"disk\", \"position\": [0,0,200], \"normal\": [0,0,-1], "
                   "\"radius\": 10, \"two_sided\": true, \"flux_lm\": 800", &s);
    assert_near_rel(l->intensity, 800.0 / (2.0 * M_PI * 100.0 * M_PI) / LR_KM_LM_PER_W, 1e-12);
    lr_scene_destroy(s);
}

static void test_refusals(void **state)
{
    (void)state;
    expect_refused("\"type\": \"point\", \"position\": [0,0,100], \"intensity\": 1,\n"
                   "\"intensity_cd\": 1",
                   "t.json:3: field 'lights[0].intensity_cd': give one of intensity, "
                   "intensity_cd, flux_lm, not both 'intensity' and 'intensity_cd'");
    expect_refused("\"type\": \"point\", \"position\": [0,0,100]",
                   "field 'lights[0]': missing its strength (required: one of intensity, "
                   "intensity_cd, flux_lm)");
    expect_refused("\"type\": \"disk\", \"position\": [0,0,100], \"radius\": 5, "
                   "\"normal\": [0,0,-1]", "(required: one of radiance, flux_lm)");
    expect_refused("\"type\": \"directional\", \"direction\": [0,0,-1], \"flux_lm\": 5",
                   "unknown field");
    expect_refused("\"type\": \"point\", \"position\": [0,0,100], \"intensity\": 1, "
                   "\"color\": [1,1,1], \"color_temperature_k\": 2700",
                   "give one of color and color_temperature_k, not both");
    expect_refused("\"type\": \"point\", \"position\": [0,0,100], \"intensity\": 1, "
                   "\"color_temperature_k\": 500", "color_temperature_k': must be");
    expect_refused("\"type\": \"point\", \"position\": [0,0,100], \"intensity_cd\": 1, "
                   "\"color\": [0,0,0]", "needs a colour with a luminous part");
}

static void set_ok(lr_scene *s, const char *key, const char *value, unsigned want)
{
    unsigned d = 0;
    lr_err e = {0};
    if (lr_scene_set(s, key, value, &d, &e))
        fail_msg("set %s=%s: %s", key, value, e.msg);
    if (d != want)
        fail_msg("set %s: dirty %#x, expected %#x", key, d, want);
}

/* The dimmer in any unit: the unit set last is the one the others follow. */
static void test_set_units(void **state)
{
    (void)state;
    lr_scene *s;
    const lr_light *l = load_light("\"type\": \"spot\", \"position\": [0,0,200], "
                                   "\"direction\": [0,0,-1], \"intensity_cd\": 100, "
                                   "\"color_temperature_k\": 2700", &s);
    double i0 = l->intensity;
    set_ok(s, "light.intensity_cd", "50", LR_DIRTY_INTENSITY);
    assert_near_rel(l->intensity, 0.5 * i0, 1e-12);
    /* Candela kept when the cone widens: the on-axis intensity stays, the flux grows. */
    double f0 = l->flux_lm;
    set_ok(s, "light.outer_deg", "45", LR_DIRTY_LIGHT_GEOMETRY);
    assert_near_rel(l->intensity, 0.5 * i0, 1e-12);
    assert_true(l->flux_lm > f0);
    /* Lumens kept when the cone widens: the intensity falls (a change of the dimmer too). */
    set_ok(s, "light.flux_lm", "300", LR_DIRTY_INTENSITY);
    double i1 = l->intensity;
    set_ok(s, "light.outer_deg", "60", LR_DIRTY_LIGHT_GEOMETRY | LR_DIRTY_INTENSITY);
    assert_true(l->intensity < i1);
    assert_near_rel(l->flux_lm, 300.0, 1e-12);
    /* Warmer at the same lumens: the colour and the W/sr both change. */
    set_ok(s, "light.color_temperature_k", "1900", LR_DIRTY_INTENSITY);
    assert_near_rel(LR_KM_LM_PER_W * lr_rgb_luminance(l->color), lr_planck_efficacy(1900.0),
                    1e-12);
    assert_near_rel(l->flux_lm, 300.0, 1e-12);
    /* A colour replaces the temperature; the W/sr set last are kept, the lumens follow. */
    set_ok(s, "light.intensity", "0.5", LR_DIRTY_INTENSITY);
    set_ok(s, "light.color", "1,1,1", LR_DIRTY_INTENSITY);
    assert_near(l->color_temperature_k, 0.0, 0.0);
    assert_near_rel(l->intensity, 0.5, 1e-12);
    assert_near_rel(l->intensity_cd, 0.5 * LR_KM_LM_PER_W, 1e-12);
    /* A derived strength beyond its field's range is no error: 1e11 W/sr of a colour with
     * Y = 1e5 is ~6.8e18 cd, past intensity_cd's 1e15, and the next change still passes. */
    set_ok(s, "light.color", "1e5,1e5,1e5", LR_DIRTY_INTENSITY);
    set_ok(s, "light.intensity", "1e11", LR_DIRTY_INTENSITY);
    assert_true(l->intensity_cd > 1e18);
    set_ok(s, "light.outer_deg", "50", LR_DIRTY_LIGHT_GEOMETRY);
    set_ok(s, "light.color", "1,1,1", LR_DIRTY_INTENSITY);
    set_ok(s, "light.intensity", "0.5", LR_DIRTY_INTENSITY);
    char buf[64];
    lr_err e = {0};
    assert_int_equal(lr_scene_get(s, "light.intensity_cd", buf, sizeof buf, &e), LR_OK);
    double v;
    assert_int_equal(sscanf(buf, "%lf", &v), 1);
    assert_near_rel(v, 341.5, 1e-8);
    lr_scene_destroy(s);
}

/* render.exposure_ev: the multiplier follows it (exposure read back = lr_ev_to_exposure),
 * a set of exposure takes over again (exposure_ev read back = its EV), both in a file are
 * refused. */
static void test_exposure_ev_field(void **state)
{
    (void)state;
    char t[512];
    snprintf(t, sizeof t,
             "{\"objects\": [{\"material\": \"candle_wax\", \"mesh\": {\"type\": \"sphere\"}}],\n"
             " \"lights\": [{\"type\": \"point\", \"position\": [0,0,100], \"intensity\": 1}],\n"
             " \"camera\": {\"position\": [0,-400,0], \"target\": [0,0,0]},\n"
             " \"render\": {\"exposure_ev\": 8}}\n");
    lr_scene *s;
    lr_err e = {0};
    if (lr_scene_parse(t, strlen(t), "t.json", NULL, &s, &e))
        fail_msg("%s", e.msg);
    assert_near_rel(lr_scene_render(s)->exposure, lr_ev_to_exposure(8.0), 1e-12);
    set_ok(s, "render.exposure_ev", "9", LR_DIRTY_DISPLAY);
    assert_near_rel(lr_scene_render(s)->exposure, 0.5 * lr_ev_to_exposure(8.0), 1e-12);
    set_ok(s, "render.exposure", "3e6", LR_DIRTY_DISPLAY);
    assert_near(lr_scene_render(s)->exposure_ev, lr_exposure_to_ev(3e6), 1e-12);
    lr_scene_destroy(s);
    char *p = strstr(t, "\"exposure_ev\": 8");
    strcpy(p + 15, "8,\n\"exposure\": 1}}\n");
    assert_int_equal(lr_scene_parse(t, strlen(t), "t.json", NULL, &s, &e), LR_EINVAL);
    if (!strstr(e.msg, "t.json:4: field 'render.exposure_ev': give one of exposure and "
                       "exposure_ev, not both"))
        fail_msg("%s", e.msg);
}

/* The shipped candle's flame and the shade's bulb are given in candela and lumens: the
 * numbers are the old W/sr times 683 lm/W x Y(color) (x 4 pi for the bulb's lumens), printed
 * to the 17 digits that give back the old intensity bit for bit, so every renderer sees the
 * same doubles and the images are unchanged, not only to 8-bit rounding:
 *   flame 0.005 W/sr, color 1, 0.55, 0.2 (Y 0.620420): 2.1187351273381263 cd
 *   bulb  0.25 W/sr, color 1, 0.78, 0.52 (Y 0.808011): 1733.754588262603 lm.
 * The colours stay: the Planckian colours at 1900 K (1, 0.23, 0 in linear sRGB) and 2700 K
 * (1, 0.42, 0.10) are far deeper than the scenes' tuned ones, so color_temperature_k would
 * change the images. */
static void test_shipped_scenes_map_exactly(void **state)
{
    (void)state;
    static const struct { const char *file; double intensity, color[3]; } sc[] = {
        {"candle.json", 0.005, {1.0, 0.55, 0.2}}, {"lampshade.json", 0.25, {1.0, 0.78, 0.52}}};
    for (int i = 0; i < 2; i++) {
        char path[512];
        snprintf(path, sizeof path, "%s/scenes/%s", LR_SOURCE_CONFIGS, sc[i].file);
        lr_scene *s;
        lr_err e = {0};
        if (lr_scene_load(path, NULL, &s, &e))
            fail_msg("%s", e.msg);
        const lr_light *l = lr_scene_light_at(s, 0);
        assert_true(l->from != LR_STRENGTH_RADIOMETRIC);
        assert_true(l->intensity == sc[i].intensity);
        assert_memory_equal(l->color, sc[i].color, sizeof l->color);
        lr_scene_destroy(s);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_point_candela),
        cmocka_unit_test(test_point_lumens_at_colour_temperature),
        cmocka_unit_test(test_spot_lumens),
        cmocka_unit_test(test_area_lumens),
        cmocka_unit_test(test_refusals),
        cmocka_unit_test(test_set_units),
        cmocka_unit_test(test_exposure_ev_field),
        cmocka_unit_test(test_shipped_scenes_map_exactly),
    };
    return cmocka_run_group_tests_name("light_units", tests, NULL, NULL);
}
