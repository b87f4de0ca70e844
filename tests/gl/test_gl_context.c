/* GL context on surfaceless EGL (Mesa llvmpipe here, V3D on the SBC): version, capabilities,
 * error reporting; and capability parsing against made-up drivers. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <GLES3/gl31.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/gl/gl.h"

static bool driver_has(const char *name)
{
    GLint n = 0;
    glGetIntegerv(GL_NUM_EXTENSIONS, &n);
    for (GLint i = 0; i < n; i++)
        if (strcmp((const char *)glGetStringi(GL_EXTENSIONS, (GLuint)i), name) == 0)
            return true;
    return false;
}

static void surfaceless_context_is_gles31_with_caps(void **state)
{
    lr_gl *gl = NULL;
    lr_err e = {0};
    int rc = lr_gl_create(NULL, &gl, &e);
    if (rc)
        fail_msg("lr_gl_create: %s", e.msg);
    const lr_gl_caps *c = lr_gl_caps_get(gl);
    print_message("GL_VERSION  %s\nGL_RENDERER %s\n", c->version, c->renderer);

    assert_string_equal(lr_gl_backend_name(gl), "surfaceless");
    assert_int_equal(lr_gl_backend_of(gl), LR_GL_SURFACELESS);
    assert_true(c->major > 3 || (c->major == 3 && c->minor >= 1));
    assert_int_equal(strncmp(c->version, "OpenGL ES ", 10), 0);
    assert_string_equal(c->version, (const char *)glGetString(GL_VERSION));
    assert_true(c->renderer[0] != '\0');

    /* The flags agree with what the driver lists, core features counted. */
    bool es32 = c->major > 3 || c->minor >= 2;
    assert_int_equal(c->color_buffer_float, es32 || driver_has("GL_EXT_color_buffer_float"));
    assert_int_equal(c->color_buffer_half_float,
                     c->color_buffer_float || driver_has("GL_EXT_color_buffer_half_float"));
    assert_int_equal(c->texture_float_linear, driver_has("GL_OES_texture_float_linear"));
    assert_int_equal(c->timer_query, driver_has("GL_EXT_disjoint_timer_query"));
    assert_int_equal(c->float_blend, driver_has("GL_EXT_float_blend"));
    /* The minimum values GLES 3.1 requires of every implementation. */
    assert_true(c->max_texture_size >= 2048);
    assert_true(c->max_cube_map_size >= 2048);
    assert_true(c->max_array_layers >= 256);
    assert_true(c->max_color_attachments >= 4);
    assert_true(c->max_draw_buffers >= 4);

    if (strstr(c->renderer, "llvmpipe")) {
        /* Mesa 22 llvmpipe is known to have all of them; the passes rely on it in CI. */
        assert_true(c->color_buffer_float && c->color_buffer_half_float && c->texture_float_linear &&
                    c->float_blend && c->timer_query);
        assert_int_equal(lr_gl_caps_require(c, LR_GL_NEED_FLOAT_RT | LR_GL_NEED_HALF_FLOAT_RT |
                                                   LR_GL_NEED_FLOAT_LINEAR | LR_GL_NEED_FLOAT_BLEND |
                                                   LR_GL_NEED_TIMER,
                                            &e),
                         LR_OK);
    }

    /* Headless: no default framebuffer, nothing to flip. */
    int w = -1, h = -1;
    lr_gl_size(gl, &w, &h);
    assert_int_equal(w, 0);
    assert_int_equal(h, 0);
    assert_int_equal(lr_gl_event_fd(gl), -1);
    assert_false(lr_gl_flip_pending(gl));
    assert_int_equal(lr_gl_present(gl, &e), LR_OK);
    assert_int_equal(lr_gl_dispatch(gl, &e), LR_OK);
    assert_int_equal(lr_gl_make_current(gl, &e), LR_OK);
    lr_gl_destroy(gl);
}

static void context_can_be_recreated(void **state)
{
    /* The firmware restarts its output after errors: create/destroy must be repeatable. */
    for (int i = 0; i < 2; i++) {
        lr_gl *gl = NULL;
        lr_err e = {0};
        if (lr_gl_create(&(lr_gl_desc){.backend = LR_GL_SURFACELESS}, &gl, &e))
            fail_msg("round %d: %s", i, e.msg);
        assert_non_null(lr_gl_caps_get(gl)->renderer);
        lr_gl_destroy(gl);
    }
}

