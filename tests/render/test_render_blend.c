/* The per-light image cache and the blend pass (issue 11, render/passes/blend.h).
 *
 * Composition writes one linear image per light at unit intensity; the blend pass weights them
 * with intensity x colour x flicker and tone-maps. A dimmer, colour or flicker change must give
 * the image a full re-render with the new values gives. Both sides compute the same per-light
 * images (the per-texel seeds do not depend on the intensity or on the light's index) and the
 * same weighted sum, so they agree to float rounding: asserted to 1e-5 relative per value
 * (plus 1e-7 of the image's largest value for values near 0), and the tone-mapped bytes
 * to one step; the bytes are also the exact output curve of the linear sum to one step (the
 * pass encodes sRGB with lr_srgb_encode_fast). Each dimmer/flicker frame must run the blend pass
 * alone.
 *
 *  - one light: dimmed after convergence, and dimmed in the middle of accumulation (the next
 *    accumulation frames update the per-light images, the blend reads the new intensity);
 *  - two lights (point flame and spot): one dimmed, the other's colour changed;
 *  - a light switched off (weight 0: its image is not read) equals the re-render without it;
 *  - flicker: a clock time with a flickering flame against a steady flame whose intensity is
 *    the flickering one's at that time.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/renderer.h"
#include "tests/support/gl.h"
#include "tests/support/render.h"

LR_TEST_GL_FIXTURE(gl) /* tests/support/gl.h: setup(), teardown() */

enum { W = 40, H = 30, SEED = 7 };

static const char *const flame =
    "{\"type\": \"point\", \"name\": \"flame\", \"position\": [0, 0, 117], \"intensity\": %s,"
    " \"color\": [%s], \"flicker\": {\"amplitude\": %s, \"frequency_hz\": 9, \"seed\": 3}}";
static const char *const side =
    "{\"type\": \"spot\", \"name\": \"side\", \"position\": [160, -160, 170], \"direction\":"
    " [-0.6, 0.6, -0.5], \"inner_deg\": 20, \"outer_deg\": 30, \"intensity\": %s,"
    " \"color\": [0.6, 0.7, 1.0]}";

/* The candle on a table before a wall; the flame's intensity, colour and flicker amplitude,
 * and the side spot's intensity (NULL: no side spot). */
static lr_scene *scene(const char *I, const char *color, const char *amp, const char *side_I)
{
    char l0[512], l1[512] = "", t[4096];
    snprintf(l0, sizeof l0, flame, I, color, amp);
    if (side_I)
        snprintf(l1, sizeof l1, side, side_I);
    snprintf(t, sizeof t,
             "{\"objects\": [{\"name\": \"pillar\", \"material\": \"candle_wax\", \"mesh\": "
             "{\"type\": \"candle\", \"radius\": 35, \"height\": 120, \"pool_depth\": 8}}],\n"
             " \"lights\": [%s%s%s],\n"
             " \"camera\": {\"position\": [0, -450, 230], \"target\": [0, 40, 70], \"fov_deg\": 40},\n"
             " \"render\": {\"exposure\": 1.5e7},\n"
             " \"receivers\": [{\"name\": \"table\", \"type\": \"plane\", \"center\": [0, -75, 0],"
             " \"normal\": [0, 0, 1], \"size\": [1200, 650], \"albedo\": [0.75, 0.72, 0.68]},\n"
             "  {\"name\": \"wall\", \"type\": \"plane\", \"center\": [0, 250, 400], \"normal\":"
             " [0, -1, 0], \"size\": [1200, 800], \"albedo\": [0.85, 0.85, 0.83]}]}",
             l0, side_I ? ", " : "", l1);
    return lr_test_scene_text(t, lr_test_small_settings);
}

static unsigned char *ldr(lr_renderer *r)
{
    unsigned char *p = malloc((size_t)W * H * 4);
    lr_err e = {0};
    assert_non_null(p);
    if (lr_renderer_read_rgba8(r, p, &e))
        fail_msg("read_rgba8: %s", e.msg);
    return p;
}

/* A fresh renderer on s, converged: the full re-render. */
static void rerender(lr_scene *s, float **hdr, unsigned char **bytes)
{
    lr_renderer *r = lr_test_renderer(gl, s, W, H, false, SEED);
    lr_test_converge(r, 20);
    *hdr = lr_test_hdr(r);
    *bytes = ldr(r);
    lr_renderer_destroy(r);
}

