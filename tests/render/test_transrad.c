/* Translucent radiosity (seed 000; render/transrad/transrad.h):
 *  - form factors by ray casts against closed forms (Howell's catalogue): coaxial parallel
 *    disks (C-41), directly opposed rectangles (C-11), perpendicular rectangles with a common
 *    edge (C-14); within 1 %, and reciprocity A_1 F_12 = A_2 F_21 within 1 %. The estimator is
 *    a hit frequency: with N rays its standard error is sqrt(F (1 - F) / N), 0.1 % at 2e5;
 *    the quasi-random set does better;
 *  - an integrating sphere (diffuse, albedo rho, inner faces, a unit point light at its
 *    centre): W = rho E / (1 - rho) on every patch within 3 % (E = 1/R^2 on a facet up to the
 *    facets' distance from the centre), total power rho 4 pi / (1 - rho) within 1 %;
 *  - sphere_shell (albedo 1, light inside): all 4 pi I leaves the shell, within 2 %;
 *  - S: every column leaves the model's plane total (sum_j A_j S_ji / A_i, the normalisation),
 *    and no light crosses air: two boxes 2 mm apart in one mesh exchange nothing;
 *  - the solve: residual <= 0.5 % within 10 Jacobi sweeps on the shipped lamp shade, votive
 *    and sphere_shell (seed 000 Sec. 6: "5-10 iterations ... residual error of 0.5 %"); a warm
 *    start from the same light needs one sweep;
 *  - bad input: no mesh, a multipole without thickness, albedo above 1, NaN irradiance.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/paths.h"
#include "render/mesh/shapes.h"
#include "render/transrad/transrad.h"
#include "tests/support/near.h"
#include "tests/support/objects.h"

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

/* A disk of radius r at height z, facing up or down, as a fan of `seg` triangles. */
static lr_mesh *disk(double r, double z, bool up, int seg)
{
    double *pos = malloc((size_t)(seg + 1) * 3 * sizeof *pos);
    uint32_t *idx = malloc((size_t)seg * 3 * sizeof *idx);
    pos[0] = 0;
    pos[1] = 0;
    pos[2] = z;
    for (int i = 0; i < seg; i++) {
        double a = 2 * M_PI * i / seg;
        pos[3 * (i + 1) + 0] = r * cos(a);
        pos[3 * (i + 1) + 1] = r * sin(a);
        pos[3 * (i + 1) + 2] = z;
        uint32_t b = (uint32_t)(i + 1), c = (uint32_t)((i + 1) % seg + 1);
        idx[3 * i + 0] = 0;
        idx[3 * i + 1] = up ? b : c;
        idx[3 * i + 2] = up ? c : b;
    }
    lr_mesh_desc d = {.name = "disk", .vertex_count = (size_t)seg + 1, .positions = pos,
                      .triangle_count = (size_t)seg, .indices = idx,
                      .checks = {.flags = LR_MESH_OPEN_OK | LR_MESH_KEEP_WINDING}};
    lr_mesh *m;
    lr_err e = {0};
    if (lr_mesh_create(&d, &m, &e))
        fail_msg("%s", e.msg);
    free(pos);
    free(idx);
    return m;
}

static lr_mesh *quad(lr_vec3 c, lr_vec3 n, lr_vec3 u, double su, double sv)
{
    lr_quad_desc q = {.center = c, .normal = n, .u_dir = u, .size_u = su, .size_v = sv};
    lr_mesh *m;
    lr_err e = {0};
    if (lr_mesh_quad(&q, &m, &e))
        fail_msg("%s", e.msg);
    return m;
}

static lr_tr_surface_desc plane_desc(const lr_mesh *m, const lr_bvh *b, lr_vec3 c, lr_vec3 n,
                                     lr_vec3 u, double su, double sv)
{
    return (lr_tr_surface_desc){.kind = LR_TR_PLANE, .mesh = m, .bvh = b, .center = c,
                                .normal = n, .u_dir = u, .size_u = su, .size_v = sv,
                                .cells_u = 1, .cells_v = 1, .albedo = {0.5, 0.5, 0.5}};
}

static const lr_tr_settings ff_settings = {.rays_per_patch = 200000, .threads = 0, .seed = 7};

