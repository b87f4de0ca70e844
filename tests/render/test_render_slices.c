/* The long GPU passes in slices (render/passes/slice.h): how many slices a frame ends, and a
 * cut at a chosen slice through the renderer's cancellation token.
 *
 *  - an accumulation frame ends K x lights slices in the radiosity pass and
 *    LR_RECV_GRID / LR_SLICE_ROWS per plane receiver in the irradiance pass;
 *  - a change that restarts the maps (LR_CANCEL_RESTART) cuts inside the radiosity pass: the
 *    frame returns LR_ECANCELED at the next slice end, the maps restart (the next frame is
 *    sample 1), and the converged image equals an uncut renderer's;
 *  - a stale state that does not restart them (LR_CANCEL_STALE: a camera move) lets the
 *    radiosity pass end its slices and cuts at the irradiance pass's first band: the frame's
 *    map sample is kept (the next frame is the one after it), and the image converges to the
 *    uncut renderer's;
 *  - without a token nothing is cut, whatever the hook requests;
 *  - with a time budget (lr_renderer_set_slice_ms) the bands are sized from the pass's last
 *    bands: a budget no row fits gives the fewest rows a band may have (LR_SLICE_MAX_BANDS
 *    bands a map and a grid),
 *    one every pass fits gives one band a map and a grid; a cut mid-map under a budget
 *    restarts the maps, and every such frame converges to the uncut image.
 * The converged images are compared exactly (to 1e-6 of the peak): the same seed and the same
 * samples give the same sums. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/cancel.h"
#include "render/core/recv_grid.h"
#include "render/passes/slice.h"
#include "render/renderer.h"
#include "render/renderer_debug.h"
#include "tests/support/gl.h"
#include "tests/support/render.h"

LR_TEST_GL_FIXTURE(gl) /* tests/support/gl.h: setup(), teardown() */

enum { W = 32, H = 24, K = 4, FRAMES = 4 };

/* The candle with its two plane receivers and VPLs (the irradiance pass runs), small maps;
 * no receiver bounce or opening light (CPU solves this test does not cut). */
static const char *const settings[] = {
    "render.K=4",           "render.N=1",          "render.map_size=32",
    "render.gbuffer_size=32", "render.vpl_map_size=16", "render.N_vpl=8",
    "render.frames=4",      "render.receiver_bounce=false", "render.opening_light=false",
    NULL};

static int plane_grids(const lr_scene *s)
{
    int n = 0;
    for (int i = 0; i < lr_scene_receiver_count(s); i++) {
        lr_recv_grid_frame f;
        n += lr_recv_grid_frame_of(lr_scene_receiver_at(s, i), &f);
    }
    return n;
}

/* Requests `token` at `level` when the renderer's slice count reaches `at`. */
typedef struct cutter {
    lr_cancel *token;
    enum lr_cancel_level level;
    long at;
} cutter;

static void cut_at(void *ctx, long slice)
{
    cutter *c = ctx;
    if (slice == c->at)
        lr_cancel_request(c->token, c->level);
}

static double peak(const float *a, size_t n)
{
    double p = 0.0;
    for (size_t i = 0; i < n; i++)
        p = fmax(p, fabs((double)a[i]));
    return p;
}

/* The converged image of a renderer that was never cut (the candle at `settings`, seed 3),
 * made once for the binary; a copy per call. */
static float *uncut;
static float *uncut_image(lr_scene *s)
{
    size_t bytes = (size_t)W * H * 3 * sizeof(float);
    if (!uncut) {
        lr_renderer *r = lr_test_renderer(gl, s, W, H, false, 3);
        lr_test_converge(r, 20);
        uncut = lr_test_hdr(r);
        lr_renderer_destroy(r);
    }
    float *img = malloc(bytes);
    assert_non_null(img);
    memcpy(img, uncut, bytes);
    return img;
}

