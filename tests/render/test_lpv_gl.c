/* The light-propagation volume's GLES 3.1 compute-shader propagation
 * (render/shaders/lpv_propagate.comp, render/lpv/gpu.c) against its CPU twin
 * (render/lpv/propagate.c) on the same injected light and blocking: the light in flight, the
 * absorbed record and the gathered irradiance agree to float rounding; the GPU keeps the no-
 * gain property; bad parameters are refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "render/base/rng.h"
#include "render/lpv/gpu.h"
#include "render/core/recv_grid.h"
#include "render/lpv/lpv.h"
#include "render/lpv/scene_lpv.h"
#include <stdlib.h>
#include "tests/support/gl.h"
#include "tests/support/near.h"
#include "tests/support/render.h"

LR_TEST_GL_FIXTURE(gl)

static lr_vec3 random_dir(lr_rng *r)
{
    double z = 2.0 * lr_rng_next(r) - 1.0, ph = 2.0 * M_PI * lr_rng_next(r);
    double s = sqrt(fmax(0.0, 1.0 - z * z));
    return lr_v3(s * cos(ph), s * sin(ph), z);
}

/* A 16^3 volume of 2 mm cells around the origin: a floor of blockers at z = -8 (opaque), a
 * half-covering wall at x = 6, 200 random blocker samples, 40 random lobes and 5 points. */
static lr_lpv *scene(uint64_t seed)
{
    const int n = 16;
    lr_err e = {0};
    lr_lpv_desc d = {.origin = lr_v3(-16, -16, -16), .cell = 2.0, .n = n};
    lr_lpv *v = NULL;
    assert_int_equal(lr_lpv_create(&d, &v, &e), LR_OK);
    for (int j = 0; j < 64; j++)
        for (int k = 0; k < 64; k++) {
            double a = -16 + (j + 0.5) * 0.5, b = -16 + (k + 0.5) * 0.5;
            assert_int_equal(lr_lpv_add_blocker(v, lr_v3(a, b, -8), lr_v3(0, 0, 1), 0.25, &e),
                             LR_OK);
            assert_int_equal(lr_lpv_add_blocker(v, lr_v3(6, a, b), lr_v3(1, 0, 0), 0.125, &e),
                             LR_OK);
        }
    lr_rng r = lr_rng_init(seed);
    for (int q = 0; q < 200; q++) {
        lr_vec3 p = lr_v3(32 * lr_rng_next(&r) - 16, 32 * lr_rng_next(&r) - 16,
                          32 * lr_rng_next(&r) - 16);
        assert_int_equal(lr_lpv_add_blocker(v, p, random_dir(&r), 3.0 * lr_rng_next(&r), &e),
                         LR_OK);
    }
    for (int q = 0; q < 45; q++) {
        lr_vec3 p = lr_v3(24 * lr_rng_next(&r) - 12, 24 * lr_rng_next(&r) - 12,
                          16 * lr_rng_next(&r) - 6);
        double phi[3] = {lr_rng_next(&r), lr_rng_next(&r), 0.5};
        if (q < 40)
            assert_int_equal(lr_lpv_inject_lobe(v, p, random_dir(&r), phi, &e), LR_OK);
        else
            assert_int_equal(lr_lpv_inject_point(v, p, phi, &e), LR_OK);
    }
    return v;
}

static double max_abs(const double *x, size_t n)
{
    double m = 0.0;
    for (size_t i = 0; i < n; i++)
        m = fmax(m, fabs(x[i]));
    return m;
}

