/* Receiver inter-reflection (render.receiver_bounce, render/bounce/rbounce.h) in the renderer
 * and its CPU twin, on configs/scenes/candle_spot.json (steady flame): the bounce each adds to
 * the receiver pixels (image with it minus image without, same seeds), GPU (per light at unit
 * intensity from its read-back grids) against twin (one solve with the lights' intensities).
 * Its source is E_dir + E_vpl: E_dir and F are the same code in both, so that part agrees to
 * rounding, while the VPLs' light differs between GPU and twin (48 VPLs placed from each one's
 * own maps; the project's final-image test allows 20 % on receivers). So per receiver the
 * bounce's GPU / twin ratio must lie between 1 and the receivers' VPL-light ratios (measured
 * here as the image with VPLs minus the image without), widened by 3 %. And the bounce only
 * adds light. Small images and maps (llvmpipe under ASan). */
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

static lr_image twin_mode(lr_scene *s, bool bounce, bool no_vpl, enum lr_cpu_sampler mode)
{
    lr_err e = {0};
    if (lr_scene_set(s, "render.receiver_bounce", bounce ? "true" : "false", NULL, &e))
        fail_msg("%s", e.msg);
    lr_cpu_render_desc d = {.scene = s, .width = W, .height = H, .mode = mode,
                            .no_vpl = no_vpl, .samples = 64};
    lr_image rgb, var;
    if (lr_cpu_render(&d, &rgb, &var, NULL, &e))
        fail_msg("%s", e.msg);
    lr_image_free(&var);
    return rgb;
}

static lr_image twin(lr_scene *s, bool bounce, bool no_vpl)
{
    return twin_mode(s, bounce, no_vpl, LR_CPU_PASS);
}

static void test_gpu_vs_twin(void **state)
{
    (void)state;
    /* A steady flame: the twin has no clock. */
    static const char *const steady[] = {"lights[0].flicker.amplitude=0",
                                         "lights[0].flicker.jitter_mm=0",
                                         "render.receiver_bounce=false", NULL};
    lr_scene *s = lr_test_scene("candle_spot", lr_test_small_settings, steady);
    lr_renderer *r = lr_test_renderer(gl, s, W, H, false, 3);
    lr_test_converge(r, 20);
    float *g_off = lr_test_hdr(r); /* rows bottom up */
    lr_test_set(s, r, "render.receiver_bounce", "true");
    lr_test_converge(r, 20);
    float *g_on = lr_test_hdr(r);
    lr_renderer_destroy(r);
    lr_err e = {0};
    if (lr_scene_set(s, "render.receiver_bounce", "false", NULL, &e))
        fail_msg("%s", e.msg);
    r = lr_test_renderer(gl, s, W, H, true, 3);
    lr_test_converge(r, 20);
    float *g_dir = lr_test_hdr(r);
    lr_renderer_destroy(r);
    lr_image c_off = twin(s, false, false), c_on = twin(s, true, false);
    lr_image c_dir = twin(s, false, true);

    int nr = lr_scene_receiver_count(s);
    assert_true(nr == 2);
    double dg[2] = {0}, dc[2] = {0}, off[2] = {0}, goff[2] = {0}, vg[2] = {0}, vc[2] = {0};
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int i = receiver_at(s, x, y);
            if (i < 0)
                continue;
            size_t gk = 3 * ((size_t)(H - 1 - y) * W + x), ck = 3 * ((size_t)y * W + x);
            for (int c = 0; c < 3; c++) {
                assert_true(isfinite(g_on[gk + c]));
                /* The bounce only adds light (float slack for the reordered sums). */
                assert_true(g_on[gk + c] >= g_off[gk + c] * (1 - 1e-5f));
                dg[i] += g_on[gk + c] - g_off[gk + c];
                dc[i] += c_on.rgb[ck + c] - c_off.rgb[ck + c];
                off[i] += c_off.rgb[ck + c];
                goff[i] += g_off[gk + c];
                vg[i] += g_off[gk + c] - g_dir[gk + c];
                vc[i] += c_off.rgb[ck + c] - c_dir.rgb[ck + c];
            }
        }
    for (int i = 0; i < nr; i++) {
        print_message("%s: bounce GPU %.5g, twin %.5g (%+.2f %%); without it GPU %.5g twin %.5g\n",
                      lr_scene_receiver_at(s, i)->name, dg[i], dc[i], 100 * (dg[i] / dc[i] - 1),
                      goff[i], off[i]);
    }
    double lo = 1, hi = 1;
    for (int i = 0; i < nr; i++) {
        print_message("%s: VPL light GPU %.5g, twin %.5g (%+.2f %%)\n",
                      lr_scene_receiver_at(s, i)->name, vg[i], vc[i], 100 * (vg[i] / vc[i] - 1));
        assert_true(vc[i] > 0);
        lo = fmin(lo, vg[i] / vc[i]);
        hi = fmax(hi, vg[i] / vc[i]);
    }
    for (int i = 0; i < nr; i++) {
        assert_true(dc[i] > 0);
        assert_true(dg[i] / dc[i] >= lo - 0.03 && dg[i] / dc[i] <= hi + 0.03);
    }
    free(g_off);
    free(g_dir);
    lr_image_free(&c_dir);
    free(g_on);
    lr_image_free(&c_off);
    lr_image_free(&c_on);
    lr_scene_destroy(s);
}

