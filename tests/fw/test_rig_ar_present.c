/* Spatial AR on the projector (firmware/rig/ar_present.h), on the headless GL context: the
 * compensated frame is uploaded, drawn full-screen into an offscreen RGBA8 framebuffer (the
 * KMS path draws the same into framebuffer 0) and read back; every pixel must equal the 8-bit
 * level of the PNG path exactly, with the image's top row at the top of the framebuffer. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <GLES3/gl31.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "firmware/rig/ar_present.h"
#include "render/gl/tex.h"
#include "tests/support/gl.h"

LR_TEST_GL_FIXTURE(g_gl) /* tests/support/gl.h: setup(), teardown() */

/* Levels with every value distinct enough to catch a flip, a shift or a channel swap, and
 * some outside 0..1 (clipped). */
static void fill_levels(lr_image *img, int w, int h)
{
    lr_err e = {0};
    assert_int_equal(lr_image_alloc(img, w, h, &e), LR_OK);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            float *p = img->rgb + 3 * ((size_t)y * w + x);
            p[0] = (float)x / (float)(w - 1);
            p[1] = (float)y / (float)(h - 1);
            p[2] = (float)((x * 7 + y * 13) % 29) / 27.0f - 0.02f; /* a little below 0, above 1 */
        }
}

/* Draws the frame into a w x h RGBA8 framebuffer and reads it back (rows bottom-up). */
static uint8_t *draw_readback(lr_ar_present *p, int w, int h)
{
    lr_err e = {0};
    lr_tex *t = NULL;
    lr_fb *fb = NULL;
    lr_tex_desc td = {.format = LR_TEX_RGBA8, .width = w, .height = h, .label = "ar target"};
    assert_int_equal(lr_tex_create(g_gl, &td, &t, &e), LR_OK);
    lr_fb_desc fd = {.color = {{t, 0}}, .label = "ar target"};
    assert_int_equal(lr_fb_create(g_gl, &fd, &fb, &e), LR_OK);
    lr_fb_bind(fb);
    glClearColor(0.5f, 0.5f, 0.5f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    int rc = lr_ar_present_draw(p, w, h, &e);
    if (rc)
        fail_msg("draw: %s", e.msg);
    uint8_t *px = malloc((size_t)w * h * 4);
    assert_non_null(px);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, px);
    assert_int_equal(lr_gl_check("readback", &e), LR_OK);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    lr_fb_destroy(fb);
    lr_tex_destroy(t);
    return px;
}

static void test_levels_to_rgb8(void **state)
{
    (void)state;
    lr_image img;
    fill_levels(&img, 5, 3);
    uint8_t out[5 * 3 * 3];
    lr_ar_levels_to_rgb8(&img, out);
    for (size_t k = 0; k < sizeof out; k++) {
        double v = img.rgb[k] < 0 ? 0 : img.rgb[k] > 1 ? 1 : img.rgb[k];
        assert_int_equal(out[k], (int)lrint(255 * v));
    }
    lr_image_free(&img);
}

/* Same size: NEAREST, every pixel exact, top row on top. Odd width: rows of 3 * 37 bytes are
 * not 4-aligned, so a wrong unpack alignment would shear the image. */