/* The displayed bytes are the exact output curve of the linear sum to one step; returns how
 * many are one step off. The pass encodes with lr_srgb_encode_fast (within a quarter step of
 * the exact encode, test_image), so bytes drawn from other images than the linear sum's (a
 * stale cache) fail here. rgba8 rows are top-down, the HDR rows bottom-up (GL order). */
static int bytes_off_curve(const char *what, lr_renderer *r, const float *got,
                           const unsigned char *got_bytes)
{
    lr_tonemap tm;
    lr_renderer_tonemap(r, &tm);
    int off = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int c = 0; c < 3; c++) {
                float v = got[3 * ((H - 1 - y) * W + x) + c];
                int a = (int)lrintf(lr_srgb_encode(lr_tonemap_apply(&tm, v)) * 255.0f);
                int b = got_bytes[4 * (y * W + x) + c];
                if (abs(a - b) > 1)
                    fail_msg("%s: pixel %d,%d band %d: byte %d, the exact curve %d", what, x,
                             y, c, b, a);
                off += a != b;
            }
    return off;
}

/* got equals want to 1e-5 relative per value (1e-7 of the largest value near 0), the
 * tone-mapped bytes exactly, and the image is lit (the check is not vacuous). */
static void assert_same(const char *what, lr_renderer *r, const float *want,
                        const unsigned char *want_bytes)
{
    float *got = lr_test_hdr(r);
    unsigned char *got_bytes = ldr(r);
    double mx = 0.0, worst = 0.0;
    int lit = 0;
    for (int i = 0; i < W * H * 3; i++) {
        mx = fmax(mx, want[i]);
        lit += want[i] > 0.0f;
    }
    for (int i = 0; i < W * H * 3; i++) {
        double d = fabs((double)got[i] - want[i]);
        if (!(d <= 1e-5 * fabs(want[i]) + 1e-7 * mx))
            fail_msg("%s: value %d: %.9g, the re-render %.9g", what, i, got[i], want[i]);
        if (want[i] > 0.0f)
            worst = fmax(worst, d / want[i]);
    }
    assert_true(lit > W * H);
    /* The bytes: equal, or one step apart where a weight rounded differently in its last
     * float bit put the value on the other side of a rounding boundary. */
    for (int i = 0; i < W * H * 4; i++)
        if (abs((int)got_bytes[i] - (int)want_bytes[i]) > 1)
            fail_msg("%s: byte %d: %d, the re-render %d", what, i, got_bytes[i], want_bytes[i]);
    int off = bytes_off_curve(what, r, got, got_bytes);
    print_message("%s: worst relative difference %.3g; %d of %d bytes one step from the "
                  "exact curve\n", what, worst, off, W * H * 3);
    free(got);
    free(got_bytes);
}

static void test_one_light_dimmer(void **state)
{
    (void)state;
    lr_scene *sb = scene("0.002", "1.0, 0.55, 0.2", "0", NULL);
    float *want;
    unsigned char *want_bytes;
    rerender(sb, &want, &want_bytes);

    /* After convergence: the blend alone. */
    lr_scene *s = scene("0.005", "1.0, 0.55, 0.2", "0", NULL);
    lr_renderer *r = lr_test_renderer(gl, s, W, H, false, SEED);
    lr_test_converge(r, 20);
    lr_test_set(s, r, "lights[flame].intensity", "0.002");
    lr_frame_stats st = lr_test_frame(r);
    assert_int_equal(st.passes, LR_PASS_BLEND);
    assert_false(lr_renderer_needs_frame(r));
    assert_same("dimmed after convergence", r, want, want_bytes);
    /* A camera move recomposes the images: the next displayed frame must show the new view,
     * and its bytes must follow the new images. */
    unsigned char *before = ldr(r);
    lr_test_set(s, r, "camera.position", "[300, -300, 150]");
    st = lr_test_frame(r);
    assert_true(st.passes & LR_PASS_COMPOSE);
    float *moved = lr_test_hdr(r);
    unsigned char *moved_bytes = ldr(r);
    int changed = 0;
    for (int i = 0; i < W * H * 4; i++)
        changed += moved_bytes[i] != before[i];
    print_message("after a camera move: %d of %d bytes changed\n", changed, W * H * 4);
    assert_true(changed > W * H / 4); /* the view did change on screen */
    bytes_off_curve("after a camera move", r, moved, moved_bytes);
    lr_test_set(s, r, "camera.position", "[0, -450, 230]"); /* the scene of the next part */
    free(before);
    free(moved);
    free(moved_bytes);
    lr_renderer_destroy(r);

    /* In the middle of accumulation: after the first of the two frames. The dimmer frame is
     * also the second accumulation frame (maps, VPLs and per-light images updated, then the
     * blend with the new intensity). */
    r = lr_test_renderer(gl, s, W, H, false, SEED);
    lr_test_frame(r);
    lr_test_set(s, r, "lights[flame].intensity", "0.002");
    st = lr_test_frame(r);
    assert_int_equal(st.passes, LR_PASS_RADIOSITY | LR_PASS_VPL | LR_PASS_IRRADIANCE |
                                    LR_PASS_COMPOSE | LR_PASS_BLEND);
    assert_true(st.converged);
    assert_same("dimmed during accumulation", r, want, want_bytes);
    lr_renderer_destroy(r);

    free(want);
    free(want_bytes);
    lr_scene_destroy(s);
    lr_scene_destroy(sb);
}

