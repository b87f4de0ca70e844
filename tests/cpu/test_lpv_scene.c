/* A scene's light-propagation volume on the plane receivers (render/lpv/scene_lpv.h) on
 * led_shade (4 LED quads in a paper shade, table and wall): the receivers never gather more
 * than was injected, the table under the shade and the wall receive indirect light, nothing
 * lands outside the volume, further bounces add light within R / (1 - R), a point light gets
 * none (area lights only), a bad light index and n = 1 are refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/cpu/recv_grid.h"
#include "render/lpv/scene_lpv.h"
#include "tests/support/near.h"

#define TEXELS ((size_t)LR_RECV_GRID * LR_RECV_GRID)

static lr_scene *load(const char *path)
{
    lr_scene *s = NULL;
    lr_err e = {0};
    if (lr_scene_load(path, NULL, &s, &e))
        fail_msg("%s", e.msg);
    return s;
}

/* E at world point x from receiver i's grid (bilinear). */
static double at(const lr_scene *s, const double *g, int i, lr_vec3 x)
{
    lr_recv_grid_frame f;
    assert_true(lr_recv_grid_frame_of(lr_scene_receiver_at(s, i), &f));
    int idx[4];
    double w[4], E = 0.0;
    lr_recv_grid_taps(&f, x, idx, w);
    for (int k = 0; k < 4; k++)
        E += w[k] * g[(size_t)idx[k] * 3];
    return E;
}

static void test_led_shade(void **st)
{
    (void)st;
    lr_scene *s = load("configs/scenes/led_shade.json");
    assert_int_equal(lr_scene_receiver_count(s), 2);
    double *g[2] = {calloc(TEXELS * 3, sizeof(double)), calloc(TEXELS * 3, sizeof(double))};
    assert_non_null(g[0]);
    assert_non_null(g[1]);
    lr_lpv_scene_desc d = {.n = 16};
    lr_lpv_scene_stats stats;
    lr_err e = {0};
    if (lr_lpv_scene_indirect(s, 0, &d, g, &stats, &e))
        fail_msg("%s", e.msg);
    printf("n 16: cell %.1f mm, %d receiver and %d object samples; injected %.4g, gathered %.4g "
           "(R), receivers' direct %.4g per unit radiance\n",
           stats.cell_mm, stats.samples_receivers, stats.samples_objects, stats.injected[0],
           stats.gathered[0], stats.direct_receivers);
    for (int c = 0; c < 3; c++) {
        assert_true(stats.injected[c] > 0.0);
        assert_true(stats.gathered[c] > 0.0);
        assert_true(stats.gathered[c] <= stats.injected[c]);
    }
    /* Under the shade (its axis at x = y = 0) and on the wall behind it. */
    assert_true(at(s, g[0], 0, lr_v3(0, 0, 0)) > 0.0);
    assert_true(at(s, g[1], 1, lr_v3(0, 250, 250)) > 0.0);
    /* The table's far corner lies outside the volume: exactly nothing. */
    assert_near(at(s, g[0], 0, lr_v3(-690, -440, 0)), 0.0, 0.0);
    /* Two more bounces off the shade's inner wall (R 0.79): more light, still bounded. */
    d.bounces = 2;
    lr_lpv_scene_stats more;
    if (lr_lpv_scene_indirect(s, 0, &d, g, &more, &e))
        fail_msg("%s", e.msg);
    printf("2 more bounces: injected %.4g, gathered %.4g (R)\n", more.injected[0],
           more.gathered[0]);
    for (int c = 0; c < 3; c++) {
        assert_true(more.injected[c] > stats.injected[c]);
        assert_true(more.gathered[c] > stats.gathered[c]);
        assert_true(more.gathered[c] <= more.injected[c]);
    }
    /* The bounces add light that a first bounce injected and the shade absorbed: at most
     * R / (1 - R) with R <= 0.8 times the first injection. */
    assert_true(more.injected[0] <= stats.injected[0] * (1.0 + 0.8 / 0.2));
    lr_scene_destroy(s);
    free(g[0]);
    free(g[1]);
}

static void test_point_light_and_bad_index(void **st)
{
    (void)st;
    lr_scene *s = load("configs/scenes/lampshade.json");
    int nr = lr_scene_receiver_count(s);
    assert_true(nr >= 1 && nr <= 4);
    double *g[4] = {NULL, NULL, NULL, NULL};
    for (int i = 0; i < nr; i++) {
        g[i] = malloc(TEXELS * 3 * sizeof(double));
        assert_non_null(g[i]);
        for (size_t k = 0; k < TEXELS * 3; k++)
            g[i][k] = 1.0;
    }
    lr_err e = {0};
    lr_lpv_scene_desc d = {.n = 8};
    assert_int_equal(lr_lpv_scene_indirect(s, 0, &d, g, NULL, &e), LR_OK);
    for (int i = 0; i < nr; i++)
        for (size_t k = 0; k < TEXELS * 3; k++)
            assert_near(g[i][k], 0.0, 0.0);
    assert_int_equal(lr_lpv_scene_indirect(s, 7, &d, g, NULL, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "light 7"));
    d.n = 1;
    lr_scene *a = load("configs/scenes/led_shade.json");
    assert_int_equal(lr_lpv_scene_indirect(a, 0, &d, g, NULL, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "n = 1"));
    lr_scene_destroy(a);
    lr_scene_destroy(s);
    for (int i = 0; i < nr; i++)
        free(g[i]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_led_shade),
        cmocka_unit_test(test_point_light_and_bad_index),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