/* The CPU reference of the model (LR_CPU_REFERENCE: the bench's "ref" column) includes the
 * bounce too. Its source is E_dir + E_vpl, E_dir the same code as the twin's, E_vpl from the
 * reference's own VPLs (their power from the reference estimator, not from maps). So, as for
 * the GPU above, per receiver the bounce's reference / twin ratio must lie between 1 and the
 * receivers' VPL-light ratios, widened by 3 %. */
static void test_reference_has_bounce(void **state)
{
    (void)state;
    static const char *const steady[] = {"lights[0].flicker.amplitude=0",
                                         "lights[0].flicker.jitter_mm=0", NULL};
    lr_scene *s = lr_test_scene("candle_spot", lr_test_small_settings, steady);
    enum { PASS, REF };
    lr_image off[2], on[2], dir[2];
    for (int m = 0; m < 2; m++) {
        enum lr_cpu_sampler mode = m == PASS ? LR_CPU_PASS : LR_CPU_REFERENCE;
        off[m] = twin_mode(s, false, false, mode);
        on[m] = twin_mode(s, true, false, mode);
        dir[m] = twin_mode(s, false, true, mode);
    }
    int nr = lr_scene_receiver_count(s);
    assert_true(nr == 2);
    double d[2][2] = {{0}}, v[2][2] = {{0}};
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            int i = receiver_at(s, x, y);
            if (i < 0)
                continue;
            for (int m = 0; m < 2; m++)
                for (int c = 0; c < 3; c++) {
                    size_t k = 3 * ((size_t)y * W + x) + c;
                    assert_true(on[m].rgb[k] >= off[m].rgb[k] * (1 - 1e-6f));
                    d[m][i] += on[m].rgb[k] - off[m].rgb[k];
                    v[m][i] += off[m].rgb[k] - dir[m].rgb[k];
                }
        }
    double lo = 1, hi = 1;
    for (int i = 0; i < nr; i++) {
        assert_true(v[PASS][i] > 0 && d[PASS][i] > 0);
        double rv = v[REF][i] / v[PASS][i], rd = d[REF][i] / d[PASS][i];
        print_message("%s: bounce reference %.5g, twin %.5g (%+.2f %%); VPL light %+.2f %%\n",
                      lr_scene_receiver_at(s, i)->name, d[REF][i], d[PASS][i],
                      100 * (rd - 1), 100 * (rv - 1));
        lo = fmin(lo, rv);
        hi = fmax(hi, rv);
    }
    for (int i = 0; i < nr; i++) {
        double rd = d[REF][i] / d[PASS][i];
        assert_true(rd >= lo - 0.03 && rd <= hi + 0.03);
    }
    for (int m = 0; m < 2; m++) {
        lr_image_free(&off[m]);
        lr_image_free(&on[m]);
        lr_image_free(&dir[m]);
    }
    lr_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gpu_vs_twin),
        cmocka_unit_test(test_reference_has_bounce),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