static void test_gpu_matches_twin(void **st)
{
    (void)st;
    lr_err e = {0};
    const int n = 16, steps = 40;
    lr_lpv *cpu = scene(3), *gpu = scene(3);
    lr_lpv_gpu *g = NULL;
    if (lr_lpv_gpu_create(gl, n, NULL, &g, &e))
        fail_msg("%s", e.msg);
    assert_int_equal(lr_lpv_gpu_upload(g, gpu, &e), LR_OK);
    double before[3];
    for (int ch = 0; ch < 3; ch++)
        before[ch] = lr_lpv_total_flux(cpu, ch);
    /* In two halves, so the GPU's ping-pong is read back mid-way too. */
    for (int half = 0; half < 2; half++) {
        assert_int_equal(lr_lpv_propagate(cpu, steps / 2, &e), LR_OK);
        if (lr_lpv_gpu_propagate(g, steps / 2, &e))
            fail_msg("%s", e.msg);
        if (lr_lpv_gpu_download(g, gpu, &e))
            fail_msg("%s", e.msg);
        size_t nc = (size_t)n * n * n * 12, na = (size_t)(n + 1) * (n + 1) * (n + 1) * 18;
        const double *a = lr_lpv_grid(cpu), *b = lr_lpv_grid(gpu);
        double scale = max_abs(a, nc), worst = 0.0;
        for (size_t i = 0; i < nc; i++)
            worst = fmax(worst, fabs(a[i] - b[i]));
        printf("after %d steps: light in flight max |gpu - cpu| = %.3g of max %.3g\n",
               (half + 1) * steps / 2, worst, scale);
        /* float against double over 20-40 steps of sums of 30 terms: 1e-5 of the largest. */
        assert_true(scale > 0.0);
        assert_true(worst <= 1e-5 * scale);
        a = lr_lpv_absorbed(cpu);
        b = lr_lpv_absorbed(gpu);
        scale = max_abs(a, na);
        worst = 0.0;
        for (size_t i = 0; i < na; i++)
            worst = fmax(worst, fabs(a[i] - b[i]));
        printf("absorbed max |gpu - cpu| = %.3g of max %.3g\n", worst, scale);
        assert_true(scale > 0.0);
        assert_true(worst <= 1e-5 * scale);
        for (int ch = 0; ch < 3; ch++) {
            double tc = lr_lpv_total_flux(cpu, ch) + lr_lpv_absorbed_flux(cpu, ch);
            double tg = lr_lpv_total_flux(gpu, ch) + lr_lpv_absorbed_flux(gpu, ch);
            assert_near_rel(tg, tc, 1e-5);
            assert_true(tg <= before[ch] * (1.0 + 1e-5));
        }
    }
    /* The gathered irradiance on the floor. */
    for (int q = 0; q < 16; q++) {
        lr_vec3 x = lr_v3(-14 + 2 * q, 3 - q, -8);
        double Ec[3], Eg[3];
        lr_lpv_irradiance(cpu, x, lr_v3(0, 0, 1), Ec);
        lr_lpv_irradiance(gpu, x, lr_v3(0, 0, 1), Eg);
        for (int ch = 0; ch < 3; ch++) {
            assert_true(Ec[ch] > 0.0);
            assert_near_rel(Eg[ch], Ec[ch], 1e-4);
        }
    }
    lr_lpv_gpu_destroy(g);
    lr_lpv_destroy(cpu);
    lr_lpv_destroy(gpu);
}

/* A scene's receiver grids (light 0, 12^3 cells, one further bounce) with the compute
 * shader's propagation, as the renderer's area-direct pass makes them, against the CPU
 * twin's: within 1e-4 of the largest texel. */
static void grids_match_twin(const char *path)
{
    lr_err e = {0};
    lr_scene *s = NULL;
    if (lr_scene_load(path, NULL, &s, &e))
        fail_msg("%s", e.msg);
    const size_t texels = (size_t)LR_RECV_GRID * LR_RECV_GRID;
    int nr = lr_scene_receiver_count(s);
    assert_true(nr >= 1 && nr <= 4);
    double *cpu[4] = {NULL}, *gpu[4] = {NULL};
    for (int i = 0; i < nr; i++) {
        cpu[i] = malloc(texels * 3 * sizeof(double));
        gpu[i] = malloc(texels * 3 * sizeof(double));
        assert_non_null(cpu[i]);
        assert_non_null(gpu[i]);
    }
    lr_lpv_gpu *g = NULL;
    if (lr_lpv_gpu_create(gl, 12, NULL, &g, &e))
        fail_msg("%s", e.msg);
    lr_lpv_scene_desc dc = {.n = 12, .bounces = 1};
    lr_lpv_scene_desc dg = {.n = 12, .bounces = 1, .propagate = lr_lpv_gpu_run, .ctx = g};
    if (lr_lpv_scene_indirect(s, 0, &dc, cpu, NULL, &e) ||
        lr_lpv_scene_indirect(s, 0, &dg, gpu, NULL, &e))
        fail_msg("%s", e.msg);
    for (int i = 0; i < nr; i++) {
        double m = max_abs(cpu[i], texels * 3), worst = 0.0;
        for (size_t k = 0; k < texels * 3; k++)
            worst = fmax(worst, fabs(cpu[i][k] - gpu[i][k]));
        printf("%s receiver %d: max |gpu - cpu| %.3g of max %.3g\n", path, i, worst, m);
        assert_true(m > 0.0);
        assert_true(worst <= 1e-4 * m);
        free(cpu[i]);
        free(gpu[i]);
    }
    lr_lpv_gpu_destroy(g);
    lr_scene_destroy(s);
}

