/* Area lights (seed 004): the emitters' closed-form irradiance against independent closed
 * forms (on-axis disk pi L a^2/(a^2+h^2), the off-axis parallel disk's view factor, the
 * rectangle's corner view factor), sample sets (stratified, Poisson-disk) converging to them
 * within 1 %, the emission profile's power, and Poisson-disk samples on meshes: minimum
 * distance and coverage. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdlib.h>

#include "render/area/emitter.h"
#include "render/area/poisson_mesh.h"
#include "render/base/rng.h"
#include "render/mesh/shapes.h"
#include "tests/support/near.h"

static lr_area_emitter quad(lr_vec3 c, lr_vec3 u, lr_vec3 v, bool two)
{
    lr_area_emitter em;
    lr_err e;
    lr_err_clear(&e);
    if (lr_area_quad(c, u, v, two, &em, &e))
        fail_msg("quad: %s", e.msg);
    return em;
}

static lr_area_emitter disk(lr_vec3 c, lr_vec3 n, double a, bool two)
{
    lr_area_emitter em;
    lr_err e;
    lr_err_clear(&e);
    if (lr_area_disk(c, n, a, two, &em, &e))
        fail_msg("disk: %s", e.msg);
    return em;
}

/* View factor from a point to a parallel rectangle X c by Y c with one corner straight above
 * it at distance c (Howell's catalogue, case B-3), in X = x/c, Y = y/c. */
static double corner_factor(double x, double y, double c)
{
    double X = x / c, Y = y / c, a = sqrt(1 + X * X), b = sqrt(1 + Y * Y);
    return (X / a * atan(Y / a) + Y / b * atan(X / b)) / (2.0 * M_PI);
}

/* Point at height h below the parallel disk of radius a, offset rho from its axis (Howell
 * B-13): F = (1 - (h^2 + rho^2 - a^2) / sqrt((h^2 + rho^2 + a^2)^2 - 4 a^2 rho^2)) / 2. */
static double disk_factor(double a, double h, double rho)
{
    double s = h * h + rho * rho;
    return 0.5 * (1.0 - (s - a * a) / sqrt((s + a * a) * (s + a * a) - 4.0 * a * a * rho * rho));
}

static void test_disk_on_axis(void **st)
{
    (void)st;
    const double L = 2.5e-3, a = 20.0;
    lr_area_emitter d = disk(lr_v3(0, 0, 100), lr_v3(0, 0, -1), a, false);
    for (double h = 1.0; h <= 1000.0; h *= 3.0) {
        double want = M_PI * L * a * a / (a * a + h * h);
        assert_near_rel(lr_area_disk_irradiance_axis(L, a, h), want, 1e-15);
        /* The emitter's general path, on the axis and just beside it (the equal-area polygon). */
        lr_vec3 x = lr_v3(0, 0, 100 - h);
        assert_near_rel(lr_area_irradiance(&d, L, x, lr_v3(0, 0, 1)), want, 1e-12);
        assert_near_rel(lr_area_irradiance(&d, L, lr_v3(1e-3, 0, 100 - h), lr_v3(0, 0, 1)),
                        want, 1e-3);
    }
    /* Behind a one-sided disk nothing; a two-sided one lights both sides alike. */
    assert_near(lr_area_irradiance(&d, L, lr_v3(0, 0, 150), lr_v3(0, 0, -1)), 0.0, 0.0);
    lr_area_emitter d2 = disk(lr_v3(0, 0, 100), lr_v3(0, 0, -1), a, true);
    assert_near_rel(lr_area_irradiance(&d2, L, lr_v3(0, 0, 150), lr_v3(0, 0, -1)),
                    lr_area_disk_irradiance_axis(L, a, 50), 1e-12);
}

static void test_disk_off_axis(void **st)
{
    (void)st;
    const double L = 1.0, a = 15.0;
    lr_area_emitter d = disk(lr_v3(3, -2, 40), lr_v3(0, 0, -1), a, false);
    const double hs[] = {2.0, 10.0, 40.0}, rhos[] = {5.0, 14.0, 16.0, 40.0};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++) {
            lr_vec3 x = lr_v3(3 + rhos[j] * 0.6, -2 + rhos[j] * 0.8, 40 - hs[i]);
            double want = M_PI * L * disk_factor(a, hs[i], rhos[j]);
            /* The 256-gon of equal area: the rim (rho ~ a at small h) is the hardest case. */
            assert_near_rel(lr_area_irradiance(&d, L, x, lr_v3(0, 0, 1)), want, 1e-2);
            if (fabs(rhos[j] - a) > 0.5 * hs[i])
                assert_near_rel(lr_area_irradiance(&d, L, x, lr_v3(0, 0, 1)), want, 1e-3);
        }
}

