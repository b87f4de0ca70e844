/* Conforming midpoint refinement (render/mesh/refine.h), the surface cache's meshes (issue 11).
 *
 * On the shipped candle (a closed mesh with long side quads and a fan of pool triangles):
 * every edge at most h; the area and the winding kept (each refined triangle's normal is its
 * parent's); conforming (every undirected edge of the closed result, vertices identified by
 * position, is used exactly twice, in opposite directions: no T-junction); and the refined mesh is the same position and normal
 * field: at random barycentrics of a parent, lr_refined_locate's child and weights give the
 * parent's linear interpolation to float rounding. Bad bounds and a vertex limit are errors. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/mesh/refine.h"
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

static lr_vec3 tri_normal(lr_vec3 a, lr_vec3 b, lr_vec3 c)
{
    return lr_v3_cross(lr_v3_sub(b, a), lr_v3_sub(c, a));
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* Vertex ids by position: the candle duplicates vertices along its creases (one normal per
 * side), so conformity is a property of positions. */
static const float *g_pos;
static int cmp_pos(const void *a, const void *b)
{
    const float *p = g_pos + 3 * *(const uint32_t *)a, *q = g_pos + 3 * *(const uint32_t *)b;
    for (int j = 0; j < 3; j++)
        if (p[j] != q[j])
            return p[j] < q[j] ? -1 : 1;
    return 0;
}

static uint32_t *position_ids(const lr_refined *r)
{
    uint32_t *order = malloc(r->nv * sizeof *order), *id = malloc(r->nv * sizeof *id);
    assert_non_null(order);
    assert_non_null(id);
    for (size_t i = 0; i < r->nv; i++)
        order[i] = (uint32_t)i;
    g_pos = r->pos;
    qsort(order, r->nv, sizeof *order, cmp_pos);
    uint32_t next = 0;
    for (size_t i = 0; i < r->nv; i++) {
        if (i > 0 && cmp_pos(&order[i], &order[i - 1]) != 0)
            next++;
        id[order[i]] = next;
    }
    free(order);
    return id;
}

static void test_edges_area_winding_conforming(void **state)
{
    (void)state;
    lr_mesh *m = candle();
    const double h = 3.0;
    lr_refined r;
    lr_err e = {0};
    assert_int_equal(lr_refine(m, h, 0, &r, &e), LR_OK);
    print_message("candle: %zu vertices, %zu triangles -> %zu, %zu at h = %g mm\n",
                  lr_mesh_vertex_count(m), lr_mesh_triangle_count(m), r.nv, r.nt, h);
    assert_true(r.nt > lr_mesh_triangle_count(m));
    assert_int_equal(r.n_parents, lr_mesh_triangle_count(m));
    assert_int_equal(r.first[r.n_parents], r.nt);
    double area = 0.0, worst = 0.0;
    uint64_t *dir = malloc(3 * r.nt * sizeof *dir), *und = malloc(3 * r.nt * sizeof *und);
    uint32_t *id = position_ids(&r);
    assert_non_null(dir);
    assert_non_null(und);
    for (size_t t = 0; t < r.nt; t++) {
        lr_vec3 p[3];
        for (int j = 0; j < 3; j++)
            p[j] = at(r.pos, r.idx[3 * t + j]);
        for (int j = 0; j < 3; j++) {
            worst = fmax(worst, lr_v3_len(lr_v3_sub(p[(j + 1) % 3], p[j])));
            uint32_t a = id[r.idx[3 * t + j]], b = id[r.idx[3 * t + (j + 1) % 3]];
            dir[3 * t + j] = (uint64_t)a << 32 | b;
            und[3 * t + j] = a < b ? ((uint64_t)a << 32 | b) : ((uint64_t)b << 32 | a);
        }
        lr_vec3 n = tri_normal(p[0], p[1], p[2]);
        area += 0.5 * lr_v3_len(n);
        lr_vec3 pn = lr_mesh_triangle_normal(m, r.parent[t]);
        assert_true(lr_v3_dot(lr_v3_normalize(n), pn) > 0.999);
        assert_true(t >= r.first[r.parent[t]] && t < r.first[r.parent[t] + 1]);
    }
    assert_true(worst <= h * (1.0 + 1e-6));
    assert_true(fabs(area / lr_mesh_area(m) - 1.0) < 1e-5);
    /* Closed and conforming: each undirected edge twice, never the same direction twice. */
    qsort(und, 3 * r.nt, sizeof *und, cmp_u64);
    qsort(dir, 3 * r.nt, sizeof *dir, cmp_u64);
    for (size_t i = 0; i < 3 * r.nt; i += 2) {
        assert_true(und[i] == und[i + 1]);
        assert_true(i + 2 >= 3 * r.nt || und[i + 2] != und[i]);
    }
    for (size_t i = 1; i < 3 * r.nt; i++)
        assert_true(dir[i] != dir[i - 1]);
    free(dir);
    free(und);
    free(id);
    lr_refined_free(&r);
    lr_mesh_destroy(m);
}