static void test_ff_coaxial_disks(void **state)
{
    (void)state;
    const double r1 = 50, r2 = 80, h = 60;
    lr_mesh *a = disk(r1, 0, true, 512), *b = disk(r2, h, false, 512);
    lr_bvh *ba = lrt_bvh(a), *bb = lrt_bvh(b);
    lr_tr_surface_desc d[2] = {
        {.kind = LR_TR_DIFFUSE, .mesh = a, .bvh = ba, .patch_mm = 1e4},
        {.kind = LR_TR_DIFFUSE, .mesh = b, .bvh = bb, .patch_mm = 1e4},
    };
    lr_tr *t;
    lr_err e = {0};
    if (lr_tr_create(d, 2, &ff_settings, &t, &e))
        fail_msg("%s", e.msg);
    assert_int_equal(lr_tr_patch_count(t), 2);
    /* Howell C-41: R_i = r_i / h, X = 1 + (1 + R2^2) / R1^2, F12 = (X - sqrt(X^2 - 4 (R2/R1)^2)) / 2 */
    double R1 = r1 / h, R2 = r2 / h, X = 1 + (1 + R2 * R2) / (R1 * R1);
    double F12 = 0.5 * (X - sqrt(X * X - 4 * (R2 / R1) * (R2 / R1)));
    double A1, A2;
    lr_tr_patch_geometry(t, 0, NULL, NULL, &A1);
    lr_tr_patch_geometry(t, 1, NULL, NULL, &A2);
    double f12 = lr_tr_form_factor(t, 0, 1), f21 = lr_tr_form_factor(t, 1, 0);
    print_message("coaxial disks: F12 %.5f closed form %.5f (%+.3f %%), F21 %.5f\n", f12, F12,
                  100 * (f12 / F12 - 1), f21);
    assert_near_rel(f12, F12, 0.01);
    assert_near_rel(A2 * f21, A1 * f12, 0.01);
    assert_near(lr_tr_escape(t, 0), 1 - f12, 1e-6); /* F is stored as float */
    lr_tr_destroy(t);
    lr_bvh_destroy(ba);
    lr_bvh_destroy(bb);
    lr_mesh_destroy(a);
    lr_mesh_destroy(b);
}

static double ff_opposed(double X, double Y)
{
    double a = sqrt((1 + X * X) * (1 + Y * Y) / (1 + X * X + Y * Y));
    return 2 / (M_PI * X * Y) *
           (log(a) + X * sqrt(1 + Y * Y) * atan(X / sqrt(1 + Y * Y)) +
            Y * sqrt(1 + X * X) * atan(Y / sqrt(1 + X * X)) - X * atan(X) - Y * atan(Y));
}

static double ff_perpendicular(double W, double H)
{
    double W2 = W * W, H2 = H * H, s = sqrt(H2 + W2);
    double l = log((1 + W2) * (1 + H2) / (1 + W2 + H2)) +
               W2 * log(W2 * (1 + W2 + H2) / ((1 + W2) * (W2 + H2))) +
               H2 * log(H2 * (1 + H2 + W2) / ((1 + H2) * (H2 + W2)));
    return (W * atan(1 / W) + H * atan(1 / H) - s * atan(1 / s) + 0.25 * l) / (M_PI * W);
}

static void test_ff_rectangles(void **state)
{
    (void)state;
    lr_err e = {0};
    /* Directly opposed: a x b at distance c. */
    {
        const double a = 100, b = 60, c = 80;
        lr_vec3 n0 = lr_v3(0, 0, 1), n1 = lr_v3(0, 0, -1), u = lr_v3(1, 0, 0);
        lr_mesh *m0 = quad(lr_v3(0, 0, 0), n0, u, a, b), *m1 = quad(lr_v3(0, 0, c), n1, u, a, b);
        lr_bvh *b0 = lrt_bvh(m0), *b1 = lrt_bvh(m1);
        lr_tr_surface_desc d[2] = {plane_desc(m0, b0, lr_v3(0, 0, 0), n0, u, a, b),
                                   plane_desc(m1, b1, lr_v3(0, 0, c), n1, u, a, b)};
        lr_tr *t;
        if (lr_tr_create(d, 2, &ff_settings, &t, &e))
            fail_msg("%s", e.msg);
        double F = ff_opposed(a / c, b / c), f = lr_tr_form_factor(t, 0, 1);
        print_message("opposed rectangles: F %.5f closed form %.5f (%+.3f %%)\n", f, F,
                      100 * (f / F - 1));
        assert_near_rel(f, F, 0.01);
        assert_near_rel(lr_tr_form_factor(t, 1, 0), F, 0.01);
        lr_tr_destroy(t);
        lr_bvh_destroy(b0);
        lr_bvh_destroy(b1);
        lr_mesh_destroy(m0);
        lr_mesh_destroy(m1);
    }
    /* Perpendicular with a common edge of length l along y: floor w (x in [0, w]), wall h
     * (z in [0, h]) at x = 0 facing +x. */
    {
        const double l = 100, w = 70, h = 120;
        lr_vec3 c0 = lr_v3(w / 2, 0, 0), c1 = lr_v3(0, 0, h / 2);
        lr_vec3 n0 = lr_v3(0, 0, 1), n1 = lr_v3(1, 0, 0), uy = lr_v3(0, 1, 0);
        lr_mesh *m0 = quad(c0, n0, uy, l, w), *m1 = quad(c1, n1, uy, l, h);
        lr_bvh *b0 = lrt_bvh(m0), *b1 = lrt_bvh(m1);
        lr_tr_surface_desc d[2] = {plane_desc(m0, b0, c0, n0, uy, l, w),
                                   plane_desc(m1, b1, c1, n1, uy, l, h)};
        lr_tr *t;
        if (lr_tr_create(d, 2, &ff_settings, &t, &e))
            fail_msg("%s", e.msg);
        /* Howell C-14 from the floor (width w) to the wall (height h): W = w/l, H = h/l. */
        double F01 = ff_perpendicular(w / l, h / l), F10 = ff_perpendicular(h / l, w / l);
        double f01 = lr_tr_form_factor(t, 0, 1), f10 = lr_tr_form_factor(t, 1, 0);
        print_message("perpendicular rectangles: F %.5f / %.5f closed form %.5f / %.5f\n", f01,
                      f10, F01, F10);
        assert_near_rel(f01, F01, 0.01);
        assert_near_rel(f10, F10, 0.01);
        assert_near_rel(w * f01, h * f10, 0.01);
        lr_tr_destroy(t);
        lr_bvh_destroy(b0);
        lr_bvh_destroy(b1);
        lr_mesh_destroy(m0);
        lr_mesh_destroy(m1);
    }
}