static void test_quad_parallel(void **st)
{
    (void)st;
    const double L = 3e-4;
    lr_area_emitter q = quad(lr_v3(10, 20, 50), lr_v3(8, 0, 0), lr_v3(0, 3, 0), false);
    /* Emits toward +z (u x v): a point above, facing down. Straight above the centre the
     * rectangle is four corner rectangles of 8 x 3. */
    for (double h = 0.5; h < 500.0; h *= 2.7) {
        lr_vec3 x = lr_v3(10, 20, 50 + h);
        double want = 4.0 * M_PI * L * corner_factor(8, 3, h);
        assert_near_rel(lr_area_irradiance(&q, L, x, lr_v3(0, 0, -1)), want, 1e-9);
        /* Above a corner: the whole 16 x 6 rectangle by one corner factor. */
        lr_vec3 y = lr_v3(2, 17, 50 + h);
        assert_near_rel(lr_area_irradiance(&q, L, y, lr_v3(0, 0, -1)),
                        M_PI * L * corner_factor(16, 6, h), 1e-9);
        /* Outside the footprint, by superposition: (x 4..20 of 0..20) minus (0..4). */
        lr_vec3 z = lr_v3(-2, 17, 50 + h);
        assert_near_rel(lr_area_irradiance(&q, L, z, lr_v3(0, 0, -1)),
                        M_PI * L * (corner_factor(20, 6, h) - corner_factor(4, 6, h)), 1e-9);
        assert_near(lr_area_irradiance(&q, L, lr_v3(10, 20, 50 - h), lr_v3(0, 0, 1)), 0.0, 0.0);
    }
}

/* Sample-set estimates against the closed form, also for a tilted receiver whose horizon
 * cuts the quad (the clipping): within 1 %. */
static void test_samples_converge(void **st)
{
    (void)st;
    const double L = 1.0;
    lr_area_emitter q = quad(lr_v3(0, 0, 0), lr_v3(20, 0, 0), lr_v3(0, 5, 5), true);
    lr_area_emitter d = disk(lr_v3(0, 0, 0), lr_v3(0.3, 0.1, 1), 12.0, false);
    const lr_vec3 xs[] = {lr_v3(5, -20, 30), lr_v3(-30, 10, 25), lr_v3(0, -12, 18)};
    const lr_vec3 ns[] = {lr_v3(0, 0.6, -0.8), lr_v3(0.8, 0, -0.6), lr_v3(1, 0, 0)};
    enum { NS = 4096, NP_CAP = 2048 };
    lr_vec3 *pts = malloc(NS * sizeof *pts);
    assert_non_null(pts);
    for (int e = 0; e < 2; e++) {
        const lr_area_emitter *em = e ? &d : &q;
        for (int i = 0; i < 3; i++) {
            double want = lr_area_irradiance(em, L, xs[i], ns[i]);
            assert_true(want > 0.0);
            lr_area_stratified(em, NS, 7, pts);
            assert_near_rel(lr_area_irradiance_samples(em, pts, NS, L, xs[i], ns[i]), want,
                            1e-2);
            /* A Poisson-disk set of about 1000 points. */
            int n = 0;
            lr_err err;
            lr_err_clear(&err);
            assert_int_equal(lr_area_poisson(em, lr_area_poisson_radius(em->area, 1000),
                                             NP_CAP, 2000, 11, pts, &n, &err), LR_OK);
            assert_true(n > 600 && n < NP_CAP);
            /* On the rectangle the torus distance is at most the Euclidean one. */
            double r = lr_area_poisson_radius(em->area, 1000);
            for (int a = 0; e == 0 && a < n; a++)
                for (int b = a + 1; b < n; b++)
                    assert_true(lr_v3_len(lr_v3_sub(pts[a], pts[b])) >= r * (1 - 1e-9));
            assert_near_rel(lr_area_irradiance_samples(em, pts, n, L, xs[i], ns[i]), want,
                            1e-2);
        }
    }
    free(pts);
}

/* Area-uniform sampling: the mean point is the centre, the disk's mean r^2 is a^2/2, the quad's
 * mean s^2 (s along u in units of |u|) is 1/3. Stratified sets are exact to O(1/n). */
