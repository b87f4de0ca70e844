/* A point light near the surface (issue 33 item 1; render/optics/near_light.h).
 *
 * A unit point light gives a surface point E = cos / d^2, which diverges as the light nears
 * the surface, while the power any patch of surface receives is bounded by the solid angle it
 * subtends (at most 2 pi). Asserted:
 *  1. The patch integral against closed forms: a square of side s = 2a with the light at
 *     height h above its centre subtends Omega = 4 asin(a^2 / (a^2 + h^2)) (the rectangle
 *     formula 4 asin(ab / sqrt((a^2 + h^2)(b^2 + h^2))) at a = b; 2 pi as h -> 0, s^2 / h^2 far
 *     away); above a corner, asin(s^2 / (s^2 + h^2)) (a quarter of the square of side 2 s);
 *     the sign flips behind the plane; the mean irradiance tends to cos / d^2 far away; the
 *     projected solid angle is pi times the parallel element's form factor.
 *  2. The diffusion grid on the candle: the flame lowered to 0.01 mm above the pool's floor,
 *     and moved to 0.01 mm off the pool's side, emits at most the light's power (4 pi per unit
 *     intensity; T_hem int B dA over the mesh), and within a factor 2 of what it emits 1 mm
 *     away. Why 2: from inside the pool the wax subtends between 2 pi and 4 pi, so what enters
 *     differs by at most 2 between any two positions there. Before the source was the cell's
 *     mean, the flame 0.01 mm above the floor emitted ~1e5 times the light's power. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "render/diffusion/dscene.h"
#include "render/mesh/mesh.h"
#include "render/optics/near_light.h"
#include "render/optics/optics.h"
#include "tests/support/mesh_quad.h"
#include "tests/support/near.h"
#include "tests/support/render.h"

static void test_square_closed_forms(void **state)
{
    (void)state;
    /* A tilted plane: the closed forms do not depend on the frame's orientation. */
    lr_vec3 normals[2] = {lr_v3(0, 0, 1), lr_v3_normalize(lr_v3(1, -2, 3))};
    lr_vec3 c = lr_v3(3, -1, 7);
    const double s = 2.0, a = 1.0;
    const double heights[] = {1e-6, 1e-3, 0.1, 0.5, 1.0, 3.0, 100.0, 1e4};
    for (int k = 0; k < 2; k++) {
        lr_vec3 n = normals[k], t1, t2;
        lr_near_light_frame(n, &t1, &t2);
        assert_near(lr_v3_dot(t1, n), 0.0, 1e-15);
        assert_near(lr_v3_dot(t2, n), 0.0, 1e-15);
        assert_near(lr_v3_dot(t1, t2), 0.0, 1e-15);
        assert_near(lr_v3_dot(lr_v3_cross(t1, t2), n), 1.0, 1e-15);
        for (size_t i = 0; i < sizeof heights / sizeof heights[0]; i++) {
            double h = heights[i];
            double want = 4.0 * asin(a * a / (a * a + h * h));
            lr_vec3 p = lr_v3_add(c, lr_v3_scale(n, h));
            double om = lr_solid_angle_square(p, c, n, s);
            assert_near_rel(om, want, 1e-9);
            assert_near_rel(lr_solid_angle_square(lr_v3_sub(c, lr_v3_scale(n, h)), c, n, s),
                            -want, 1e-9);
            assert_true(om <= 2.0 * M_PI);
            double mu, E = lr_patch_irradiance(p, c, n, s, &mu);
            assert_near_rel(E, want / (s * s), 1e-9);
            assert_near(lr_patch_irradiance(lr_v3_sub(c, lr_v3_scale(n, h)), c, n, s, NULL), 0.0,
                        0.0);
            /* Projected solid angle: pi times the form factor from a parallel element at p,
             * 4 (X / sqrt(1 + X^2)) atan(X / sqrt(1 + X^2)), X = a / h (four corner-aligned
             * a x a rectangles); pi as h -> 0, s^2 / h^2 far away. */
            double X = a / h, Y = X / sqrt(1.0 + X * X);
            double phi = 4.0 * Y * atan(Y);
            assert_near_rel(lr_projected_solid_angle_square(p, c, n, s), phi, 1e-9);
            assert_near_rel(mu, phi / want, 1e-9);
            /* Far away the mean is the point sample to O((s / h)^2). */
            if (h >= 100.0)
                assert_near_rel(E, 1.0 / (h * h), (s * s) / (h * h));
            /* Above a corner: the quarter of the square of side 2 s centred there. */
            lr_vec3 corner = lr_v3_add(c, lr_v3_scale(lr_v3_add(t1, t2), 0.5 * s));
            lr_vec3 pc = lr_v3_add(corner, lr_v3_scale(n, h));
            assert_near_rel(lr_solid_angle_square(pc, c, n, s), asin(s * s / (s * s + h * h)),
                            1e-9);
        }
    }
    /* A triangle seen from its own plane subtends nothing; the point sample at side 0. */
    assert_near(lr_solid_angle_triangle(lr_v3(5, 5, 0), lr_v3(0, 0, 0), lr_v3(1, 0, 0),
                                        lr_v3(0, 1, 0)),
                0.0, 1e-15);
    lr_vec3 p = lr_v3(0.3, 0.4, 2.0), n = lr_v3(0, 0, 1);
    double mu;
    assert_near_rel(lr_patch_irradiance(p, lr_v3(0, 0, 0), n, 0.0, &mu), 2.0 / pow(4.25, 1.5),
                    1e-12);
    assert_near_rel(mu, 2.0 / sqrt(4.25), 1e-12);
}

