/* Change-driven scheduling (docs/ARCHITECTURE.md "Data flow", render/renderer.h): which passes each kind of
 * change re-runs, that a dimmer change rescales the image exactly, and that accumulation stops
 * at render.frames. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "render/renderer.h"
#include "render/renderer_debug.h"
#include "tests/support/gl.h"
#include "tests/support/near.h"
#include "tests/support/render.h"

#define W 48
#define H 36

enum {
    ALL = LR_PASS_GBUFFER | LR_PASS_RADIOSITY | LR_PASS_VPL | LR_PASS_IRRADIANCE |
          LR_PASS_COMPOSE | LR_PASS_BLEND,
    MAPS = LR_PASS_RADIOSITY | LR_PASS_VPL | LR_PASS_IRRADIANCE | LR_PASS_COMPOSE | LR_PASS_BLEND,
    VIEW = LR_PASS_COMPOSE | LR_PASS_BLEND,
};

typedef struct fixture {
    lr_gl *gl;
    lr_scene *s;
    lr_renderer *r;
} fixture;

static int setup(void **state)
{
    static fixture f;
    if (lr_test_gl_create(&f.gl))
        return -1;
    *state = &f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = *state;
    lr_gl_destroy(f->gl);
    return 0;
}

static int each_setup(void **state)
{
    fixture *f = *state;
    f->s = lr_test_scene("candle", lr_test_small_settings, NULL);
    f->r = lr_test_renderer(f->gl, f->s, W, H, false, 1);
    return 0;
}

static int each_teardown(void **state)
{
    fixture *f = *state;
    lr_renderer_destroy(f->r);
    lr_scene_destroy(f->s);
    return 0;
}

/* First frame runs everything, then accumulation (radiosity, VPLs, composition) until
 * render.frames = 2; then nothing is due. */
static void test_accumulates_until_converged(void **state)
{
    fixture *f = *state;
    assert_true(lr_renderer_needs_frame(f->r));
    lr_frame_stats a = lr_test_frame(f->r);
    assert_int_equal(a.passes, ALL);
    assert_int_equal(a.samples, 1);
    assert_false(a.converged);
    assert_int_equal(a.index, 0);
    for (int i = 0; i < LR_PASS_COUNT; i++)
        assert_true(a.ms[i] >= 0.0);
    assert_true(lr_renderer_needs_frame(f->r));
    lr_frame_stats b = lr_test_frame(f->r);
    assert_int_equal(b.passes, MAPS);
    assert_int_equal(b.samples, 2);
    assert_true(b.converged);
    assert_false(lr_renderer_needs_frame(f->r));
    /* A frame with nothing due runs nothing. */
    lr_frame_stats c = lr_test_frame(f->r);
    assert_int_equal(c.passes, 0);
    assert_int_equal(c.samples, 2);
}

/* The dimmer: the blend pass alone, and the HDR image scales by the intensity ratio. The GPU
 * multiplies the float intensity into products of three or four float factors; the ratio of
 * two such images differs from the ratio of the intensities by at most ~8 roundings of 2^-24:
 * 5e-7 relative; we allow 1e-6. */
static void test_dimmer_runs_blend_only_and_scales(void **state)
{
    fixture *f = *state;
    lr_test_converge(f->r, 8);
    float *before = lr_test_hdr(f->r);
    lr_test_set(f->s, f->r, "light.intensity", "0.002"); /* from 0.005 */
    assert_true(lr_renderer_needs_frame(f->r));
    lr_frame_stats st = lr_test_frame(f->r);
    assert_int_equal(st.passes, LR_PASS_BLEND);
    assert_int_equal(st.samples, 2);
    assert_false(lr_renderer_needs_frame(f->r));
    float *after = lr_test_hdr(f->r);
    double ratio = 0.002 / 0.005;
    int lit = 0;
    for (int i = 0; i < W * H * 3; i++) {
        assert_near(after[i], ratio * before[i], 1e-6 * ratio * before[i]);
        lit += before[i] > 0.0f;
    }
    assert_true(lit > W * H); /* most of the image is lit: the check is not vacuous */
    free(before);
    free(after);
}

/* render.lpv: the volume's row (lpv) runs on the first frame with everything, not while the
 * maps accumulate; a dimmer turn is still the blend alone and scales the image exactly (the
 * volume's light on the receivers and objects is per unit intensity); a camera move runs
 * composition alone; a material change makes it due with the maps. The dirty mapping:
 * transport, material, receivers and settings make it due, camera, intensity and display not. */