static void assert_same_image(const float *a, const float *b)
{
    size_t n = (size_t)W * H * 3;
    double p = peak(b, n), worst = 0.0;
    assert_true(p > 0.0);
    for (size_t i = 0; i < n; i++)
        worst = fmax(worst, fabs((double)a[i] - b[i]));
    print_message("converged after the cut against uncut: max |diff| %.3g of peak %.3g\n", worst,
                  p);
    assert_true(worst <= 1e-6 * p);
}

/* A renderer with `token` set, two frames accumulated (sample 2). */
static lr_renderer *tokened(lr_scene *s, lr_cancel *token)
{
    lr_renderer *r = lr_test_renderer(gl, s, W, H, false, 3);
    lr_cancel_init(token);
    lr_renderer_set_cancel(r, token);
    lr_test_frame(r);
    lr_frame_stats st = lr_test_frame(r);
    assert_int_equal(st.samples, 2);
    return r;
}

/* Converges r after its cuts and compares it with the uncut renderer's image; frees both and
 * the scene. */
static void converges_as_uncut(lr_renderer *r, lr_scene *s, float *want)
{
    lr_test_converge(r, 20);
    float *got = lr_test_hdr(r);
    assert_same_image(got, want);
    free(got);
    free(want);
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
}

static void test_slices_per_frame(void **state)
{
    (void)state;
    lr_scene *s = lr_test_scene("candle", settings, NULL);
    int planes = plane_grids(s);
    assert_int_equal(planes, 2);
    lr_renderer *r = lr_test_renderer(gl, s, W, H, false, 3);
    lr_test_frame(r); /* the first: every pass */
    long before = lr_renderer_debug_slices(r);
    lr_frame_stats st = lr_test_frame(r); /* an accumulation frame: maps, VPLs, grids */
    assert_true(st.passes & LR_PASS_RADIOSITY);
    assert_true(st.passes & LR_PASS_IRRADIANCE);
    long n = lr_renderer_debug_slices(r) - before;
    assert_int_equal(n, K * lr_scene_light_count(s) + planes * (LR_RECV_GRID / LR_SLICE_ROWS));
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
}

static void test_restart_cuts_inside_the_maps(void **state)
{
    (void)state;
    lr_scene *s = lr_test_scene("candle", settings, NULL);
    float *want = uncut_image(s);
    lr_cancel token;
    lr_renderer *r = tokened(s, &token);
    lr_frame_stats st;
    /* Third frame: cut after its second map, mid-pass. */
    cutter c = {&token, LR_CANCEL_RESTART, lr_renderer_debug_slices(r) + 2};
    lr_renderer_debug_on_slice(r, cut_at, &c);
    lr_err e = {0};
    assert_int_equal(lr_renderer_frame(r, &st, &e), LR_ECANCELED);
    assert_non_null(strstr(e.msg, "radiosity pass: cancelled"));
    /* Cut at that slice: nothing after it ran. */
    assert_int_equal(lr_renderer_debug_slices(r), c.at);
    lr_renderer_debug_on_slice(r, NULL, NULL);
    lr_cancel_reset(&token);
    st = lr_test_frame(r);
    assert_int_equal(st.samples, 1); /* restarted */
    converges_as_uncut(r, s, want);
}

