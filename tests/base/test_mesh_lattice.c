/* Lattice refinement (render/mesh/lattice.h), the surface cache's entries and its per-pixel
 * lookup (issue 11: composition finds a pixel's three entries by arithmetic from its original
 * triangle and barycentrics, render/shaders/compose_cached.frag).
 *
 * On the shipped candle (long side quads and a fan of pool triangles) and the lamp shade:
 * each triangle's resolution is the least R with L / R <= h (L its longest edge), so every
 * sub-triangle edge is at most h; the counts are sum (R + 1)(R + 2) / 2 vertices and sum R^2
 * triangles; the sub-triangles tile their parent (areas sum to the parent's, winding kept).
 * The lookup: at random barycentrics of random triangles, lr_lattice_locate's sub-triangle
 * holds the point (weights in [0, 1], its corners' (u, v) interpolate back to the point) and
 * the interpolation of the lattice's stored positions and normals gives the parent's linear
 * interpolation, to float rounding of the stored values: a few float ulps of the largest
 * coordinate (|x| <= 300 mm: 300 x 2^-24 = 1.8e-5 mm per ulp; 1e-4 mm asserted). The
 * interpolation of any field that is linear over the surface is therefore exact up to that
 * rounding. Bad bounds and a vertex limit are errors. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/mesh/lattice.h"
#include "render/mesh/shapes.h"

static lr_mesh *candle(void)
{
    lr_candle_desc d = {.radius = 35, .height = 120, .pool_depth = 8, .pool_radius = 31};
    lr_mesh *m = NULL;
    lr_err e = {0};
    assert_int_equal(lr_mesh_candle(&d, &m, &e), LR_OK);
    return m;
}

static lr_vec3 at(const float *p, size_t i) { return lr_v3(p[3 * i], p[3 * i + 1], p[3 * i + 2]); }

static double edge(lr_vec3 a, lr_vec3 b) { return lr_v3_len(lr_v3_sub(a, b)); }

/* xorshift64*: reproducible barycentrics. */
static double rnd(uint64_t *s)
{
    *s ^= *s >> 12;
    *s ^= *s << 25;
    *s ^= *s >> 27;
    return (double)((*s * 0x2545F4914F6CDD1Dull) >> 11) * 0x1.0p-53;
}

static void check(const lr_mesh *m, double h)
{
    lr_refined r;
    lr_err e = {0};
    assert_int_equal(lr_refine_lattice(m, h, 0, &r, &e), LR_OK);
    size_t nt = lr_mesh_triangle_count(m), nv = 0, ntr = 0;
    assert_int_equal(r.n_parents, nt);
    const float *P = lr_mesh_positions(m), *N = lr_mesh_normals(m);
    const uint32_t *ix = lr_mesh_indices(m);
    for (size_t t = 0; t < nt; t++) {
        lr_vec3 p[3];
        lr_mesh_triangle(m, t, p);
        double L = fmax(edge(p[0], p[1]), fmax(edge(p[1], p[2]), edge(p[2], p[0])));
        size_t R = r.lat_R[t];
        assert_true(R >= 1);
        assert_true(L / (double)R <= h * (1.0 + 1e-9));
        if (R > 1)
            assert_true(L / (double)(R - 1) > h);
        assert_int_equal(r.lat_base[t], nv);
        assert_int_equal(r.first[t], ntr);
        nv += (R + 1) * (R + 2) / 2;
        ntr += R * R;
        /* The sub-triangles tile the parent: their areas sum to its area, each is turned
         * the parent's way, every edge at most h. */
        lr_vec3 np = lr_v3_cross(lr_v3_sub(p[1], p[0]), lr_v3_sub(p[2], p[0]));
        double area = 0.0;
        for (size_t q = r.first[t]; q < r.first[t + 1]; q++) {
            assert_int_equal(r.parent[q], t);
            lr_vec3 a = at(r.pos, r.idx[3 * q]), b = at(r.pos, r.idx[3 * q + 1]),
                    c = at(r.pos, r.idx[3 * q + 2]);
            lr_vec3 n = lr_v3_cross(lr_v3_sub(b, a), lr_v3_sub(c, a));
            assert_true(lr_v3_dot(n, np) > 0.0);
            area += lr_v3_len(n);
            assert_true(fmax(edge(a, b), fmax(edge(b, c), edge(c, a))) <= h * (1.0 + 1e-5));
        }
        assert_true(fabs(area - lr_v3_len(np)) <= 1e-4 * lr_v3_len(np));
    }
    assert_int_equal(r.nv, nv);
    assert_int_equal(r.nt, ntr);
    uint64_t seed = 0x9E3779B97F4A7C15ull;
    for (int k = 0; k < 20000; k++) {
        size_t t = (size_t)(rnd(&seed) * (double)nt) % nt;
        double u = rnd(&seed), v = rnd(&seed);
        if (u + v > 1.0)
            u = 1.0 - u, v = 1.0 - v;
        double w[3];
        size_t q = lr_refined_locate(&r, t, u, v, w);
        assert_true(q >= r.first[t] && q < r.first[t + 1]);
        assert_true(fabs(w[0] + w[1] + w[2] - 1.0) < 1e-12);
        double uu = 0.0, vv = 0.0;
        lr_vec3 x = lr_v3(0, 0, 0), n = lr_v3(0, 0, 0);
        for (int j = 0; j < 3; j++) {
            assert_true(w[j] >= -1e-9 && w[j] <= 1.0 + 1e-9);
            uu += w[j] * r.uv[6 * q + 2 * j];
            vv += w[j] * r.uv[6 * q + 2 * j + 1];
            x = lr_v3_add(x, lr_v3_scale(at(r.pos, r.idx[3 * q + j]), w[j]));
            n = lr_v3_add(n, lr_v3_scale(at(r.nrm, r.idx[3 * q + j]), w[j]));
        }
        assert_true(fabs(uu - u) < 1e-6 && fabs(vv - v) < 1e-6);
        double w0 = 1.0 - u - v;
        const uint32_t *c = ix + 3 * t;
        lr_vec3 xe = lr_v3_add(lr_v3_add(lr_v3_scale(at(P, c[0]), w0), lr_v3_scale(at(P, c[1]), u)),
                               lr_v3_scale(at(P, c[2]), v));
        lr_vec3 ne = lr_v3_add(lr_v3_add(lr_v3_scale(at(N, c[0]), w0), lr_v3_scale(at(N, c[1]), u)),
                               lr_v3_scale(at(N, c[2]), v));
        assert_true(edge(x, xe) < 1e-4);
        assert_true(edge(n, ne) < 1e-6); /* unit normals: |n| <= 1 */
    }
    lr_refined_free(&r);
}

