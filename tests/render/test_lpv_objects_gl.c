/* The light-propagation volume's light on the objects in the image (render/passes/lpv_pass.h,
 * lib/lpv_object.glsl) against the CPU twin's field (render/lpv/objfield.h, CPU propagation):
 * a ball in the dark in front of a wall that a spot lights, rendered with render.lpv = 8
 * (0: the ball is black) and no VPLs: on every ball pixel the HDR image is
 * I F_t(w_o) / pi B_ind(x, n),
 * B_ind = kR E(x, n) + kT E(x, -n) at the camera ray's hit, for the per-pixel gather
 * (compose_object.frag) and the surface cache (compose_cached.frag). The rasterised position
 * differs from the ray's hit by float rounding, which can put a pixel on the other side of an
 * interface the field switches at (nearest interface along each axis), so the assertion is on
 * the pixels' median and 90th-percentile relative error (<= 1e-5 and 1e-4: the GPU
 * propagation's 1e-9, fp32 texels and images; measured 5e-7 and 1.4e-6 gathered, 5.8e-7 and
 * 1.7e-6 cached) and on the sum over the ball (1e-4). The pass-table row: the lpv pass runs on the first
 * frame and after a material change, not after a camera move or a dimmer turn. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/cpu/frame.h"
#include "render/models/twin/radiosity.h"
#include "render/core/recv_grid.h"
#include "render/lpv/scene_lpv.h"
#include "render/mesh/bvh.h"
#include "render/optics/optics.h"
#include "render/renderer.h"
#include "tests/support/gl.h"
#include "tests/support/near.h"
#include "tests/support/render.h"

LR_TEST_GL_FIXTURE(gl)

enum { W = 64, H = 48 };

/* A marble ball (r 10 mm) 20 mm in front of a 40 x 40 mm wall; a spot 70 mm over the ball
 * aimed at the wall (cone 15-16 degrees: the wall is 4.5-14 degrees off its axis, the ball
 * 18-35), so the ball gets no direct light and its pixels are the volume's term alone. */
static const char *const BALL =
    "{\"name\": \"lpv_ball_spot\", \"objects\": [{\"name\": \"ball\", \"material\": "
    "{\"name\": \"m\", \"source\": \"marble preset\", \"base\": \"marble\"}, "
    "\"mesh\": {\"type\": \"sphere\", \"radius\": 10, \"subdivisions\": 3}, "
    "\"transform\": {\"translate\": [0, 30, -50]}}],"
    " \"lights\": [{\"type\": \"spot\", \"name\": \"spot\", \"position\": [0, 30, 20], "
    "\"direction\": [0, 0.4472136, -0.8944272], \"inner_deg\": 15, \"outer_deg\": 16, "
    "\"intensity\": 2}],"
    " \"camera\": {\"position\": [0, -100, -20], \"target\": [0, 30, -50], \"fov_deg\": 30},"
    " \"receivers\": [{\"name\": \"wall\", \"type\": \"plane\", \"center\": [0, 60, -50], "
    "\"normal\": [0, -1, 0], \"size\": [40, 40], \"albedo\": [0.8, 0.8, 0.8]}]}";

/* The ball gets no direct light, so its radiosity maps hold nothing the assertions read: they
 * run at the tests' small settings (tests/support/render.h) rather than the defaults (16 maps
 * of 256^2, 16 samples), which cost 93 % of this binary's CPU time in llvmpipe for nothing. The
 * volume's light does not depend on them: the wall's direct light, which the volume injects,
 * is the receiver grid's (LR_RECV_GRID), and the ball is outside the spot's cone, so no
 * shadow the G-buffer resolves falls on the wall. */
static lr_scene *ball_scene(const char *lpv, const char *cache)
{
    const char *sets[16];
    int n = 0;
    for (const char *const *a = lr_test_small_settings; *a; a++)
        sets[n++] = *a;
    sets[n++] = lpv;
    sets[n++] = cache;
    sets[n] = NULL;
    return lr_test_scene_text(BALL, sets);
}