static const char *const candle_sets[] = {"objects[0].model=diffusion_grid",
                                          "objects[0].dgrid_h_mm=4",
                                          "lights[0].flicker.amplitude=0", NULL};

/* T_hem int B dA over the mesh per unit intensity: the field at the centroids of each
 * triangle's R^2 sub-triangles (R = ceil(longest edge / 1 mm)), times their area. */
typedef struct field_acc {
    lr_dfield_view v;
    double sum;
} field_acc;

static void add_field(void *user, size_t t, double u, double w, lr_vec3 x, lr_vec3 n, double dA)
{
    (void)t, (void)u, (void)w, (void)n;
    field_acc *a = user;
    double B[3];
    lr_dfield_eval(a->v.data, a->v.n, a->v.origin, a->v.h, x, B);
    a->sum += (B[0] + B[1] + B[2]) / 3.0 * dA;
}

static double object_power(const lr_scene *s, const lr_dscene *d)
{
    field_acc a = {.sum = 0.0};
    assert_true(lr_dscene_field(d, 0, 0, &a.v));
    const lr_scene_object *o = lr_scene_object_at(s, 0);
    lrt_mesh_quadrature(lr_bvh_mesh(o->bvh), 1.0, add_field, &a);
    return lr_hemi_transmittance(o->material.medium.eta) * a.sum;
}

static double power_at(lr_scene *s, lr_dscene *d, lr_vec3 x)
{
    char val[128];
    snprintf(val, sizeof val, "%.9g,%.9g,%.9g", x.x, x.y, x.z);
    lr_err e = {0};
    if (lr_scene_set(s, "lights[0].position", val, NULL, &e) || lr_dscene_update(d, s, &e))
        fail_msg("%s", e.msg);
    return object_power(s, d);
}

/* The pool triangle whose centroid is nearest to q: its centroid and outward normal. */
static void pool_face(const lr_scene *s, lr_vec3 q, lr_vec3 *c, lr_vec3 *n)
{
    const lr_mesh *m = lr_bvh_mesh(lr_scene_object_at(s, 0)->bvh);
    double best = INFINITY;
    for (size_t t = 0; t < lr_mesh_triangle_count(m); t++) {
        lr_vec3 p[3];
        lr_mesh_triangle(m, t, p);
        lr_vec3 g = lr_v3_scale(lr_v3_add(p[0], lr_v3_add(p[1], p[2])), 1.0 / 3.0);
        double dd = lr_v3_len(lr_v3_sub(g, q));
        if (dd < best) {
            best = dd;
            *c = g;
            *n = lr_mesh_triangle_normal(m, t);
        }
    }
}

static void sweep(lr_scene *s, lr_dscene *d, const char *label, lr_vec3 c, lr_vec3 n)
{
    const double dist[] = {5.0, 1.0, 0.1, 0.01};
    double P[4];
    for (int i = 0; i < 4; i++) {
        P[i] = power_at(s, d, lr_v3_add(c, lr_v3_scale(n, dist[i])));
        print_message("%s: light %5.2f mm off the wax: object power %.4g of the light's 4 pi\n",
                      label, dist[i], P[i] / (4.0 * M_PI));
    }
    for (int i = 0; i < 4; i++) {
        assert_true(isfinite(P[i]) && P[i] > 0.0);
        /* The grid's energy error (README: 0.96-0.99) is far inside this 5 %. */
        assert_true(P[i] <= 1.05 * 4.0 * M_PI);
    }
    assert_true(P[3] <= 2.0 * P[1] && P[3] >= 0.5 * P[1]);
}

static void test_grid_flame_near_wax(void **state)
{
    (void)state;
    lr_scene *s = lr_test_scene("candle", candle_sets, NULL);
    lr_dscene *d;
    lr_err e = {0};
    assert_int_equal(lr_dscene_create(&d, &e), LR_OK);
    /* The floor: the pool's lowest point (0, 0, 112), a vertex of the fan there. */
    sweep(s, d, "floor", lr_v3(0, 0, 112), lr_v3(0, 0, 1));
    /* The pool's side: a face 20 mm out, along its own normal. */
    lr_vec3 c, n;
    pool_face(s, lr_v3(20, 0, 115.3), &c, &n);
    assert_true(n.z > 0.5 && n.x < 0.0); /* facing up and in */
    print_message("side: face centroid (%.6f, %.6f, %.6f), normal (%.6f, %.6f, %.6f)\n", c.x,
                  c.y, c.z, n.x, n.y, n.z);
    sweep(s, d, "side", c, n);
    lr_dscene_destroy(d);
    lr_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_square_closed_forms),
        cmocka_unit_test(test_grid_flame_near_wax),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
