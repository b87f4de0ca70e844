/* The receiver irradiance grid (render/core/recv_grid.h), shared by the GPU's irradiance pass
 * and the CPU twin:
 *  - geometry: texel centres lie on the plane at the stated offsets, a texel centre's taps put
 *    all weight on that texel, points beyond the outer centres take the edge texels;
 *  - bilinear interpolation reproduces a function linear in the plane exactly (to rounding)
 *    between the centres;
 *  - the interpolation error on real emergent light: the candle's VPLs (unit B) over its table
 *    and wall, grid against the exact VPL sum at points between the texel centres. Bilinear
 *    error is about h^2/8 |E''|; E varies over at least sqrt(A_v) >= 10 mm against 4.7 mm
 *    texels, so the integrated (what an image sums) error is well below 1 %; asserted < 1 % of
 *    the sum (measured +0.05 % table, +0.001 % wall), and each point within 5 % of the largest
 *    E (measured 4.2 % on the table: the steep spots at the candle's foot, where the nearest
 *    VPLs are a few mm away; 0.5 % on the wall).
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "render/base/paths.h"
#include "render/core/recv_grid.h"
#include "render/base/rng.h"
#include "render/core/vpl.h"
#include "tests/support/near.h"

static lr_scene *load(const char *name)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/scenes/%s.json", lr_configs_dir(), name);
    lr_scene *s;
    lr_err e = {0};
    if (lr_scene_load(path, NULL, &s, &e))
        fail_msg("%s", e.msg);
    return s;
}

static void test_geometry(void **state)
{
    (void)state;
    lr_scene *s = load("candle");
    const lr_receiver *rc = lr_scene_receiver_at(s, 0);
    lr_recv_grid_frame f;
    assert_true(lr_recv_grid_frame_of(rc, &f));
    const double R = LR_RECV_GRID;
    const int cases[][2] = {{0, 0}, {17, 200}, {LR_RECV_GRID - 1, LR_RECV_GRID - 1}};
    for (int k = 0; k < 3; k++) {
        int si = cases[k][0], ti = cases[k][1];
        lr_vec3 x = lr_recv_grid_point(&f, si, ti), d = lr_v3_sub(x, rc->center);
        assert_near(lr_v3_dot(d, rc->normal), 0.0, 1e-9);
        assert_near(lr_v3_dot(d, f.a), ((si + 0.5) / R - 0.5) * rc->size[0], 1e-9);
        assert_near(lr_v3_dot(d, f.b), ((ti + 0.5) / R - 0.5) * rc->size[1], 1e-9);
        int idx[4];
        double w[4], sum = 0.0, at = 0.0;
        lr_recv_grid_taps(&f, x, idx, w);
        for (int q = 0; q < 4; q++) {
            sum += w[q];
            if (idx[q] == si + LR_RECV_GRID * ti)
                at += w[q];
        }
        assert_near(sum, 1.0, 1e-12);
        assert_near(at, 1.0, 1e-9);
    }
    /* Beyond the outermost centre (and beyond the plane): the corner texel alone. */
    lr_vec3 far = lr_v3_add(rc->center, lr_v3_add(lr_v3_scale(f.a, 0.6 * rc->size[0]),
                                                    lr_v3_scale(f.b, 0.6 * rc->size[1])));
    int idx[4];
    double w[4];
    lr_recv_grid_taps(&f, far, idx, w);
    for (int q = 0; q < 4; q++)
        assert_int_equal(idx[q], LR_RECV_GRID * LR_RECV_GRID - 1);
    /* A box receiver has no grid. */
    lr_receiver box = *rc;
    box.type = LR_RECEIVER_BOX;
    assert_false(lr_recv_grid_frame_of(&box, &f));
    lr_scene_destroy(s);
}