static float *render(const char *lpv, const char *cache, lr_frame_stats *first)
{
    lr_scene *s = ball_scene(lpv, cache);
    lr_renderer *r = lr_test_renderer(gl, s, W, H, true, 1);
    lr_err e = {0};
    lr_frame_stats st;
    if (lr_renderer_frame(r, &st, &e))
        fail_msg("%s", e.msg);
    if (first)
        *first = st;
    lr_test_converge(r, 8);
    float *hdr = lr_test_hdr(r);
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
    return hdr;
}

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void parity(const char *cache)
{
    lr_frame_stats st;
    float *on = render("render.lpv=8", cache, &st), *off = render("render.lpv=0", cache, NULL);
    assert_true(st.passes & LR_PASS_LPV);
    lr_scene *s = ball_scene("render.lpv=8", cache);
    lr_lpv_objfield *f = NULL;
    lr_err e = {0};
    assert_int_equal(lr_lpv_objfield_create(&f, &e), LR_OK);
    const size_t texels = (size_t)LR_RECV_GRID * LR_RECV_GRID;
    double *g[8] = {NULL};
    assert_true(lr_scene_receiver_count(s) <= 8);
    for (int i = 0; i < lr_scene_receiver_count(s); i++)
        assert_non_null(g[i] = malloc(texels * 3 * sizeof(double)));
    lr_lpv_scene_desc d = {.n = 8, .bounces = 2, .objects = f};
    if (lr_lpv_scene_indirect(s, 0, &d, g, NULL, &e))
        fail_msg("%s", e.msg);
    double I[3], kR[3], kT[3];
    lr_light_rgb(lr_scene_light_at(s, 0), I);
    const lr_scene_object *o = lr_scene_object_at(s, 0);
    lr_lpv_object_factors(o, kR, kT);
    double *rel = malloc(sizeof *rel * W * H), sum_got = 0.0, sum_want = 0.0;
    assert_non_null(rel);
    int m = 0;
    for (int py = 0; py < H; py++)
        for (int px = 0; px < W; px++) {
            lr_vec3 org, dir, x, n;
            lr_cpu_camera_ray(s, W, H, px, py, &org, &dir);
            lr_hit h;
            double best = INFINITY;
            for (int i = 0; i < lr_scene_receiver_count(s); i++)
                if (lr_bvh_intersect(lr_scene_receiver_at(s, i)->bvh, org, dir, 0.0, best, &h))
                    best = h.t;
            if (!lr_bvh_intersect(o->bvh, org, dir, 0.0, best, &h) ||
                !lr_first_surface(o, org, dir, 0.0, &x, &n))
                continue;
            if (!o->closed && lr_v3_dot(n, dir) > 0.0)
                n = lr_v3_scale(n, -1.0);
            double ft = lr_fresnel_transmittance(fmax(0.0, -lr_v3_dot(n, dir)), o->coeffs.eta);
            double E[3], Eb[3];
            lr_lpv_objfield_irradiance(f, x, n, E);
            lr_lpv_objfield_irradiance(f, x, lr_v3_scale(n, -1.0), Eb);
            double want = I[0] * ft / M_PI * (kR[0] * E[0] + kT[0] * Eb[0]);
            size_t k = 3 * ((size_t)(H - 1 - py) * W + px); /* GL rows bottom up */
            double got = (double)on[k];
            assert_true(off[k] == 0.0f); /* no direct light on the ball */
            sum_got += got;
            sum_want += want;
            if (want > 0.0)
                rel[m++] = fabs(got - want) / want;
        }
    qsort(rel, (size_t)m, sizeof *rel, cmp);
    printf("%s: %d object pixels lit by the volume; median |gpu - twin| / twin %.2e, 90th "
           "percentile %.2e; sum gpu %.5g, twin %.5g\n", cache, m, rel[m / 2], rel[9 * m / 10],
           sum_got, sum_want);
    assert_true(m >= 100);
    assert_true(rel[m / 2] <= 1e-5);
    assert_true(rel[9 * m / 10] <= 1e-4);
    assert_near(sum_got, sum_want, 1e-4 * sum_want);
    free(rel);
    for (int i = 0; i < 8; i++)
        free(g[i]);
    lr_lpv_objfield_destroy(f);
    lr_scene_destroy(s);
    free(on);
    free(off);
}

static void test_gather_parity(void **st)
{
    (void)st;
    parity("render.surface_cache=false");
}

static void test_cached_parity(void **st)
{
    (void)st;
    parity("render.surface_cache=true");
}

/* The lpv row: due on the first frame and on a material change (with the maps), not on a
 * camera move or a dimmer turn; off (never run) with render.lpv 0. */
static void test_schedule(void **st)
{
    (void)st;
    const char *const sets[] = {"render.lpv=8", NULL};
    lr_scene *s = lr_test_scene("lampshade", lr_test_small_settings, sets);
    lr_renderer *r = lr_test_renderer(gl, s, 32, 24, true, 1);
    lr_err e = {0};
    lr_frame_stats st1;
    assert_int_equal(lr_renderer_frame(r, &st1, &e), LR_OK);
    assert_true(st1.passes & LR_PASS_LPV);
    assert_string_equal(lr_pass_name(7), "lpv");
    lr_test_converge(r, 8);
    lr_test_set(s, r, "camera.position", "[10, -400, 200]");
    assert_int_equal(lr_renderer_frame(r, &st1, &e), LR_OK);
    assert_false(st1.passes & LR_PASS_LPV);
    lr_test_set(s, r, "lights[0].intensity", "0.5");
    assert_int_equal(lr_renderer_frame(r, &st1, &e), LR_OK);
    assert_false(st1.passes & LR_PASS_LPV);
    lr_test_set(s, r, "objects[0].material", "marble");
    assert_int_equal(lr_renderer_frame(r, &st1, &e), LR_OK);
    assert_true(st1.passes & LR_PASS_LPV);
    assert_true(st1.passes & LR_PASS_RADIOSITY);
    lr_test_set(s, r, "render.lpv", "0");
    assert_int_equal(lr_renderer_frame(r, &st1, &e), LR_OK);
    assert_false(st1.passes & LR_PASS_LPV);
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gather_parity),
        cmocka_unit_test(test_cached_parity),
        cmocka_unit_test(test_schedule),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