static void test_integrating_sphere(void **state)
{
    (void)state;
    const double R = 100, rho = 0.8;
    lr_sphere_desc sd = {.radius = R, .subdivisions = 3};
    lr_mesh *out;
    lr_err e = {0};
    if (lr_mesh_sphere(&sd, &out, &e))
        fail_msg("%s", e.msg);
    /* The same sphere with faces turned inward. */
    size_t nv = lr_mesh_vertex_count(out), nt = lr_mesh_triangle_count(out);
    double *pos = malloc(nv * 3 * sizeof *pos);
    uint32_t *idx = malloc(nt * 3 * sizeof *idx);
    for (size_t i = 0; i < 3 * nv; i++)
        pos[i] = lr_mesh_positions(out)[i];
    for (size_t i = 0; i < nt; i++) {
        idx[3 * i] = lr_mesh_indices(out)[3 * i];
        idx[3 * i + 1] = lr_mesh_indices(out)[3 * i + 2];
        idx[3 * i + 2] = lr_mesh_indices(out)[3 * i + 1];
    }
    lr_mesh_desc md = {.name = "integrating sphere", .vertex_count = nv, .positions = pos,
                       .triangle_count = nt, .indices = idx,
                       .checks = {.flags = LR_MESH_KEEP_WINDING}};
    lr_mesh *m;
    if (lr_mesh_create(&md, &m, &e))
        fail_msg("%s", e.msg);
    free(pos);
    free(idx);
    lr_bvh *b = lrt_bvh(m);
    lr_tr_surface_desc d = {.kind = LR_TR_DIFFUSE, .mesh = m, .bvh = b, .albedo = {rho, rho, rho},
                            .patch_mm = 40};
    lr_tr_settings set = {.rays_per_patch = 256, .max_iterations = 300, .tolerance = 1e-7};
    lr_tr *t;
    if (lr_tr_create(&d, 1, &set, &t, &e))
        fail_msg("%s", e.msg);
    lr_light L = {.type = LR_LIGHT_POINT, .position = lr_v3(0, 0, 0), .intensity = 1};
    lr_tr_stats st;
    if (lr_tr_solve_light(t, &L, 0, &st, &e))
        fail_msg("%s", e.msg);
    size_t n = lr_tr_patch_count(t);
    double power = 0, worst = 0;
    for (size_t p = 0; p < n; p++) {
        double W[3], A;
        lr_tr_radiosity(t, 0, p, W);
        lr_tr_patch_geometry(t, p, NULL, NULL, &A);
        power += A * W[1];
        worst = fmax(worst, fabs(W[1] / (rho / (R * R) / (1 - rho)) - 1));
        assert_near(lr_tr_escape(t, p), 0.0, 1e-12);
    }
    print_message("integrating sphere: %zu patches, %d sweeps, power %.5f expected %.5f, worst "
                  "patch %.2f %%\n", n, st.iterations, power, rho * 4 * M_PI / (1 - rho),
                  100 * worst);
    assert_near_rel(power, rho * 4 * M_PI / (1 - rho), 0.01);
    assert_true(worst < 0.03);
    lr_tr_destroy(t);
    lr_bvh_destroy(b);
    lr_mesh_destroy(m);
    lr_mesh_destroy(out);
}

