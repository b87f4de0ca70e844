/* The irradiance pass keeps the receiver bounce's and the openings' state across a material
 * change (render/passes/irradiance.h, lr_irradiance_free_grids): the grids are laid out again,
 * the patches, F, the objects' per-vertex rows and the openings' points are not rebuilt (their
 * keys hold geometry, receivers and lights; the openings' light key holds the material). What
 * must hold: the image after the change equals a fresh renderer's on the changed scene, same
 * seeds, to float rounding, on the lamp shade (receiver bounce, the receivers' light on the
 * objects and the light through the openings all on, as shipped), for a translucency knob
 * (the material's scale) and for a material preset. Small images and maps. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "render/renderer.h"
#include "tests/support/gl.h"
#include "tests/support/render.h"

#define W 48
#define H 36

LR_TEST_GL_FIXTURE(gl) /* tests/support/gl.h: setup(), teardown() */

static void same_as_fresh(const char *key, const char *value)
{
    lr_scene *s = lr_test_scene("lampshade", lr_test_small_settings, NULL);
    lr_renderer *r = lr_test_renderer(gl, s, W, H, false, 5);
    lr_test_converge(r, 20);
    float *before = lr_test_hdr(r);
    lr_test_set(s, r, key, value);
    lr_test_converge(r, 20);
    float *kept = lr_test_hdr(r);
    lr_renderer_destroy(r);
    r = lr_test_renderer(gl, s, W, H, false, 5);
    lr_test_converge(r, 20);
    float *fresh = lr_test_hdr(r);
    lr_renderer_destroy(r);
    double mx = 0.0, worst = 0.0;
    int changed = 0;
    for (int i = 0; i < W * H * 3; i++)
        mx = fmax(mx, fresh[i]);
    for (int i = 0; i < W * H * 3; i++) {
        double d = fabs((double)kept[i] - fresh[i]);
        if (!(d <= 1e-5 * fabs(fresh[i]) + 1e-7 * mx))
            fail_msg("%s=%s: value %d: %.9g, a fresh renderer %.9g", key, value, i, kept[i],
                     fresh[i]);
        worst = fmax(worst, d / (fabs(fresh[i]) + 1e-7 * mx));
        changed += fabs((double)before[i] - fresh[i]) > 1e-3 * mx;
    }
    print_message("%s=%s: worst relative difference %.3g; %d of %d values changed by it\n", key,
                  value, worst, changed, W * H * 3);
    assert_true(changed > W * H / 4); /* the change does change the image */
    free(before);
    free(kept);
    free(fresh);
    lr_scene_destroy(s);
}

static void test_translucency_knob(void **state)
{
    (void)state;
    same_as_fresh("objects[0].material.scale", "1.3");
}

static void test_material_preset(void **state)
{
    (void)state;
    same_as_fresh("objects[0].material", "candle_wax");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_translucency_knob),
        cmocka_unit_test(test_material_preset),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
