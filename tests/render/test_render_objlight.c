/* The receivers' light on the objects (render.receiver_light_on_objects, render/bounce/
 * objlight.h) in the renderer and its CPU twin, on configs/scenes/candle_spot.json (steady
 * flame, receiver_bounce on): the light it adds to the object pixels (image with it minus
 * image without, same seeds), GPU (per light at unit intensity, per vertex through the
 * compose pass's varyings) against twin (one solve with the lights' intensities, per camera
 * hit by barycentrics). Its source, the receivers' radiosity, is E_dir + E_vpl + E_b: E_dir,
 * F and the objects' rows are the same code in both, the VPLs' light differs between GPU and
 * twin (each places its VPLs from its own maps). So the GPU / twin ratio of the objects' added
 * light must lie between 1 and the receivers' VPL-light ratios, widened by 3 % (as
 * test_render_rbounce bounds the bounce). It only adds light, and with the surface cache the
 * GPU adds the same as without it (the same per-vertex values, by corner) within 1e-4. */
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

static int hit_at(const lr_scene *s, int x, int y)
{
    return lr_test_pixel_hit(s, W, H, x, y);
}

static void set(lr_scene *s, const char *k, const char *v)
{
    lr_err e = {0};
    if (lr_scene_set(s, k, v, NULL, &e))
        fail_msg("%s", e.msg);
}

static lr_image twin(lr_scene *s, bool objlight, bool no_vpl)
{
    set(s, "render.receiver_light_on_objects", objlight ? "true" : "false");
    lr_cpu_render_desc d = {.scene = s, .width = W, .height = H, .mode = LR_CPU_PASS,
                            .no_vpl = no_vpl};
    lr_image rgb, var;
    lr_err e = {0};
    if (lr_cpu_render(&d, &rgb, &var, NULL, &e))
        fail_msg("%s", e.msg);
    lr_image_free(&var);
    return rgb;
}

static float *gpu(lr_scene *s, bool objlight, bool no_vpl, bool cache)
{
    set(s, "render.receiver_light_on_objects", objlight ? "true" : "false");
    set(s, "render.surface_cache", cache ? "true" : "false");
    lr_renderer *r = lr_test_renderer(gl, s, W, H, no_vpl, 3);
    lr_test_converge(r, 20);
    float *img = lr_test_hdr(r); /* rows bottom up */
    lr_renderer_destroy(r);
    return img;
}

static void test_gpu_vs_twin(void **state)
{
    (void)state;
    static const char *const steady[] = {"lights[0].flicker.amplitude=0",
                                         "lights[0].flicker.jitter_mm=0",
                                         "render.receiver_bounce=true", NULL};
    lr_scene *s = lr_test_scene("candle_spot", lr_test_small_settings, steady);
    float *g_off = gpu(s, false, false, false), *g_on = gpu(s, true, false, false);
    float *g_dir = gpu(s, false, true, false), *g_cache = gpu(s, true, false, true);
    float *g_cache_off = gpu(s, false, false, true);
    set(s, "render.surface_cache", "false");
    lr_image c_off = twin(s, false, false), c_on = twin(s, true, false);
    lr_image c_dir = twin(s, false, true);

    double dg = 0, dc = 0, dgc = 0, obj_g = 0, obj_c = 0, vg[2] = {0}, vc[2] = {0};
    long npx = 0;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int who = hit_at(s, x, y);
            if (who < 0)
                continue;
            size_t gk = 3 * ((size_t)(H - 1 - y) * W + x), ck = 3 * ((size_t)y * W + x);
            for (int c = 0; c < 3; c++) {
                if (who == 0) {
                    assert_true(isfinite(g_on[gk + c]));
                    assert_true(g_on[gk + c] >= g_off[gk + c] * (1 - 1e-5f));
                    assert_true(c_on.rgb[ck + c] >= c_off.rgb[ck + c] * (1 - 1e-9));
                    dg += g_on[gk + c] - g_off[gk + c];
                    dgc += g_cache[gk + c] - g_cache_off[gk + c];
                    dc += c_on.rgb[ck + c] - c_off.rgb[ck + c];
                    obj_g += g_off[gk + c];
                    obj_c += c_off.rgb[ck + c];
                    npx += c == 0;
                } else {
                    /* The receivers do not change: only the objects are lit. */
                    assert_true(fabs(g_on[gk + c] - g_off[gk + c]) <=
                                1e-5 * fabs(g_off[gk + c]) + 1e-30);
                    vg[who - 1] += g_off[gk + c] - g_dir[gk + c];
                    vc[who - 1] += c_off.rgb[ck + c] - c_dir.rgb[ck + c];
                }
            }
        }
    double lo = 1, hi = 1;
    for (int i = 0; i < 2; i++) {
        print_message("%s: VPL light GPU %.5g, twin %.5g (%+.2f %%)\n",
                      lr_scene_receiver_at(s, i)->name, vg[i], vc[i], 100 * (vg[i] / vc[i] - 1));
        assert_true(vc[i] > 0);
        lo = fmin(lo, vg[i] / vc[i]);
        hi = fmax(hi, vg[i] / vc[i]);
    }
    print_message("objects (%ld px): added GPU %.5g, twin %.5g (%+.2f %%), GPU with the surface "
                  "cache %.5g; without it GPU %.5g twin %.5g (the added light %.1f %% of it)\n",
                  npx, dg, dc, 100 * (dg / dc - 1), dgc, obj_g, obj_c, 100 * dc / obj_c);
    assert_true(npx > 50);
    assert_true(dc > 0);
    assert_true(dg / dc >= lo - 0.03 && dg / dc <= hi + 0.03);
    assert_near_rel(dgc, dg, 1e-4);
    free(g_off);
    free(g_on);
    free(g_dir);
    free(g_cache);
    free(g_cache_off);
    lr_image_free(&c_off);
    lr_image_free(&c_on);
    lr_image_free(&c_dir);
    lr_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gpu_vs_twin),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
