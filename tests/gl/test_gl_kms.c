/* The projector back end where there is no display: it must build, fail cleanly and say why.
 * (On the rig itself /dev/dri exists; the first test then checks nothing and says so.) */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "render/gl/gl.h"

static void no_dev_dri_gives_clear_message(void **state)
{
    if (access("/dev/dri", F_OK) == 0)
        skip(); /* a machine with DRM devices: covered by the explicit-path tests below */
    lr_gl *gl = (lr_gl *)1;
    lr_err e = {0};
    int rc = lr_gl_create(&(lr_gl_desc){.backend = LR_GL_KMS}, &gl, &e);
    assert_int_equal(rc, LR_ENODEV);
    assert_int_equal(e.code, LR_ENODEV);
    assert_null(gl);
    assert_string_equal(e.msg, "KMS: no /dev/dri on this machine (no display driver loaded, or "
                               "the device not passed into the container); use the surfaceless "
                               "back end for headless rendering");
}

static void missing_device_path_is_named(void **state)
{
    lr_gl *gl = (lr_gl *)1;
    lr_err e = {0};
    lr_gl_desc d = {.backend = LR_GL_KMS, .drm_device = "/nonexistent/dri/card7"};
    assert_int_equal(lr_gl_create(&d, &gl, &e), LR_ENODEV);
    assert_null(gl);
    assert_string_equal(e.msg, "KMS: cannot open /nonexistent/dri/card7: No such file or directory");
}

static void non_drm_device_is_rejected(void **state)
{
    /* /dev/null opens read-write but answers no mode-setting ioctl: the path past open(). */
    lr_gl *gl = (lr_gl *)1;
    lr_err e = {0};
    lr_gl_desc d = {.backend = LR_GL_KMS, .drm_device = "/dev/null", .connector = "HDMI-A-1"};
    assert_int_equal(lr_gl_create(&d, &gl, &e), LR_ENODEV);
    assert_null(gl);
    assert_string_equal(e.msg, "KMS: /dev/null has no mode-setting resources (render-only GPU?)");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(no_dev_dri_gives_clear_message),
        cmocka_unit_test(missing_device_path_is_named),
        cmocka_unit_test(non_drm_device_is_rejected),
    };
    if (getenv("LR_TEST_FILTER")) /* e.g. LR_TEST_FILTER='cube*' to run one test */
        cmocka_set_test_filter(getenv("LR_TEST_FILTER"));
    return cmocka_run_group_tests(tests, NULL, NULL);
}