/* Draws into a framebuffer object and reads it back: the context is a working one. */
static void clear_and_read_back(float r, float g, float b)
{
    GLuint tex = 0, fb = 0;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA8, 4, 4);
    glGenFramebuffers(1, &fb);
    glBindFramebuffer(GL_FRAMEBUFFER, fb);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
    assert_int_equal(glCheckFramebufferStatus(GL_FRAMEBUFFER), GL_FRAMEBUFFER_COMPLETE);
    glClearColor(r, g, b, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    unsigned char px[4] = {0};
    glReadPixels(1, 2, 1, 1, GL_RGBA, GL_UNSIGNED_BYTE, px);
    /* Unorm8 stores round(255 x): within one code. */
    assert_true(abs(px[0] - (int)(255.0f * r + 0.5f)) <= 1);
    assert_true(abs(px[1] - (int)(255.0f * g + 0.5f)) <= 1);
    assert_true(abs(px[2] - (int)(255.0f * b + 0.5f)) <= 1);
    assert_int_equal(px[3], 255);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDeleteFramebuffers(1, &fb);
    glDeleteTextures(1, &tex);
}

/* The EGL-device back end (NVIDIA's headless path) on Mesa's software device, which Mesa lists
 * through the same EGL_EXT_device_enumeration: a GLES 3.1 context that renders. */
static void device_backend_renders(void **state)
{
    lr_gl *gl = NULL;
    lr_err e = {0};
    if (lr_gl_create(&(lr_gl_desc){.backend = LR_GL_DEVICE}, &gl, &e))
        fail_msg("lr_gl_create(device): %s", e.msg);
    assert_string_equal(lr_gl_backend_name(gl), "device");
    assert_int_equal(lr_gl_backend_of(gl), LR_GL_DEVICE);
    const lr_gl_caps *c = lr_gl_caps_get(gl);
    assert_true(c->major > 3 || (c->major == 3 && c->minor >= 1));
    int w = -1, h = -1;
    lr_gl_size(gl, &w, &h);
    assert_int_equal(w, 0);
    assert_int_equal(lr_gl_event_fd(gl), -1);
    clear_and_read_back(0.25f, 0.5f, 0.75f);
    assert_int_equal(lr_gl_present(gl, &e), LR_OK);
    lr_gl_destroy(gl);

    /* The default back end can be sent to the device by the environment. */
    setenv("LAMPRIG_EGL_PLATFORM", "device", 1);
    int rc = lr_gl_create(NULL, &gl, &e);
    unsetenv("LAMPRIG_EGL_PLATFORM");
    if (rc)
        fail_msg("lr_gl_create(LAMPRIG_EGL_PLATFORM=device): %s", e.msg);
    assert_string_equal(lr_gl_backend_name(gl), "device");
    clear_and_read_back(1.0f, 0.0f, 0.5f);
    lr_gl_destroy(gl);
}

static void device_and_platform_choices_are_checked(void **state)
{
    lr_gl *gl = (lr_gl *)1;
    lr_err e = {0};
    setenv("LAMPRIG_EGL_DEVICE", "99", 1);
    assert_int_equal(lr_gl_create(&(lr_gl_desc){.backend = LR_GL_DEVICE}, &gl, &e), LR_EINVAL);
    unsetenv("LAMPRIG_EGL_DEVICE");
    assert_null(gl);
    assert_non_null(strstr(e.msg, "LAMPRIG_EGL_DEVICE='99': expected 0.."));
    setenv("LAMPRIG_EGL_DEVICE", "x", 1);
    assert_int_equal(lr_gl_create(&(lr_gl_desc){.backend = LR_GL_DEVICE}, &gl, &e), LR_EINVAL);
    unsetenv("LAMPRIG_EGL_DEVICE");
    setenv("LAMPRIG_EGL_PLATFORM", "x11", 1);
    assert_int_equal(lr_gl_create(NULL, &gl, &e), LR_EINVAL);
    unsetenv("LAMPRIG_EGL_PLATFORM");
    assert_string_equal(e.msg, "EGL: LAMPRIG_EGL_PLATFORM='x11': expected surfaceless or device");
    /* Device 0 named explicitly works (Mesa's software device here). */
    setenv("LAMPRIG_EGL_DEVICE", "0", 1);
    int rc = lr_gl_create(&(lr_gl_desc){.backend = LR_GL_DEVICE}, &gl, &e);
    unsetenv("LAMPRIG_EGL_DEVICE");
    if (rc)
        fail_msg("LAMPRIG_EGL_DEVICE=0: %s", e.msg);
    lr_gl_destroy(gl);
}

