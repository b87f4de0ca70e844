/* The light through the openings (render.opening_light, render/openings/openings.h) in the
 * renderer and its CPU twin, on configs/scenes/lampshade.json (receiver bounce off, so the
 * difference is the openings' grid alone): the light each adds to the receiver pixels (image
 * with it minus image without, same seeds). Both add the same grids (one function, fixed
 * seeds; the GPU per light at unit intensity, the twin times the intensity) and composition
 * reads them with the same bilinear taps, so the two differences agree to float rounding of
 * the RGBA32F grid (test 0.5 %); the term only adds light. Small images and maps. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "render/cpu/frame.h"
#include "render/image/image.h"
#include "render/renderer.h"
#include "tests/support/gl.h"
#include "tests/support/pixel_hit.h"
#include "tests/support/near.h"
#include "tests/support/render.h"

#define W 64
#define H 48

LR_TEST_GL_FIXTURE(gl) /* tests/support/gl.h: setup(), teardown() */

static int receiver_at(const lr_scene *s, int x, int y)
{
    return lr_test_pixel_receiver(s, W, H, x, y);
}

static lr_image twin(lr_scene *s, bool on)
{
    lr_err e = {0};
    if (lr_scene_set(s, "render.opening_light", on ? "true" : "false", NULL, &e))
        fail_msg("%s", e.msg);
    lr_cpu_render_desc d = {.scene = s, .width = W, .height = H, .mode = LR_CPU_PASS};
    lr_image rgb, var;
    if (lr_cpu_render(&d, &rgb, &var, NULL, &e))
        fail_msg("%s", e.msg);
    lr_image_free(&var);
    return rgb;
}

static void test_gpu_vs_twin(void **state)
{
    (void)state;
    static const char *const off_sets[] = {"render.receiver_bounce=false",
                                           "render.opening_light=false", NULL};
    lr_scene *s = lr_test_scene("lampshade", lr_test_small_settings, off_sets);
    lr_renderer *r = lr_test_renderer(gl, s, W, H, false, 3);
    lr_test_converge(r, 20);
    float *g_off = lr_test_hdr(r); /* rows bottom up */
    lr_test_set(s, r, "render.opening_light", "true");
    lr_test_converge(r, 20);
    float *g_on = lr_test_hdr(r);
    lr_renderer_destroy(r);
    lr_image c_off = twin(s, false), c_on = twin(s, true);
    int nr = lr_scene_receiver_count(s);
    assert_true(nr == 2);
    double dg[2] = {0}, dc[2] = {0}, base[2] = {0};
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int i = receiver_at(s, x, y);
            if (i < 0)
                continue;
            size_t gk = 3 * ((size_t)(H - 1 - y) * W + x), ck = 3 * ((size_t)y * W + x);
            for (int c = 0; c < 3; c++) {
                assert_true(isfinite(g_on[gk + c]));
                assert_true(g_on[gk + c] >= g_off[gk + c] * (1 - 1e-5f)); /* only adds */
                dg[i] += g_on[gk + c] - g_off[gk + c];
                dc[i] += c_on.rgb[ck + c] - c_off.rgb[ck + c];
                base[i] += c_off.rgb[ck + c];
            }
        }
    for (int i = 0; i < nr; i++) {
        print_message("%s: openings GPU %.5g, twin %.5g (%+.3f %%); %.1f %% of the twin's "
                      "receiver light without it\n",
                      lr_scene_receiver_at(s, i)->name, dg[i], dc[i], 100 * (dg[i] / dc[i] - 1),
                      100 * dc[i] / base[i]);
        assert_true(dc[i] > 0);
        assert_true(fabs(dg[i] / dc[i] - 1) < 0.005);
    }
    free(g_off);
    free(g_on);
    lr_image_free(&c_off);
    lr_image_free(&c_on);
    lr_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gpu_vs_twin),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