/* led_shade: an LED quad (area light, per unit radiance). */
static void test_scene_grids_match_twin(void **st)
{
    (void)st;
    grids_match_twin("configs/scenes/led_shade.json");
}

/* lampshade: a bulb (point light, per unit intensity) inside a shade. */
static void test_point_scene_grids_match_twin(void **st)
{
    (void)st;
    grids_match_twin("configs/scenes/lampshade.json");
}

/* End to end, a point light (lampshade's bulb) with render.lpv = 8 and no VPLs: at receiver
 * points in the shade's shadow (direct light 0, test_render_emergent.c) the renderer's HDR
 * pixel is the volume's light alone, I albedo / pi E_lpv, E_lpv the CPU twin's grid there
 * (2 further bounces, as the area-direct pass builds it) interpolated as composition does.
 * Tolerance 2e-3 relative: the GPU propagation (1e-4 above) and the running-mean grid's
 * half-float storage (2^-11). */
static void test_renderer_point_light(void **st)
{
    (void)st;
    static const char *const lpv[] = {"render.lpv=8", NULL};
    lr_scene *s = lr_test_scene("lampshade", lr_test_small_settings, lpv);
    enum { W = 64, H = 48 };
    lr_renderer *r = lr_test_renderer(gl, s, W, H, true, 1);
    lr_test_converge(r, 8);
    float *hdr = lr_test_hdr(r);
    const size_t texels = (size_t)LR_RECV_GRID * LR_RECV_GRID;
    double *g[2] = {malloc(texels * 3 * sizeof(double)), malloc(texels * 3 * sizeof(double))};
    assert_int_equal(lr_scene_receiver_count(s), 2);
    assert_non_null(g[0]);
    assert_non_null(g[1]);
    lr_err e = {0};
    lr_lpv_scene_desc d = {.n = 8, .bounces = 2};
    if (lr_lpv_scene_indirect(s, 0, &d, g, NULL, &e))
        fail_msg("%s", e.msg);
    double I[3];
    lr_light_rgb(lr_scene_light_at(s, 0), I);
    static const struct { int receiver; lr_vec3 p; } probes[] = {
        {0, {300.0, -150.0, 0.0}}, /* the table outside the light pool */
        {1, {200.0, 250.0, 300.0}}, /* the wall beside the shade */
    };
    for (int i = 0; i < 2; i++) {
        const lr_receiver *rc = lr_scene_receiver_at(s, probes[i].receiver);
        int x, y;
        assert_true(lr_test_project(s, W, H, probes[i].p, &x, &y));
        lr_vec3 p = lr_test_pixel_on_plane(s, W, H, x, y, rc->center, rc->normal);
        lr_recv_grid_frame f;
        assert_true(lr_recv_grid_frame_of(rc, &f));
        int idx[4];
        double w[4];
        lr_recv_grid_taps(&f, p, idx, w);
        for (int c = 0; c < 3; c++) {
            double E = 0.0;
            for (int k = 0; k < 4; k++)
                E += w[k] * g[probes[i].receiver][(size_t)idx[k] * 3 + c];
            double L = I[c] * rc->albedo[c] / M_PI * E, got = hdr[3 * ((size_t)y * W + x) + c];
            if (c == 0)
                printf("receiver %d at (%.0f, %.0f, %.0f): pixel %.4g, I albedo / pi E_lpv "
                       "%.4g\n", probes[i].receiver, p.x, p.y, p.z, got, L);
            assert_true(L > 0.0);
            assert_near(got, L, 2e-3 * L);
        }
    }
    free(g[0]);
    free(g[1]);
    free(hdr);
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
}

static void test_gpu_bad_parameters(void **st)
{
    (void)st;
    lr_err e = {0};
    lr_lpv_gpu *g = NULL;
    assert_int_equal(lr_lpv_gpu_create(gl, 1, NULL, &g, &e), LR_EINVAL);
    assert_null(g);
    assert_int_equal(lr_lpv_gpu_create(gl, 8, NULL, &g, &e), LR_OK);
    lr_lpv *v = scene(1); /* n 16 */
    assert_int_equal(lr_lpv_gpu_upload(g, v, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "n = 16"));
    assert_int_equal(lr_lpv_gpu_propagate(g, 33, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "steps = 33"));
    assert_int_equal(lr_lpv_gpu_download(g, v, &e), LR_EINVAL);
    lr_lpv_gpu_destroy(g);
    lr_lpv_destroy(v);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gpu_matches_twin),
        cmocka_unit_test(test_scene_grids_match_twin),
        cmocka_unit_test(test_point_scene_grids_match_twin),
        cmocka_unit_test(test_renderer_point_light),
        cmocka_unit_test(test_gpu_bad_parameters),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