static void test_exact(void **state)
{
    (void)state;
    enum { W = 37, H = 23 };
    lr_err e = {0};
    lr_ar_present *p = NULL;
    int rc = lr_ar_present_create(g_gl, &p, &e);
    if (rc)
        fail_msg("create: %s", e.msg);
    lr_image img;
    fill_levels(&img, W, H);
    uint8_t want[W * H * 3];
    lr_ar_levels_to_rgb8(&img, want);
    assert_int_equal(lr_ar_present_upload(p, &img, &e), LR_OK);
    uint8_t *got = draw_readback(p, W, H);
    int bad = 0;
    for (int y = 0; y < H; y++)          /* GL row y is the image's row H - 1 - y */
        for (int x = 0; x < W; x++)
            for (int k = 0; k < 3; k++) {
                int g = got[4 * ((size_t)y * W + x) + k];
                int w = want[3 * ((size_t)(H - 1 - y) * W + x) + k];
                if (g != w && bad++ < 5)
                    print_error("pixel (%d,%d) ch %d: got %d want %d\n", x, H - 1 - y, k, g, w);
            }
    assert_int_equal(bad, 0);
    free(got);

    /* A second frame replaces the first (another size too). */
    lr_image_free(&img);
    fill_levels(&img, 8, 4);
    for (size_t k = 0; k < 8 * 4 * 3; k++)
        img.rgb[k] = 1.0f - img.rgb[k];
    uint8_t want2[8 * 4 * 3];
    lr_ar_levels_to_rgb8(&img, want2);
    assert_int_equal(lr_ar_present_upload(p, &img, &e), LR_OK);
    got = draw_readback(p, 8, 4);
    for (int y = 0; y < 4; y++)
        for (int x = 0; x < 8; x++)
            for (int k = 0; k < 3; k++)
                assert_int_equal(got[4 * (y * 8 + x) + k], want2[3 * ((3 - y) * 8 + x) + k]);
    free(got);

    /* lr_ar_present_show on surfaceless: no default framebuffer (0 x 0), uploads and flushes. */
    assert_int_equal(lr_ar_present_show(p, &img, &e), LR_OK);
    lr_image_free(&img);
    lr_ar_present_destroy(p);
}

/* Another size than the frame (calibrated projector != KMS mode): stretched over the whole
 * target, no border. Left column black, right column white. */
static void test_stretch(void **state)
{
    (void)state;
    lr_err e = {0};
    lr_ar_present *p = NULL;
    assert_int_equal(lr_ar_present_create(g_gl, &p, &e), LR_OK);
    lr_image img;
    assert_int_equal(lr_image_alloc(&img, 2, 2, &e), LR_OK);
    for (int y = 0; y < 2; y++)
        for (int k = 0; k < 3; k++)
            img.rgb[3 * (y * 2 + 1) + k] = 1.0f;
    assert_int_equal(lr_ar_present_upload(p, &img, &e), LR_OK);
    enum { W = 16, H = 6 };
    uint8_t *got = draw_readback(p, W, H);
    for (int y = 0; y < H; y++) {
        assert_int_equal(got[4 * (y * W)], 0);
        assert_int_equal(got[4 * (y * W + W - 1)], 255);
        for (int x = 1; x < W; x++) /* monotone across, so nothing of the grey clear remains */
            assert_true(got[4 * (y * W + x)] >= got[4 * (y * W + x - 1)]);
    }
    free(got);
    lr_image_free(&img);
    lr_ar_present_destroy(p);
}

static void test_errors(void **state)
{
    (void)state;
    lr_err e = {0};
    lr_ar_present *p = NULL;
    assert_int_equal(lr_ar_present_create(g_gl, &p, &e), LR_OK);
    assert_int_equal(lr_ar_present_draw(p, 4, 4, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "no frame uploaded"));
    lr_image empty = {0};
    assert_int_equal(lr_ar_present_upload(p, &empty, &e), LR_EINVAL);
    lr_ar_present_destroy(p);
    lr_ar_present_destroy(NULL);

    /* Shaders not found: a clear error, nothing allocated. */
    setenv("LAMPRIG_SHADERS", "/nonexistent/shaders", 1);
    p = (lr_ar_present *)&e; /* must be reset */
    int rc = lr_ar_present_create(g_gl, &p, &e);
    unsetenv("LAMPRIG_SHADERS");
    assert_int_not_equal(rc, LR_OK);
    assert_null(p);
    assert_non_null(strstr(e.msg, "spatial AR output"));
    assert_non_null(strstr(e.msg, "fullscreen.vert"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_levels_to_rgb8),
        cmocka_unit_test(test_exact),
        cmocka_unit_test(test_stretch),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