static void test_point_distribution(void **st)
{
    (void)st;
    enum { N = 10000 };
    lr_vec3 *p = malloc(N * sizeof *p);
    assert_non_null(p);
    lr_area_emitter d = disk(lr_v3(1, 2, 3), lr_v3(0, 1, 0), 10.0, false);
    lr_area_stratified(&d, N, 3, p);
    double r2 = 0.0, on = 0.0;
    lr_vec3 m = lr_v3(0, 0, 0);
    for (int i = 0; i < N; i++) {
        lr_vec3 q = lr_v3_sub(p[i], d.center);
        r2 += lr_v3_dot(q, q) / N;
        on = fmax(on, fabs(lr_v3_dot(q, d.normal)));
        m = lr_v3_add(m, lr_v3_scale(q, 1.0 / N));
        assert_true(lr_v3_len(q) <= 10.0 * (1 + 1e-12));
    }
    assert_near_rel(r2, 50.0, 2e-3);
    assert_near(lr_v3_len(m), 0.0, 0.02);
    assert_near(on, 0.0, 1e-12);
    lr_area_emitter q = quad(lr_v3(0, 0, 0), lr_v3(0, 0, 7), lr_v3(2, 0, 0), false);
    assert_near_rel(q.area, 4 * 14.0, 1e-15);
    lr_area_stratified(&q, N, 5, p);
    double s2 = 0.0;
    for (int i = 0; i < N; i++)
        s2 += (p[i].z / 7.0) * (p[i].z / 7.0) / N;
    assert_near_rel(s2, 1.0 / 3.0, 2e-3);
    free(p);
}

/* The emission profile A cos: power pi L A one-sided, 2 pi L A two-sided (quadrature over
 * the sphere of directions, midpoint rule in cos theta: exact for a linear integrand). */
static void test_intensity_power(void **st)
{
    (void)st;
    lr_area_emitter q = quad(lr_v3(0, 0, 0), lr_v3(3, 0, 0), lr_v3(0, 2, 0), false);
    for (int two = 0; two < 2; two++) {
        q.two_sided = two;
        double P = 0.0;
        const int nc = 200, nphi = 8;
        for (int i = 0; i < nc; i++)
            for (int j = 0; j < nphi; j++) {
                double c = -1.0 + (i + 0.5) * 2.0 / nc, s = sqrt(1 - c * c);
                double phi = 2 * M_PI * (j + 0.3) / nphi;
                lr_vec3 w = lr_v3(s * cos(phi), s * sin(phi), c);
                P += lr_area_intensity_factor(&q, w) * (2.0 / nc) * (2 * M_PI / nphi);
            }
        assert_near_rel(P, (two ? 2.0 : 1.0) * M_PI * q.area, 1e-9);
    }
}

static void test_invalid(void **st)
{
    (void)st;
    lr_area_emitter em;
    lr_err e;
    lr_err_clear(&e);
    assert_int_equal(lr_area_quad(lr_v3(0, 0, 0), lr_v3(1, 0, 0), lr_v3(2, 0, 0), false, &em,
                                  &e), LR_EINVAL);
    assert_int_equal(lr_area_quad(lr_v3(NAN, 0, 0), lr_v3(1, 0, 0), lr_v3(0, 1, 0), false, &em,
                                  &e), LR_EINVAL);
    assert_int_equal(lr_area_disk(lr_v3(0, 0, 0), lr_v3(0, 0, 0), 1, false, &em, &e), LR_EINVAL);
    assert_int_equal(lr_area_disk(lr_v3(0, 0, 0), lr_v3(0, 0, 1), 0, false, &em, &e), LR_EINVAL);
    lr_area_emitter q = quad(lr_v3(0, 0, 0), lr_v3(1, 0, 0), lr_v3(0, 1, 0), false);
    lr_vec3 p[4];
    int n = -1;
    assert_int_equal(lr_area_poisson(&q, 0.0, 4, 10, 1, p, &n, &e), LR_EINVAL);
    assert_int_equal(n, 0);
    assert_int_equal(lr_area_poisson(&q, 0.1, 0, 10, 1, p, &n, &e), LR_EINVAL);
    lr_poisson_set set;
    assert_int_equal(lr_poisson_mesh(NULL, 1.0, 10, 10, 1, &set, &e), LR_EINVAL);
    /* Degenerate polygons give 0, not NaN. */
    lr_vec3 v[3] = {lr_v3(0, 0, 1), lr_v3(1, 0, 1), lr_v3(2, 0, 1)};
    assert_near(lr_area_polygon_irradiance(v, 3, 1.0, lr_v3(0, 0, 0), lr_v3(0, 0, 1)), 0.0, 1e-15);
    assert_near(lr_area_polygon_irradiance(v, 2, 1.0, lr_v3(0, 0, 0), lr_v3(0, 0, 1)), 0.0, 0.0);
}