static void test_candle(void **state)
{
    (void)state;
    lr_mesh *m = candle();
    check(m, 1.09); /* the candle's edge bound at 256^2 maps (PIPELINE.md "Surface cache") */
    check(m, 7.0);
    lr_mesh_destroy(m);
}

static void test_shade(void **state)
{
    (void)state;
    lr_shade_desc d = {.radius_bottom = 110, .radius_top = 70, .height = 170, .thickness = 1.5,
                       .segments = 96};
    lr_mesh *m = NULL;
    lr_err e = {0};
    assert_int_equal(lr_mesh_shade(&d, &m, &e), LR_OK);
    check(m, 2.17);
    lr_mesh_destroy(m);
}

/* Points just outside the triangle (rounding in the rasteriser's barycentrics) clamp into the
 * nearest cell: the weights extrapolate a little but sum to 1, and the cell is the parent's. */
static void test_outside_clamps(void **state)
{
    (void)state;
    lr_mesh *m = candle();
    lr_refined r;
    lr_err e = {0};
    assert_int_equal(lr_refine_lattice(m, 1.09, 0, &r, &e), LR_OK);
    for (size_t t = 0; t < r.n_parents; t += 97) {
        const double uv[][2] = {{-1e-6, 0.5}, {0.5, -1e-6}, {0.5 + 1e-6, 0.5}, {1.0 + 1e-6, 0.0}};
        for (size_t k = 0; k < sizeof uv / sizeof uv[0]; k++) {
            double w[3];
            size_t q = lr_lattice_locate(&r, t, uv[k][0], uv[k][1], w);
            assert_true(q >= r.first[t] && q < r.first[t + 1]);
            assert_true(fabs(w[0] + w[1] + w[2] - 1.0) < 1e-12);
            for (int j = 0; j < 3; j++)
                assert_true(w[j] > -1e-4 && w[j] < 1.0 + 1e-4);
        }
    }
    lr_refined_free(&r);
    lr_mesh_destroy(m);
}

static void test_errors(void **state)
{
    (void)state;
    lr_mesh *m = candle();
    lr_refined r;
    lr_err e = {0};
    assert_int_equal(lr_refine_lattice(m, 0.0, 0, &r, &e), LR_EINVAL);
    assert_int_equal(lr_refine_lattice(m, NAN, 0, &r, &e), LR_EINVAL);
    assert_int_equal(lr_refine_lattice(m, 1.0, 1000, &r, &e), LR_EUNSUPPORTED);
    assert_non_null(strstr(e.msg, "1000"));
    lr_mesh_destroy(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_candle),
        cmocka_unit_test(test_shade),
        cmocka_unit_test(test_outside_clamps),
        cmocka_unit_test(test_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