static void test_stale_cut_keeps_the_maps(void **state)
{
    (void)state;
    lr_scene *s = lr_test_scene("candle", settings, NULL);
    float *want = uncut_image(s);
    lr_cancel token;
    lr_renderer *r = tokened(s, &token);
    lr_frame_stats st;
    /* Requested during the radiosity pass's first slice: the maps end their frame, the cut
     * comes at the poll after the pass. */
    int maps = K * lr_scene_light_count(s);
    long base = lr_renderer_debug_slices(r);
    cutter c = {&token, LR_CANCEL_STALE, base + 1};
    lr_renderer_debug_on_slice(r, cut_at, &c);
    lr_err e = {0};
    assert_int_equal(lr_renderer_frame(r, &st, &e), LR_ECANCELED);
    assert_non_null(strstr(e.msg, "renderer: frame: cancelled"));
    assert_int_equal(lr_renderer_debug_slices(r), base + maps);
    /* Requested at the irradiance pass's first band: cut there. */
    lr_cancel_reset(&token);
    base = lr_renderer_debug_slices(r);
    c.at = base + maps + 1;
    e = (lr_err){0};
    assert_int_equal(lr_renderer_frame(r, &st, &e), LR_ECANCELED);
    assert_non_null(strstr(e.msg, "receiver irradiance pass: cancelled"));
    assert_int_equal(lr_renderer_debug_slices(r), base + maps + 1);
    lr_renderer_debug_on_slice(r, NULL, NULL);
    lr_cancel_reset(&token);
    /* Both cut frames' samples (3 and 4) were kept: this frame runs the VPLs and the grids on
     * the maps as they are (render.frames 4 reached: no fifth sample). */
    st = lr_test_frame(r);
    assert_int_equal(st.samples, FRAMES);
    assert_true(st.passes & LR_PASS_IRRADIANCE);
    assert_false(st.passes & LR_PASS_RADIOSITY);
    converges_as_uncut(r, s, want);
}

static void test_no_token_no_cut(void **state)
{
    (void)state;
    lr_scene *s = lr_test_scene("candle", settings, NULL);
    lr_renderer *r = lr_test_renderer(gl, s, W, H, false, 3);
    lr_cancel token;
    lr_cancel_init(&token);
    lr_test_frame(r);
    cutter c = {&token, LR_CANCEL_STOP, lr_renderer_debug_slices(r) + 1};
    lr_renderer_debug_on_slice(r, cut_at, &c);
    lr_frame_stats st = lr_test_frame(r); /* asserts LR_OK */
    assert_true(lr_cancel_at(&token, LR_CANCEL_STOP)); /* requested, but not the renderer's */
    assert_int_equal(st.samples, 2);
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
}

/* render.irradiance_grid=false: no irradiance pass (no bands), composition gathers the VPLs
 * per receiver pixel; back on, the pass runs and the image is the grid's again, exactly; the
 * receiver bounce keeps the grid on. */
static void test_irradiance_grid_off(void **state)
{
    (void)state;
    lr_scene *s = lr_test_scene("candle", settings, NULL);
    float *grid = uncut_image(s);
    lr_renderer *r = lr_test_renderer(gl, s, W, H, false, 3);
    lr_test_set(s, r, "render.irradiance_grid", "false");
    for (int f = 0; f < FRAMES + 1; f++) {
        long before = lr_renderer_debug_slices(r);
        lr_frame_stats st = lr_test_frame(r);
        assert_false(st.passes & LR_PASS_IRRADIANCE);
        if (st.passes & LR_PASS_RADIOSITY)
            assert_int_equal(lr_renderer_debug_slices(r) - before, K * lr_scene_light_count(s));
    }
    float *pixel = lr_test_hdr(r);
    size_t n = (size_t)W * H * 3;
    {
        lr_renderer *d = lr_test_renderer(gl, s, W, H, true, 3);
        lr_test_converge(d, 20);
        float *direct = lr_test_hdr(d);
        double nv = 0.0, dv = 0.0, sv = 0.0;
        for (size_t i = 0; i < n; i++) {
            double a = (double)pixel[i] - direct[i], b = (double)grid[i] - direct[i];
            nv += (a - b) * (a - b);
            dv += b * b;
            sv += b;
        }
        print_message("VPL part: sum %.6g, relative RMSE %.4g\n", sv, sqrt(nv / dv));
        /* The grid is the same sum at its texel centres, read bilinearly: for E ~ 1/d^2 its
         * error is h^2 |E''| / 8 = (3/4) (h/d)^2 of E, under 5e-3 where d >= 12 h (56 mm at
         * the table's 4.7 mm texels); the pixels nearer the VPLs are few (measured 6.9e-4
         * over the image). The VPL part is ~1 % of the image (emergent light), so compared
         * alone. */
        assert_true(sv > 0.0);
        assert_true(sqrt(nv / dv) <= 5e-3);
        free(direct);
        lr_renderer_destroy(d);
    }
    /* A settings change: the maps restart, the grid is drawn at every frame again. */
    lr_test_set(s, r, "render.irradiance_grid", "true");
    lr_frame_stats st = lr_test_frame(r);
    assert_true(st.passes & LR_PASS_IRRADIANCE);
    lr_test_converge(r, 20);
    float *back = lr_test_hdr(r);
    assert_same_image(back, grid);
    lr_test_set(s, r, "render.irradiance_grid", "false");
    lr_test_set(s, r, "render.receiver_bounce", "true");
    st = lr_test_frame(r);
    assert_true(st.passes & LR_PASS_IRRADIANCE);
    free(back);
    free(pixel);
    free(grid);
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
}