/* The parent's interpolation of a per-vertex field at barycentrics (u, v). */
static lr_vec3 parent_field(const lr_mesh *m, const float *f, size_t t, double u, double v)
{
    const uint32_t *ix = lr_mesh_indices(m) + 3 * t;
    lr_vec3 a = at(f, ix[0]), b = at(f, ix[1]), c = at(f, ix[2]);
    return lr_v3_add(lr_v3_scale(a, 1.0 - u - v), lr_v3_add(lr_v3_scale(b, u), lr_v3_scale(c, v)));
}

static void test_same_field(void **state)
{
    (void)state;
    lr_mesh *m = candle();
    lr_refined r;
    lr_err e = {0};
    assert_int_equal(lr_refine(m, 2.0, 0, &r, &e), LR_OK);
    srand(5);
    double worst_p = 0.0, worst_n = 0.0, worst_w = 0.0;
    for (int i = 0; i < 20000; i++) {
        size_t t = (size_t)rand() % lr_mesh_triangle_count(m);
        double u = rand() / (RAND_MAX + 1.0), v = rand() / (RAND_MAX + 1.0);
        if (u + v > 1.0) {
            u = 1.0 - u;
            v = 1.0 - v;
        }
        double w[3];
        size_t k = lr_refined_locate(&r, t, u, v, w);
        assert_int_equal(r.parent[k], t);
        assert_true(fabs(w[0] + w[1] + w[2] - 1.0) < 1e-9);
        lr_vec3 p = lr_v3(0, 0, 0), n = lr_v3(0, 0, 0);
        for (int j = 0; j < 3; j++) {
            worst_w = fmin(worst_w, w[j]);
            p = lr_v3_add(p, lr_v3_scale(at(r.pos, r.idx[3 * k + j]), w[j]));
            n = lr_v3_add(n, lr_v3_scale(at(r.nrm, r.idx[3 * k + j]), w[j]));
        }
        worst_p = fmax(worst_p, lr_v3_len(lr_v3_sub(p, parent_field(m, lr_mesh_positions(m), t, u, v))));
        worst_n = fmax(worst_n, lr_v3_len(lr_v3_sub(n, parent_field(m, lr_mesh_normals(m), t, u, v))));
    }
    print_message("locate: worst position %.2g mm, normal %.2g, weight %.2g\n", worst_p, worst_n,
                  worst_w);
    /* Float storage of positions up to ~120 mm: 2^-24 * 120 per coordinate, a few roundings. */
    assert_true(worst_p < 1e-4);
    assert_true(worst_n < 1e-5);
    assert_true(worst_w > -1e-6);
    lr_refined_free(&r);
    lr_mesh_destroy(m);
}

static void test_nothing_to_split_and_errors(void **state)
{
    (void)state;
    lr_mesh *m = candle();
    lr_refined r;
    lr_err e = {0};
    assert_int_equal(lr_refine(m, 1e4, 0, &r, &e), LR_OK);
    assert_int_equal(r.nv, lr_mesh_vertex_count(m));
    assert_int_equal(r.nt, lr_mesh_triangle_count(m));
    assert_memory_equal(r.idx, lr_mesh_indices(m), 3 * r.nt * sizeof *r.idx);
    lr_refined_free(&r);
    assert_int_equal(lr_refine(m, 0.0, 0, &r, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "edge bound"));
    assert_int_equal(lr_refine(m, NAN, 0, &r, &e), LR_EINVAL);
    assert_int_equal(lr_refine(m, 0.5, 5000, &r, &e), LR_EUNSUPPORTED);
    assert_non_null(strstr(e.msg, "5000 vertices"));
    assert_null(r.pos);
    lr_refined_free(&r); /* idempotent on the zeroed result */
    lr_mesh_destroy(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_edges_area_winding_conforming),
        cmocka_unit_test(test_same_field),
        cmocka_unit_test(test_nothing_to_split_and_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