/* Poisson-disk samples on a mesh: no two closer than r_min (brute force over all pairs), and a
 * nearly maximal set: 20000 area-uniform surface points all lie within 2 r_min of a sample and
 * at least 99 % within r_min. On a sphere (curved, translucent-object-like) and a box (sharp
 * edges, receiver-like). */
static void check_mesh(const lr_mesh *m, double r)
{
    lr_poisson_set set;
    lr_err e;
    lr_err_clear(&e);
    assert_int_equal(lr_poisson_mesh(m, r, 100000, 3000, 42, &set, &e), LR_OK);
    double A = lr_mesh_area(m);
    /* Density: a maximal set in the plane holds between 1/(pi r^2) ... 2/(sqrt(3) r^2)
     * points per unit area (disks of radius r cover it; disks of r/2 are disjoint). */
    assert_true(set.n >= A / (M_PI * r * r));
    assert_true(set.n <= 1.2 * 2.0 * A / (sqrt(3.0) * r * r));
    assert_near_rel(set.s[0].area * set.n, A, 1e-12);
    for (int i = 0; i < set.n; i++)
        for (int j = i + 1; j < set.n; j++) {
            lr_vec3 d = lr_v3_sub(set.s[i].p, set.s[j].p);
            if (lr_v3_dot(d, d) < r * r)
                fail_msg("samples %d and %d are %g apart, r_min %g", i, j, lr_v3_len(d), r);
        }
    size_t nt = lr_mesh_triangle_count(m);
    lr_rng rng = lr_rng_init(99);
    int within = 0, tests = 20000;
    double worst = 0.0;
    for (int k = 0; k < tests; k++) {
        /* Area-uniform by rejection on the triangles' areas. */
        size_t t;
        double amax = 0.0;
        for (size_t i = 0; i < nt; i++)
            amax = fmax(amax, lr_mesh_triangle_area(m, i));
        do
            t = (size_t)(lr_rng_next(&rng) * nt);
        while (lr_rng_next(&rng) * amax > lr_mesh_triangle_area(m, t));
        lr_vec3 q[3];
        lr_mesh_triangle(m, t, q);
        double a = sqrt(lr_rng_next(&rng)), b = lr_rng_next(&rng);
        lr_vec3 p = lr_v3_add(lr_v3_scale(q[0], 1 - a), lr_v3_add(lr_v3_scale(q[1], a * (1 - b)),
                                                                 lr_v3_scale(q[2], a * b)));
        double best = INFINITY;
        for (int i = 0; i < set.n; i++)
            best = fmin(best, lr_v3_len(lr_v3_sub(p, set.s[i].p)));
        within += best <= r;
        worst = fmax(worst, best);
    }
    assert_true(worst <= 2.0 * r);
    assert_true(within >= 0.99 * tests);
    lr_poisson_set_free(&set);
}

static void test_poisson_mesh(void **st)
{
    (void)st;
    lr_err e;
    lr_err_clear(&e);
    lr_mesh *m;
    lr_sphere_desc sd = {.center = lr_v3(0, 0, 50), .radius = 40.0, .subdivisions = 4};
    assert_int_equal(lr_mesh_sphere(&sd, &m, &e), LR_OK);
    check_mesh(m, 6.0);
    lr_mesh_destroy(m);
    lr_box_desc bd = {.center = lr_v3(0, 0, 0), .size = lr_v3(100, 60, 20)};
    assert_int_equal(lr_mesh_box(&bd, &m, &e), LR_OK);
    check_mesh(m, 8.0);
    lr_mesh_destroy(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_disk_on_axis),      cmocka_unit_test(test_disk_off_axis),
        cmocka_unit_test(test_quad_parallel),     cmocka_unit_test(test_samples_converge),
        cmocka_unit_test(test_point_distribution), cmocka_unit_test(test_intensity_power),
        cmocka_unit_test(test_invalid),           cmocka_unit_test(test_poisson_mesh),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