static void test_two_lights_dimmer_and_colour(void **state)
{
    (void)state;
    lr_scene *sb = scene("0.005", "0.9, 0.7, 0.3", "0", "0.005");
    float *want;
    unsigned char *want_bytes;
    rerender(sb, &want, &want_bytes);

    lr_scene *s = scene("0.005", "1.0, 0.55, 0.2", "0", "0.02");
    lr_renderer *r = lr_test_renderer(gl, s, W, H, false, SEED);
    lr_test_converge(r, 20);
    lr_test_set(s, r, "lights[side].intensity", "0.005");
    lr_frame_stats st = lr_test_frame(r);
    assert_int_equal(st.passes, LR_PASS_BLEND);
    lr_test_set(s, r, "lights[flame].color", "0.9,0.7,0.3");
    st = lr_test_frame(r);
    assert_int_equal(st.passes, LR_PASS_BLEND);
    assert_same("two lights: side dimmed, flame recoloured", r, want, want_bytes);
    lr_renderer_destroy(r);
    free(want);
    free(want_bytes);
    lr_scene_destroy(s);
    lr_scene_destroy(sb);
}

/* A light switched off (weight 0) is not read by the blend pass; the image is the one of the
 * scene without its light's contribution: the re-render with intensity 0. */
static void test_light_switched_off(void **state)
{
    (void)state;
    lr_scene *sb = scene("0.005", "1.0, 0.55, 0.2", "0", "0");
    float *want;
    unsigned char *want_bytes;
    rerender(sb, &want, &want_bytes);

    lr_scene *s = scene("0.005", "1.0, 0.55, 0.2", "0", "0.02");
    lr_renderer *r = lr_test_renderer(gl, s, W, H, false, SEED);
    lr_test_converge(r, 20);
    lr_test_set(s, r, "lights[side].intensity", "0");
    lr_frame_stats st = lr_test_frame(r);
    assert_int_equal(st.passes, LR_PASS_BLEND);
    assert_same("two lights: side switched off", r, want, want_bytes);
    lr_renderer_destroy(r);
    free(want);
    free(want_bytes);
    lr_scene_destroy(s);
    lr_scene_destroy(sb);
}

static void test_flicker_equals_steady_rerender(void **state)
{
    (void)state;
    lr_scene *s = scene("0.005", "1.0, 0.55, 0.2", "0.3", NULL);
    lr_renderer *r = lr_test_renderer(gl, s, W, H, false, SEED);
    lr_test_converge(r, 20);
    const double times[] = {0.11, 2.37};
    for (size_t i = 0; i < sizeof times / sizeof times[0]; i++) {
        lr_renderer_set_time(r, times[i]);
        lr_frame_stats st = lr_test_frame(r);
        assert_int_equal(st.passes, LR_PASS_BLEND);
        double f = lr_renderer_flicker(r, 0);
        assert_true(fabs(f - 1.0) > 1e-3); /* the flame does flicker at this time */
        char I[64];
        snprintf(I, sizeof I, "%.17g", 0.005 * f);
        lr_scene *sb = scene(I, "1.0, 0.55, 0.2", "0", NULL);
        float *want;
        unsigned char *want_bytes;
        rerender(sb, &want, &want_bytes);
        char what[64];
        snprintf(what, sizeof what, "flicker at t = %.2f s (factor %.4f)", times[i], f);
        assert_same(what, r, want, want_bytes);
        free(want);
        free(want_bytes);
        lr_scene_destroy(sb);
    }
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_one_light_dimmer),
        cmocka_unit_test(test_two_lights_dimmer_and_colour),
        cmocka_unit_test(test_light_switched_off),
        cmocka_unit_test(test_flicker_equals_steady_rerender),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