/* Slices in one accumulation frame of r. */
static long frame_slices(lr_renderer *r)
{
    long before = lr_renderer_debug_slices(r);
    lr_frame_stats st = lr_test_frame(r);
    assert_true(st.passes & LR_PASS_RADIOSITY);
    assert_true(st.passes & LR_PASS_IRRADIANCE);
    return lr_renderer_debug_slices(r) - before;
}

static void test_budget_sizes_the_bands(void **state)
{
    (void)state;
    lr_scene *s = lr_test_scene("candle", settings, NULL);
    int lights = lr_scene_light_count(s), planes = plane_grids(s);
    float *want = uncut_image(s);
    lr_cancel token;
    /* A budget under any row's time: after the first frame's estimates, the fewest rows a
     * band may have (a 32-row map: one; the 256-row grid: 8). */
    lr_renderer *r = tokened(s, &token);
    lr_renderer_set_slice_ms(r, 1e-9);
    (void)frame_slices(r); /* the estimates */
    long n = frame_slices(r);
    print_message("budget 1e-9 ms: %ld slices a frame\n", n);
    assert_int_equal(n, (long)(K * lights + planes) * LR_SLICE_MAX_BANDS);
    converges_as_uncut(r, s, want);

    /* A budget every pass fits in: one band a map and a grid. */
    s = lr_test_scene("candle", settings, NULL);
    want = uncut_image(s);
    r = tokened(s, &token);
    lr_renderer_set_slice_ms(r, 1e9);
    (void)frame_slices(r);
    n = frame_slices(r);
    print_message("budget 1e9 ms: %ld slices a frame\n", n);
    assert_int_equal(n, (long)K * lights + planes);
    converges_as_uncut(r, s, want);

    /* Cut at the fifth band of the first map: the maps restart. */
    s = lr_test_scene("candle", settings, NULL);
    want = uncut_image(s);
    r = tokened(s, &token);
    lr_renderer_set_slice_ms(r, 1e-9);
    (void)frame_slices(r);
    cutter c = {&token, LR_CANCEL_RESTART, lr_renderer_debug_slices(r) + 5};
    lr_renderer_debug_on_slice(r, cut_at, &c);
    lr_frame_stats st;
    lr_err e = {0};
    assert_int_equal(lr_renderer_frame(r, &st, &e), LR_ECANCELED);
    assert_non_null(strstr(e.msg, "radiosity pass: cancelled"));
    assert_int_equal(lr_renderer_debug_slices(r), c.at);
    lr_renderer_debug_on_slice(r, NULL, NULL);
    lr_cancel_reset(&token);
    st = lr_test_frame(r);
    assert_int_equal(st.samples, 1); /* restarted */
    converges_as_uncut(r, s, want);
}

int main(void)
{
    if (getenv("LR_TEST_FILTER"))
        cmocka_set_test_filter(getenv("LR_TEST_FILTER"));
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_slices_per_frame),
        cmocka_unit_test(test_restart_cuts_inside_the_maps),
        cmocka_unit_test(test_stale_cut_keeps_the_maps),
        cmocka_unit_test(test_no_token_no_cut),
        cmocka_unit_test(test_irradiance_grid_off),
        cmocka_unit_test(test_budget_sizes_the_bands),
    };
    int failed = cmocka_run_group_tests(tests, setup, teardown);
    free(uncut);
    return failed;
}