static void gl_errors_are_reported_by_name(void **state)
{
    lr_gl *gl = NULL;
    lr_err e = {0};
    assert_int_equal(lr_gl_create(NULL, &gl, &e), LR_OK);
    assert_int_equal(lr_gl_check("clean", &e), LR_OK);
    glEnable(0x7fff); /* not a capability: GL_INVALID_ENUM */
    glBindTexture(GL_TEXTURE_2D, 0xdeadu); /* fine in GLES: names are created on bind */
    assert_int_equal(lr_gl_check("bad enable", &e), LR_EGL);
    assert_string_equal(e.msg, "bad enable: GL_INVALID_ENUM");
    /* Drained: the next check sees only new errors. */
    assert_int_equal(lr_gl_check("after", &e), LR_OK);
    lr_gl_destroy(gl);
}

static void bad_descriptor_is_rejected(void **state)
{
    lr_gl *gl = (lr_gl *)1;
    lr_err e = {0};
    assert_int_equal(lr_gl_create(&(lr_gl_desc){.backend = (lr_gl_backend)7}, &gl, &e), LR_EINVAL);
    assert_null(gl);
    assert_non_null(strstr(e.msg, "unknown back end 7"));
    assert_int_equal(lr_gl_create(&(lr_gl_desc){.backend = LR_GL_KMS, .width = -1}, &gl, &e),
                     LR_EINVAL);
}

/* ---- capability parsing, no context ---------------------------------------------------- */

static void caps_gles31_without_extensions(void **state)
{
    lr_gl_caps c = {0};
    lr_err e = {0};
    assert_int_equal(lr_gl_caps_parse("OpenGL ES 3.1 V3D 4.2", NULL, 0, &c, &e), LR_OK);
    assert_int_equal(c.major, 3);
    assert_int_equal(c.minor, 1);
    assert_false(c.color_buffer_float);
    assert_false(c.color_buffer_half_float);
    assert_false(c.texture_float_linear);
    assert_false(c.timer_query);
    snprintf(c.renderer, sizeof c.renderer, "V3D 4.2");
    assert_int_equal(lr_gl_caps_require(&c, LR_GL_NEED_FLOAT_RT, &e), LR_EUNSUPPORTED);
    assert_string_equal(e.msg, "GL: missing GL_EXT_color_buffer_float (32-bit float render "
                               "targets; core in GLES 3.2) on V3D 4.2 (OpenGL ES 3.1 V3D 4.2)");
    /* Several at once: every missing one named. */
    assert_int_equal(lr_gl_caps_require(&c, LR_GL_NEED_HALF_FLOAT_RT | LR_GL_NEED_FLOAT_LINEAR, &e),
                     LR_EUNSUPPORTED);
    assert_non_null(strstr(e.msg, "GL_EXT_color_buffer_half_float"));
    assert_non_null(strstr(e.msg, "GL_OES_texture_float_linear"));
    assert_null(strstr(e.msg, "GL_EXT_color_buffer_float "));
    assert_int_equal(lr_gl_caps_require(&c, 0, &e), LR_OK);
}