static void test_sphere_shell_power(void **state)
{
    (void)state;
    lr_scene *s = load("sphere_shell");
    lr_tr *t;
    lr_err e = {0};
    lr_tr_settings set = {.rays_per_patch = 256};
    if (lr_tr_create_scene(s, &set, &t, &e))
        fail_msg("%s", e.msg);
    lr_tr_stats st;
    if (lr_tr_solve_light(t, lr_scene_light_at(s, 0), 0, &st, &e))
        fail_msg("%s", e.msg);
    double P[3];
    lr_tr_escaped_power(t, 0, P);
    print_message("sphere_shell: %zu patches, %d sweeps (residual after 10: %.2e), emitted "
                  "%.4f %.4f %.4f of 4 pi = %.4f\n", lr_tr_patch_count(t), st.iterations,
                  st.residual10, P[0], P[1], P[2], 4 * M_PI);
    for (int b = 0; b < 3; b++)
        assert_near_rel(P[b], 4 * M_PI, 0.02);
    assert_true(st.residual10 <= 0.005);
    lr_tr_destroy(t);
    lr_scene_destroy(s);
}

/* S: column totals, and nothing across air between two boxes of one mesh. */
static void test_subsurface_columns_and_gap(void **state)
{
    (void)state;
    lr_err e = {0};
    lr_mesh *b0, *b1;
    lr_box_desc d0 = {.center = lr_v3(-11, 0, 0), .size = lr_v3(20, 20, 20)};
    lr_box_desc d1 = {.center = lr_v3(11, 0, 0), .size = lr_v3(20, 20, 20)};
    if (lr_mesh_box(&d0, &b0, &e) || lr_mesh_box(&d1, &b1, &e))
        fail_msg("%s", e.msg);
    size_t n0 = lr_mesh_vertex_count(b0), t0 = lr_mesh_triangle_count(b0);
    size_t nv = n0 + lr_mesh_vertex_count(b1), nt = t0 + lr_mesh_triangle_count(b1);
    double *pos = malloc(nv * 3 * sizeof *pos);
    uint32_t *idx = malloc(nt * 3 * sizeof *idx);
    for (size_t i = 0; i < 3 * n0; i++)
        pos[i] = lr_mesh_positions(b0)[i];
    for (size_t i = 0; i < 3 * (nv - n0); i++)
        pos[3 * n0 + i] = lr_mesh_positions(b1)[i];
    for (size_t i = 0; i < 3 * t0; i++)
        idx[i] = lr_mesh_indices(b0)[i];
    for (size_t i = 0; i < 3 * (nt - t0); i++)
        idx[3 * t0 + i] = lr_mesh_indices(b1)[i] + (uint32_t)n0;
    lr_mesh_desc md = {.name = "two boxes", .vertex_count = nv, .positions = pos,
                       .triangle_count = nt, .indices = idx};
    lr_mesh *m;
    if (lr_mesh_create(&md, &m, &e))
        fail_msg("%s", e.msg);
    free(pos);
    free(idx);
    lr_bvh *bv = lrt_bvh(m);
    lr_medium med = {.sigma_a = {0.01, 0.02, 0.03}, .sigma_s_prime = {1, 1, 1}, .eta = 1.3};
    lr_coeffs co;
    if (lr_coeffs_derive(&med, &co, &e))
        fail_msg("%s", e.msg);
    lr_tr_surface_desc d = {.kind = LR_TR_TRANSLUCENT, .mesh = m, .bvh = bv, .coeffs = &co,
                            .model = LR_SSS_STANDARD_DIPOLE, .patch_mm = 10};
    lr_tr_settings set = {.rays_per_patch = 64};
    lr_tr *t;
    if (lr_tr_create(&d, 1, &set, &t, &e))
        fail_msg("%s", e.msg);
    size_t n = lr_tr_patch_count(t);
    double total[3];
    lr_dipole_rd_total(&co, total);
    size_t across = 0, within = 0;
    for (size_t i = 0; i < n; i++) {
        lr_vec3 ci;
        double Ai, sum[3] = {0, 0, 0};
        lr_tr_patch_geometry(t, i, &ci, NULL, &Ai);
        for (size_t j = 0; j < n; j++) {
            lr_vec3 cj;
            double Aj, S[3];
            lr_tr_patch_geometry(t, j, &cj, NULL, &Aj);
            lr_tr_subsurface(t, j, i, S);
            for (int b = 0; b < 3; b++)
                sum[b] += Aj * S[b] / Ai;
            if ((ci.x < 0) != (cj.x < 0)) {
                across++;
                assert_true(S[0] == 0 && S[1] == 0 && S[2] == 0);
            } else if (S[2] > 0) {
                within++;
            }
        }
        /* Entries below 1e-7 of the input are dropped: the kept sum is within 1e-4. */
        for (int b = 0; b < 3; b++)
            assert_near_rel(sum[b], total[b], 1e-4);
    }
    assert_true(across > 0 && within > 0);
    lr_tr_destroy(t);
    lr_bvh_destroy(bv);
    lr_mesh_destroy(m);
    lr_mesh_destroy(b0);
    lr_mesh_destroy(b1);
}