static void test_linear_is_exact(void **state)
{
    (void)state;
    lr_scene *s = load("candle");
    const lr_receiver *rc = lr_scene_receiver_at(s, 1);
    lr_recv_grid_frame f;
    assert_true(lr_recv_grid_frame_of(rc, &f));
    /* g(x) = 3 + 0.01 (x . a) - 0.02 (x . b) sampled at the centres, read anywhere inside. */
    lr_rng rng = lr_rng_init(5);
    for (int i = 0; i < 200; i++) {
        double u = (lr_rng_next(&rng) - 0.5) * (1.0 - 1.0 / LR_RECV_GRID) * f.w;
        double v = (lr_rng_next(&rng) - 0.5) * (1.0 - 1.0 / LR_RECV_GRID) * f.h;
        lr_vec3 x = lr_v3_add(f.c, lr_v3_add(lr_v3_scale(f.a, u), lr_v3_scale(f.b, v)));
        int idx[4];
        double w[4], got = 0.0;
        lr_recv_grid_taps(&f, x, idx, w);
        for (int q = 0; q < 4; q++) {
            lr_vec3 p = lr_recv_grid_point(&f, idx[q] % LR_RECV_GRID, idx[q] / LR_RECV_GRID);
            lr_vec3 d = lr_v3_sub(p, f.c);
            got += w[q] * (3.0 + 0.01 * lr_v3_dot(d, f.a) - 0.02 * lr_v3_dot(d, f.b));
        }
        assert_near(got, 3.0 + 0.01 * u - 0.02 * v, 1e-9);
    }
    lr_scene_destroy(s);
}

static void exact_E(const lr_scene *s, const lr_vpl_point *v, int n, lr_vec3 x, lr_vec3 nx,
                    double E[3])
{
    E[0] = E[1] = E[2] = 0.0;
    lr_vpl_point_irradiance(v, n, lr_scene_object_at(s, 0)->coeffs.eta, x, nx, E, NULL);
}

static void test_interpolation_error_candle(void **state)
{
    (void)state;
    lr_scene *s = load("candle");
    const int n = lr_scene_render(s)->N_vpl;
    lr_vpl_point *v = calloc((size_t)n, sizeof *v);
    assert_non_null(v);
    lr_vpl_place(lr_scene_object_at(s, 0), n, v);
    for (int i = 0; i < n; i++)
        v[i].B[0] = v[i].B[1] = v[i].B[2] = 1.0;
    lr_rng rng = lr_rng_init(9);
    for (int r = 0; r < lr_scene_receiver_count(s); r++) {
        const lr_receiver *rc = lr_scene_receiver_at(s, r);
        lr_recv_grid_frame f;
        assert_true(lr_recv_grid_frame_of(rc, &f));
        double sum_exact = 0.0, sum_diff = 0.0, worst = 0.0, Emax = 0.0;
        const int P = 4000;
        for (int i = 0; i < P; i++) {
            double u = (lr_rng_next(&rng) - 0.5) * f.w;
            double w2 = (lr_rng_next(&rng) - 0.5) * f.h;
            lr_vec3 x = lr_v3_add(f.c, lr_v3_add(lr_v3_scale(f.a, u), lr_v3_scale(f.b, w2)));
            double E[3], G = 0.0, Eq[3];
            exact_E(s, v, n, x, rc->normal, E);
            int idx[4];
            double w[4];
            lr_recv_grid_taps(&f, x, idx, w);
            for (int q = 0; q < 4; q++) {
                lr_vec3 p = lr_recv_grid_point(&f, idx[q] % LR_RECV_GRID, idx[q] / LR_RECV_GRID);
                exact_E(s, v, n, p, rc->normal, Eq);
                G += w[q] * Eq[1];
            }
            sum_exact += E[1];
            sum_diff += G - E[1];
            worst = fmax(worst, fabs(G - E[1]));
            Emax = fmax(Emax, E[1]);
        }
        print_message("%s: grid vs exact E_vpl over %d points: sum %+.3f %%, worst %.2f %% of "
                      "the largest\n", rc->name, P, 100.0 * sum_diff / sum_exact,
                      100.0 * worst / Emax);
        assert_true(sum_exact > 0.0);
        assert_true(fabs(sum_diff) < 0.01 * sum_exact);
        assert_true(worst < 0.05 * Emax);
    }
    free(v);
    lr_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_geometry),
        cmocka_unit_test(test_linear_is_exact),
        cmocka_unit_test(test_interpolation_error_candle),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