static void caps_half_float_only(void **state)
{
    const char *exts[] = {"GL_EXT_color_buffer_half_float", "GL_OES_texture_float_linear"};
    lr_gl_caps c = {0};
    lr_err e = {0};
    assert_int_equal(lr_gl_caps_parse("OpenGL ES 3.1 Mali-G52", exts, 2, &c, &e), LR_OK);
    assert_false(c.color_buffer_float);
    assert_true(c.color_buffer_half_float);
    assert_true(c.texture_float_linear);
    assert_int_equal(lr_gl_caps_require(&c, LR_GL_NEED_HALF_FLOAT_RT | LR_GL_NEED_FLOAT_LINEAR, &e),
                     LR_OK);
    assert_int_equal(lr_gl_caps_require(&c, LR_GL_NEED_FLOAT_RT | LR_GL_NEED_HALF_FLOAT_RT, &e),
                     LR_EUNSUPPORTED);
    assert_non_null(strstr(e.msg, "missing GL_EXT_color_buffer_float "));
    assert_null(strstr(e.msg, "half"));
}

static void caps_gles32_has_float_targets_in_core(void **state)
{
    lr_gl_caps c = {0};
    lr_err e = {0};
    assert_int_equal(lr_gl_caps_parse("OpenGL ES 3.2 build 1.13", NULL, 0, &c, &e), LR_OK);
    assert_true(c.color_buffer_float);
    assert_true(c.color_buffer_half_float);
    assert_false(c.texture_float_linear); /* never core */
}

/* The sRGB output target (render/passes/blend.h) needs sampling without decode. */
static void caps_srgb_decode(void **state)
{
    (void)state;
    const char *exts[] = {"GL_EXT_texture_sRGB_decode"};
    lr_gl_caps c = {0};
    lr_err e = {0};
    assert_int_equal(lr_gl_caps_parse("OpenGL ES 3.1", exts, 1, &c, &e), LR_OK);
    assert_true(c.srgb_decode);
    assert_int_equal(lr_gl_caps_require(&c, LR_GL_NEED_SRGB_DECODE, &e), LR_OK);
    assert_int_equal(lr_gl_caps_parse("OpenGL ES 3.2", NULL, 0, &c, &e), LR_OK);
    assert_false(c.srgb_decode); /* not core in any GLES */
    assert_int_equal(lr_gl_caps_require(&c, LR_GL_NEED_SRGB_DECODE, &e), LR_EUNSUPPORTED);
    assert_non_null(strstr(e.msg, "missing GL_EXT_texture_sRGB_decode "));
}

static void caps_extension_names_match_whole(void **state)
{
    const char *exts[] = {"GL_EXT_color_buffer_float_x", "GL_EXT_disjoint_timer_query_webgl"};
    lr_gl_caps c = {0};
    assert_int_equal(lr_gl_caps_parse("OpenGL ES 3.1", exts, 2, &c, NULL), LR_OK);
    assert_false(c.color_buffer_float);
    assert_false(c.timer_query);
}

static void caps_desktop_gl_is_rejected(void **state)
{
    lr_gl_caps c = {0};
    lr_err e = {0};
    assert_int_equal(lr_gl_caps_parse("4.6.0 NVIDIA 535.54", NULL, 0, &c, &e), LR_EUNSUPPORTED);
    assert_string_equal(e.msg, "GL: not an OpenGL ES context (GL_VERSION \"4.6.0 NVIDIA 535.54\")");
    assert_int_equal(lr_gl_caps_parse(NULL, NULL, 0, &c, &e), LR_EUNSUPPORTED);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(surfaceless_context_is_gles31_with_caps),
        cmocka_unit_test(context_can_be_recreated),
        cmocka_unit_test(device_backend_renders),
        cmocka_unit_test(device_and_platform_choices_are_checked),
        cmocka_unit_test(gl_errors_are_reported_by_name),
        cmocka_unit_test(bad_descriptor_is_rejected),
        cmocka_unit_test(caps_gles31_without_extensions),
        cmocka_unit_test(caps_half_float_only),
        cmocka_unit_test(caps_gles32_has_float_targets_in_core),
        cmocka_unit_test(caps_srgb_decode),
        cmocka_unit_test(caps_extension_names_match_whole),
        cmocka_unit_test(caps_desktop_gl_is_rejected),
    };
    if (getenv("LR_TEST_FILTER")) /* e.g. LR_TEST_FILTER='cube*' to run one test */
        cmocka_set_test_filter(getenv("LR_TEST_FILTER"));
    return cmocka_run_group_tests(tests, NULL, NULL);
}