static void converges_in_10(const char *name)
{
    lr_scene *s = load(name);
    lr_tr *t;
    lr_err e = {0};
    lr_tr_settings set = {.rays_per_patch = 128, .max_iterations = 10, .tolerance = 1e-9};
    if (lr_tr_create_scene(s, &set, &t, &e))
        fail_msg("%s: %s", name, e.msg);
    lr_tr_stats st;
    if (lr_tr_solve_light(t, lr_scene_light_at(s, 0), 0, &st, &e))
        fail_msg("%s", e.msg);
    print_message("%s: %zu patches, residual after %d sweeps %.2e\n", name,
                  lr_tr_patch_count(t), st.iterations, st.residual);
    assert_true(st.residual <= 0.005);
    /* Warm start: the same light again is already converged. */
    lr_tr_stats st2;
    if (lr_tr_solve_light(t, lr_scene_light_at(s, 0), 0, &st2, &e))
        fail_msg("%s", e.msg);
    assert_true(st2.residual <= st.residual * 1.01 + 1e-12);
    lr_tr_destroy(t);
    lr_scene_destroy(s);
}

static void test_converges_lampshade(void **state)
{
    (void)state;
    converges_in_10("lampshade");
}

static void test_converges_votive(void **state)
{
    (void)state;
    converges_in_10("votive");
}

static void test_bad_input(void **state)
{
    (void)state;
    lr_err e = {0};
    lr_tr *t = NULL;
    lr_tr_surface_desc d = {.kind = LR_TR_DIFFUSE};
    assert_int_equal(lr_tr_create(&d, 1, NULL, &t, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "mesh"));
    lr_mesh *a = disk(10, 0, true, 16);
    lr_bvh *b = lrt_bvh(a);
    d = (lr_tr_surface_desc){.kind = LR_TR_DIFFUSE, .mesh = a, .bvh = b, .albedo = {1.5, 0, 0}};
    assert_int_equal(lr_tr_create(&d, 1, NULL, &t, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "albedo"));
    lr_coeffs co = {0};
    d = (lr_tr_surface_desc){.kind = LR_TR_TRANSLUCENT, .mesh = a, .bvh = b, .coeffs = &co,
                             .model = LR_SSS_MULTIPOLE};
    assert_int_equal(lr_tr_create(&d, 1, NULL, &t, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "thickness_mm"));
    assert_int_equal(lr_tr_create(&d, 0, NULL, &t, &e), LR_EINVAL);
    assert_null(t);
    d = (lr_tr_surface_desc){.kind = LR_TR_DIFFUSE, .mesh = a, .bvh = b, .albedo = {0.5, 0.5, 0.5},
                             .patch_mm = 1e3};
    lr_tr_settings set = {.rays_per_patch = 16};
    if (lr_tr_create(&d, 1, &set, &t, &e))
        fail_msg("%s", e.msg);
    double E[3] = {1, NAN, 1};
    size_t n = lr_tr_patch_count(t);
    assert_int_equal(n, 1);
    assert_int_equal(lr_tr_solve_irradiance(t, E, 0, NULL, &e), LR_EINVAL);
    assert_int_equal(lr_tr_solve_irradiance(t, E, 9, NULL, &e), LR_EINVAL);
    lr_tr_destroy(t);
    lr_bvh_destroy(b);
    lr_mesh_destroy(a);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ff_coaxial_disks),
        cmocka_unit_test(test_ff_rectangles),
        cmocka_unit_test(test_integrating_sphere),
        cmocka_unit_test(test_subsurface_columns_and_gap),
        cmocka_unit_test(test_sphere_shell_power),
        cmocka_unit_test(test_converges_lampshade),
        cmocka_unit_test(test_converges_votive),
        cmocka_unit_test(test_bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
