/* Translucent radiosity in the renderer (render/transrad/tr_scene.h, radiosity.vert): the GPU's
 * radiosity maps of an object with model translucent_radiosity against the CPU twin's value at
 * the same x_o (the solved per-vertex B interpolated over the triangle found by the closest
 * point, as render/cpu/maps.c does). Both read the same deterministic solve, so they differ by
 * float rounding and by where the GPU's interpolated x_o lies (a fraction of a texel): per
 * texel within 2 % of the map's largest B, the maps' sums within 0.5 %. After a light move
 * the maps are re-solved (warm start) and agree again (measured: sums equal to 1e-5, worst
 * texel 0.001 % of the peak). The receiver extra is positive and never negative. */
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
#include "render/transrad/tr_scene.h"
#include "tests/support/gl.h"
#include "tests/support/render.h"

LR_TEST_GL_FIXTURE(gl)

static const char *const small[] = {"render.K=4", "render.map_size=48", "render.frames=2",
                                    "render.gbuffer_size=64", "render.N_vpl=16", NULL};

/* The twin's solver, kept across the tests like the renderer keeps its own: a light move
 * re-solves it without rebuilding F and S (the precomputation is most of the time). */
static lr_tr_scene *ts;

static void compare(lr_renderer *r, const lr_scene *s)
{
    lr_err e = {0};
    if (lr_tr_scene_update(&ts, s, NULL, &e))
        fail_msg("%s", e.msg);
    assert_non_null(ts);
    lr_debug_map_info info;
    lr_renderer_debug_map_info(r, &info);
    size_t n = (size_t)info.size * info.size;
    float *B = malloc(3 * n * sizeof *B), *pos = malloc(3 * n * sizeof *pos);
    int *obj = malloc(n * sizeof *obj);
    double sg = 0, sc = 0, worst = 0, peak = 0;
    long texels = 0;
    for (int l = 0; l < lr_scene_light_count(s); l++)
        for (int k = 0; k < info.K; k++) {
            if (lr_renderer_debug_read_light_map(r, l, k, B, pos, NULL, obj, &e))
                fail_msg("%s", e.msg);
            for (size_t i = 0; i < n; i++) {
                if (obj[i] < 0)
                    continue;
                const lr_scene_object *o = lr_scene_object_at(s, obj[i]);
                lr_closest cl;
                lr_vec3 x = lr_v3(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]);
                double c[3] = {0, 0, 0};
                if (lr_bvh_closest(o->bvh, x, INFINITY, &cl))
                    lr_tr_scene_B_at(ts, obj[i], l, cl.triangle, cl.w, c);
                for (int b = 0; b < 3; b++) {
                    sg += B[3 * i + (size_t)b];
                    sc += c[b];
                    worst = fmax(worst, fabs(B[3 * i + (size_t)b] - c[b]));
                    peak = fmax(peak, c[b]);
                }
                texels++;
            }
        }
    print_message("%ld texels: GPU / twin map sum %.5f, worst texel %.3f %% of the peak\n", texels,
                  sg / sc, 100 * worst / peak);
    assert_true(texels > 100);
    assert_true(peak > 0);
    assert_true(fabs(sg / sc - 1) < 0.005);
    assert_true(worst < 0.02 * peak);
    free(B);
    free(pos);
    free(obj);
}

static void test_votive_maps(void **state)
{
    (void)state;
    static const char *const tr[] = {"objects[0].model=translucent_radiosity", NULL};
    lr_scene *s = lr_test_scene("votive", small, tr);
    lr_renderer *r = lr_test_renderer(gl, s, 16, 12, false, 3);
    lr_test_converge(r, 4);
    compare(r, s);
    /* A light move: re-solved, the twin agrees at the new position. */
    unsigned dirty = 0;
    lr_err e = {0};
    if (lr_scene_set(s, "light.position", "3,0,30", &dirty, &e))
        fail_msg("%s", e.msg);
    lr_renderer_invalidate(r, dirty);
    lr_test_converge(r, 4);
    compare(r, s);
    /* The receivers' extra irradiance (what the VPLs do not carry): positive on the table and
     * the wall (the votive's inner faces through its opening, the other receiver), never
     * negative. */
    for (int i = 0; i < lr_scene_receiver_count(s); i++) {
        const float *X = lr_tr_scene_recv_E(ts, i, 0);
        assert_non_null(X);
        double sum = 0, lo = INFINITY;
        for (size_t k = 0; k < (size_t)3 * 256 * 256; k++) {
            sum += X[k];
            lo = fmin(lo, X[k]);
        }
        assert_true(sum > 0);
        assert_true(lo >= 0);
    }
    lr_tr_scene_destroy(ts);
    ts = NULL;
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_votive_maps),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
