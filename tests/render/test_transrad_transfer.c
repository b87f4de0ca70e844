/* The precomputed transfer of translucent radiosity (render/transrad/transfer.c; seed 000's
 * T = (I - S F)^-1 S for relighting, issue 14 part 3):
 *  - on the lamp shade (translucent multipole wall, table and wall receivers; coarse patches so
 *    that the dense factors stay small), the transfer's W, the renderer's map value and the
 *    irradiance H equal the Gauss-Seidel sweeps' run to a 1e-12 tolerance: the sweeps stop
 *    within about tolerance / (1 - rho) of the fixed point, so the two agree to 1e-8 (power-
 *    weighted L1), for the shipped point light, after a light move, and for a quad light;
 *  - the fixed point's own residual after the transfer is at rounding (< 1e-12);
 *  - over the budget nothing is built and the sweeps run (lr_tr_transfer_bytes 0). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/transrad/transrad.h"
#include "tests/support/near.h"
#include "tests/support/render.h"

static lr_scene *load(const char *name)
{
    static const char *const model[] = {"objects[0].model=translucent_radiosity", NULL};
    return lr_test_scene(name, model, NULL);
}

static lr_tr *create(const lr_scene *s, int transfer_mb)
{
    lr_tr_settings set = {.patch_mm = 30, .receiver_mm = 150, .rays_per_patch = 128,
                          .max_iterations = 2000, .tolerance = 1e-12, .seed = 5,
                          .transfer_mb = transfer_mb};
    lr_tr *t;
    lr_err e = {0};
    if (lr_tr_create_scene(s, &set, &t, &e))
        fail_msg("%s", e.msg);
    return t;
}

/* Power-weighted L1 difference of the two solutions (W, map value, H), relative. */
static double differ(const lr_tr *a, const lr_tr *b)
{
    double dn = 0, nn = 0;
    for (size_t p = 0; p < lr_tr_patch_count(a); p++) {
        double A, wa[3][3], wb[3][3];
        lr_tr_patch_geometry(a, p, NULL, NULL, &A);
        lr_tr_radiosity(a, 0, p, wa[0]);
        lr_tr_radiosity(b, 0, p, wb[0]);
        lr_tr_map_radiosity(a, 0, p, wa[1]);
        lr_tr_map_radiosity(b, 0, p, wb[1]);
        lr_tr_irradiance(a, 0, p, wa[2]);
        lr_tr_irradiance(b, 0, p, wb[2]);
        for (int k = 0; k < 3; k++)
            for (int c = 0; c < 3; c++) {
                dn += A * fabs(wa[k][c] - wb[k][c]);
                nn += A * fabs(wb[k][c]);
            }
    }
    return nn > 0 ? dn / nn : INFINITY;
}

static void both(lr_tr *x, lr_tr *it, const lr_light *L, const char *what)
{
    lr_tr_stats sx, si;
    lr_err e = {0};
    if (lr_tr_solve_light(x, L, 0, &sx, &e) || lr_tr_solve_light(it, L, 0, &si, &e))
        fail_msg("%s", e.msg);
    double d = differ(x, it);
    print_message("%s: transfer (residual %.1e) vs %d sweeps (residual %.1e): differ %.2e\n",
                  what, sx.residual, si.iterations, si.residual, d);
    assert_true(sx.transfer && sx.iterations == 0);
    assert_false(si.transfer);
    assert_true(sx.residual < 1e-12);
    assert_true(d < 1e-8);
}

static void test_transfer_equals_sweeps(void **state)
{
    (void)state;
    lr_scene *s = load("lampshade");
    lr_tr *x = create(s, 256), *it = create(s, 0);
    size_t n = lr_tr_patch_count(x);
    assert_int_equal(n, lr_tr_patch_count(it));
    assert_int_equal(lr_tr_transfer_bytes(x), 24 * n * n + 12 * n);
    assert_int_equal(lr_tr_transfer_bytes(it), 0);
    print_message("lampshade, coarse: %zu patches, transfer %.1f MB\n", n,
                  lr_tr_transfer_bytes(x) / 1048576.0);
    lr_light L = *lr_scene_light_at(s, 0);
    both(x, it, &L, "point light");
    L.position.x += 15;
    L.position.z -= 10;
    both(x, it, &L, "moved 18 mm");
    lr_light q = {.type = LR_LIGHT_QUAD, .name = "panel", .position = L.position,
                  .edge_u = {10, 0, 0}, .edge_v = {0, 10, 0}, .intensity = 1,
                  .color = {1, 1, 1}, .two_sided = true};
    both(x, it, &q, "quad light");
    lr_tr_destroy(x);
    lr_tr_destroy(it);
    lr_scene_destroy(s);
}

static void test_over_budget_sweeps(void **state)
{
    (void)state;
    lr_scene *s = load("lampshade");
    lr_tr *t = create(s, 1); /* 1 MB: a few hundred patches need more */
    assert_true(lr_tr_transfer_bytes(t) == 0);
    lr_tr_stats st;
    lr_err e = {0};
    if (lr_tr_solve_light(t, lr_scene_light_at(s, 0), 0, &st, &e))
        fail_msg("%s", e.msg);
    assert_false(st.transfer);
    assert_true(st.iterations > 0 && st.residual < 1e-12);
    lr_tr_destroy(t);
    lr_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_transfer_equals_sweeps),
        cmocka_unit_test(test_over_budget_sweeps),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