static void test_lpv_row(void **state)
{
    fixture *f = *state;
    assert_true(lr_dirty_passes(LR_DIRTY_MATERIAL) & LR_PASS_LPV);
    assert_true(lr_dirty_passes(LR_DIRTY_RECEIVERS) & LR_PASS_LPV);
    assert_true(lr_dirty_passes(LR_DIRTY_LIGHT_GEOMETRY) & LR_PASS_LPV);
    assert_true(lr_dirty_passes(LR_DIRTY_GEOMETRY | LR_DIRTY_SETTINGS) & LR_PASS_LPV);
    assert_false(lr_dirty_passes(LR_DIRTY_CAMERA | LR_DIRTY_INTENSITY | LR_DIRTY_DISPLAY) &
                 LR_PASS_LPV);
    assert_string_equal(lr_pass_name(7), "lpv");
    lr_test_set(f->s, f->r, "render.lpv", "8");
    lr_frame_stats a = lr_test_frame(f->r);
    assert_int_equal(a.passes, ALL | LR_PASS_LPV);
    assert_true(a.ms[7] >= 0.0);
    lr_frame_stats b = lr_test_frame(f->r);
    assert_int_equal(b.passes, MAPS);
    float *before = lr_test_hdr(f->r);
    lr_test_set(f->s, f->r, "light.intensity", "0.002"); /* from 0.005 */
    lr_frame_stats c = lr_test_frame(f->r);
    assert_int_equal(c.passes, LR_PASS_BLEND);
    float *after = lr_test_hdr(f->r);
    for (int i = 0; i < W * H * 3; i++)
        assert_near(after[i], 0.4 * before[i], 1e-6 * 0.4 * before[i]);
    /* A camera move on converged maps: the surface cache first (render.surface_cache_moves). */
    lr_test_set(f->s, f->r, "camera.position", "20,-300,160");
    assert_int_equal(lr_test_frame(f->r).passes, LR_PASS_SURFACE | VIEW);
    lr_test_set(f->s, f->r, "objects[0].material", "marble");
    lr_frame_stats d = lr_test_frame(f->r);
    assert_true(d.passes & LR_PASS_LPV);
    assert_true(d.passes & LR_PASS_RADIOSITY);
    free(before);
    free(after);
}

static void test_camera_runs_compose_only(void **state)
{
    fixture *f = *state;
    lr_test_converge(f->r, 8);
    /* A move on converged maps composes from the objects' surface cache (drawn now, from the
     * maps: view-independent), the frame after it with the per-pixel gather
     * (render.surface_cache_moves, render/README.md "Camera moves"). */
    lr_test_set(f->s, f->r, "camera.position", "100,-400,250");
    lr_frame_stats st = lr_test_frame(f->r);
    assert_int_equal(st.passes, LR_PASS_SURFACE | VIEW);
    assert_int_equal(st.samples, 2);
    assert_false(lr_renderer_debug_compose_gathered(f->r));
    assert_true(lr_renderer_needs_frame(f->r));
    assert_int_equal(lr_test_frame(f->r).passes, VIEW);
    assert_true(lr_renderer_debug_compose_gathered(f->r));
    assert_false(lr_renderer_needs_frame(f->r));
    /* The next move finds the cache current: composition and blend alone. */
    lr_test_set(f->s, f->r, "camera.position", "100,-380,250");
    assert_int_equal(lr_test_frame(f->r).passes, VIEW);
    assert_int_equal(lr_test_frame(f->r).passes, VIEW);
    lr_test_set(f->s, f->r, "render.surface_cache_moves", "false");
    lr_test_set(f->s, f->r, "camera.position", "100,-400,250");
    assert_int_equal(lr_test_frame(f->r).passes, VIEW);
    assert_true(lr_renderer_debug_compose_gathered(f->r));
    assert_false(lr_renderer_needs_frame(f->r));
    lr_test_set(f->s, f->r, "render.exposure", "1e6");
    assert_int_equal(lr_test_frame(f->r).passes, LR_PASS_BLEND);
    /* Receivers: their irradiance grids, then the view. */
    lr_test_set(f->s, f->r, "receivers[table].albedo", "0.5,0.5,0.5");
    assert_int_equal(lr_test_frame(f->r).passes, LR_PASS_IRRADIANCE | VIEW);
}

static void test_material_runs_maps_vpl_compose(void **state)
{
    fixture *f = *state;
    lr_test_converge(f->r, 8);
    lr_test_set(f->s, f->r, "objects[pillar].material.scale", "0.6");
    lr_frame_stats st = lr_test_frame(f->r);
    assert_int_equal(st.passes, MAPS);
    assert_int_equal(st.samples, 1); /* accumulation restarted */
    assert_true(lr_renderer_needs_frame(f->r));
}

static void test_light_move_runs_everything(void **state)
{
    fixture *f = *state;
    lr_test_converge(f->r, 8);
    lr_test_set(f->s, f->r, "light.position", "0,0,116");
    lr_frame_stats st = lr_test_frame(f->r);
    assert_int_equal(st.passes, ALL);
    assert_int_equal(st.samples, 1);
    lr_test_set(f->s, f->r, "render.map_size", "32");
    st = lr_test_frame(f->r);
    assert_int_equal(st.passes, ALL);
    assert_int_equal(st.samples, 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_accumulates_until_converged, each_setup, each_teardown),
        cmocka_unit_test_setup_teardown(test_dimmer_runs_blend_only_and_scales, each_setup, each_teardown),
        cmocka_unit_test_setup_teardown(test_lpv_row, each_setup, each_teardown),
        cmocka_unit_test_setup_teardown(test_camera_runs_compose_only, each_setup, each_teardown),
        cmocka_unit_test_setup_teardown(test_material_runs_maps_vpl_compose, each_setup, each_teardown),
        cmocka_unit_test_setup_teardown(test_light_move_runs_everything, each_setup, each_teardown),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
