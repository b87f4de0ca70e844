/* The light the objects' inner faces send through their openings (render/openings/openings.h,
 * issue 12 part 3) against closed forms:
 *  - an open tube (the shade mesh with equal radii, eta 1 so F_t = 1) with unit exitance on
 *    every emitter: the power that lands on a table under it is the emitters' form factors to
 *    the bottom opening, sum_j a_j F(x_j) with Howell's differential ring on the inside of a
 *    cylinder to its end disk, F = (X^2 + 1/2) / sqrt(X^2 + 1) - X, X = x / (2 R), x the height
 *    above the disk; and that sum is the reciprocity form pi R^2 (1 - F_12), F_12 the coaxial
 *    equal disks' C-41 form factor across the tube;
 *  - the emitters are the inner wall only (the VPLs' outermost surface is left out), normals
 *    toward the axis, total area the inner wall's;
 *  - a closed hollow sphere: emitters inside, nothing reaches a receiver (exactly 0);
 *  - the shipped lamp shade: B > 0, per unit intensity (an intensity change reuses it, a light
 *    move does not), the table under the shade lit;
 *  - the field (default off, a SETTINGS change) and not needed with translucent_radiosity or
 *    render.lpv (both carry this light already);
 *  - a diffusion_grid object (the jar candle's deep pool): its emitters carry its solved field
 *    (render/diffusion/dscene.h), to float rounding; without the field they carried 0. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/core/recv_grid.h"
#include "render/diffusion/dscene.h"
#include "render/openings/openings.h"
#include "render/scene/dirty.h"
#include "tests/support/near.h"
#include "tests/support/render.h"

static const char *const on[] = {"render.opening_light=true", NULL};

/* Tube: outer radius 50, wall 1.5, height 200 from z = 100 to 300; eta 1; light at z = 200;
 * a 2000 mm table 60 mm under the bottom opening. */
#define TUBE_R 50.0
#define TUBE_H 200.0
#define TUBE_Z0 100.0
#define TUBE_SEG 96

static lr_scene *tube(void)
{
    char doc[2048];
    snprintf(doc, sizeof doc,
             "{\"name\":\"tube\",\"objects\":[{\"name\":\"t\",\"material\":{\"name\":\"m\","
             "\"source\":\"test medium, index matched\",\"sigma_a\":[0.1,0.1,0.1],\"sigma_s_prime\":[5,5,5],\"eta\":1.0},"
             "\"model\":\"multipole\",\"thickness_mm\":1.5,"
             "\"mesh\":{\"type\":\"shade\",\"radius_bottom\":%g,\"radius_top\":%g,\"height\":%g,"
             "\"thickness\":1.5,\"rims\":true,\"segments\":%d},"
             "\"transform\":{\"translate\":[0,0,%g]}}],"
             "\"lights\":[{\"type\":\"point\",\"position\":[0,0,%g],\"intensity\":1}],"
             "\"camera\":{\"position\":[0,-3000,100],\"target\":[0,0,0]},"
             "\"receivers\":[{\"name\":\"table\",\"type\":\"plane\",\"center\":[0,0,%g],"
             "\"normal\":[0,0,1],\"size\":[2000,2000],\"albedo\":[0.5,0.5,0.5]}]}",
             TUBE_R, TUBE_R, TUBE_H, TUBE_SEG, TUBE_Z0, TUBE_Z0 + TUBE_H / 2, TUBE_Z0 - 60.0);
    return lr_test_scene_text(doc, on);
}

static lr_openings *openings_of(const lr_scene *s)
{
    lr_openings *op = NULL;
    lr_err e = {0};
    if (lr_openings_update(&op, s, NULL, 0, &e))
        fail_msg("%s", e.msg);
    assert_non_null(op);
    return op;
}

/* Howell: differential ring element on the inside of a cylinder of radius R, at height x
 * above its end disk, to that disk. */
static double ring_to_disk(double x, double R)
{
    double X = x / (2.0 * R);
    return (X * X + 0.5) / sqrt(X * X + 1.0) - X;
}

static void test_tube_closed_form(void **state)
{
    (void)state;
    lr_scene *s = tube();
    lr_openings *op = openings_of(s);
    double area = 0.0;
    size_t ne = lr_openings_emitter_count(op, &area);
    assert_true(ne > 200);
    /* The inner wall's vertices sit the shade's radial offset in (render/mesh/shade.c); the
     * opening is that 96-gon, of area n/2 r^2 sin(2 pi / n). */
    double c = cos(M_PI / TUBE_SEG), r_in = TUBE_R - 1.5 / c;
    double A_disk = 0.5 * TUBE_SEG * r_in * r_in * sin(2.0 * M_PI / TUBE_SEG);
    double R_eff = sqrt(A_disk / M_PI);
    double expect = 0.0, wall = 2.0 * TUBE_SEG * r_in * sin(M_PI / TUBE_SEG) * TUBE_H;
    double *B = malloc(3 * ne * sizeof *B);
    assert_non_null(B);
    for (size_t j = 0; j < ne; j++) {
        lr_vec3 x, n;
        double a;
        assert_true(lr_openings_emitter(op, j, &x, &n, &a));
        double rho = hypot(x.x, x.y);
        /* the inner wall: between the apothem and the vertex radius, normal toward the axis */
        assert_true(rho > r_in * c - 1e-6 && rho < r_in + 1e-6);
        assert_true(n.x * x.x + n.y * x.y < -0.99 * rho);
        assert_true(x.z > TUBE_Z0 - 1e-6 && x.z < TUBE_Z0 + TUBE_H + 1e-6);
        expect += a * ring_to_disk(x.z - TUBE_Z0, R_eff);
        B[3 * j] = B[3 * j + 1] = B[3 * j + 2] = 1.0;
    }
    /* stratified by area: the kept points' area is the inner wall's within a few points' */
    printf("tube: %zu emitters, area %.1f (inner wall %.1f)\n", ne, area, wall);
    assert_true(fabs(area / wall - 1.0) < 0.02);
    int nu, nv;
    assert_true(lr_openings_cells(op, 0, &nu, &nv));
    double *X = malloc(3 * (size_t)nu * (size_t)nv * sizeof *X);
    assert_non_null(X);
    lr_err e = {0};
    assert_int_equal(lr_openings_apply(op, 0, B, X, &e), LR_OK);
    double P = 0.0, cell = (2000.0 / nu) * (2000.0 / nv);
    for (int q = 0; q < nu * nv; q++) {
        assert_true(X[3 * q] == X[3 * q + 1] && X[3 * q] == X[3 * q + 2]);
        P += X[3 * q] * cell;
    }
    /* Reciprocity: A_wall F_wall->disk = A_disk F_disk->wall = A_disk (1 - F_12), C-41 with
     * equal radii: F_12 = (S - sqrt(S^2 - 4)) / 2, S = 2 + H^2 / R^2. */
    double S = 2.0 + TUBE_H * TUBE_H / (R_eff * R_eff);
    double recip = A_disk * (1.0 - 0.5 * (S - sqrt(S * S - 4.0)));
    printf("tube: power on the table %.2f, sum a_j F_j %.2f, pi R^2 (1 - F12) %.2f\n", P, expect,
           recip);
    /* Midpoint rule over 31 mm cells of the opening's soft-edged pool (60 mm below it) and the
     * light past the table's edge (rays within atan(60 / 1000) = 3.4 deg of the horizontal,
     * under 0.4 % for a Lambertian aperture): 3 %. */
    assert_true(fabs(P / expect - 1.0) < 0.03);
    /* Stratified emitters (LR_OPENINGS_POINTS over the whole mesh) against the exact integral: 2 %. */
    assert_true(fabs(expect / recip - 1.0) < 0.02);
    /* and the light the model gives: positive, per unit intensity */
    const double *Bm = lr_openings_B(op, 0);
    assert_non_null(Bm);
    double sum = 0.0;
    for (size_t j = 0; j < 3 * ne; j++) {
        assert_true(Bm[j] >= 0.0 && isfinite(Bm[j]));
        sum += Bm[j];
    }
    assert_true(sum > 0.0);
    free(X);
    free(B);
    lr_openings_destroy(op);
    lr_scene_destroy(s);
}

/* A closed hollow sphere around the light (the shell mesh, with a table): its inner face
 * emits into the cavity only, so no receiver gets any of it. */
static void test_closed_shell_sends_nothing(void **state)
{
    (void)state;
    char doc[2048];
    snprintf(doc, sizeof doc, "%s",
             "{\"name\":\"shell\",\"objects\":[{\"name\":\"s\",\"material\":\"porcelain\","
             "\"model\":\"multipole\",\"thickness_mm\":2,"
             "\"mesh\":{\"type\":\"file\",\"path\":\"../meshes/sphere_shell.obj\"}}],"
             "\"lights\":[{\"type\":\"point\",\"position\":[0,0,0],\"intensity\":1}],"
             "\"camera\":{\"position\":[0,-3000,100],\"target\":[0,0,0]},"
             "\"receivers\":[{\"name\":\"table\",\"type\":\"plane\",\"center\":[0,0,-60],"
             "\"normal\":[0,0,1],\"size\":[600,600],\"albedo\":[0.5,0.5,0.5]}]}");
    lr_scene *s = NULL;
    s = lr_test_scene_text(doc, on);
    lr_openings *op = openings_of(s);
    double area = 0.0;
    size_t ne = lr_openings_emitter_count(op, &area);
    assert_true(ne > 100);
    const double *B = lr_openings_B(op, 0);
    double sum = 0.0;
    for (size_t j = 0; j < 3 * ne; j++)
        sum += B[j];
    assert_true(sum > 0.0); /* the inner face is lit */
    const float *g = lr_openings_grid(op, 0, 0);
    assert_non_null(g);
    for (size_t k = 0; k < 3 * (size_t)LR_RECV_GRID * LR_RECV_GRID; k++)
        assert_true(g[k] == 0.0f);
    lr_openings_destroy(op);
    lr_scene_destroy(s);
}

static double grid_sum(const float *g)
{
    double s = 0.0;
    for (size_t k = 0; k < 3 * (size_t)LR_RECV_GRID * LR_RECV_GRID; k++)
        s += g[k];
    return s;
}

static void test_lampshade(void **state)
{
    (void)state;
    lr_scene *s = lr_test_scene("lampshade", on, NULL);
    lr_openings *op = openings_of(s);
    const float *t0 = lr_openings_grid(op, 0, 0), *w0 = lr_openings_grid(op, 1, 0);
    assert_non_null(t0);
    assert_non_null(w0);
    double st = grid_sum(t0), sw = grid_sum(w0);
    assert_true(st > 0.0 && sw > 0.0);
    /* The table under the bulb (the bottom opening) gets light; printed for the README. */
    lr_recv_grid_frame f;
    assert_true(lr_recv_grid_frame_of(lr_scene_receiver_at(s, 0), &f));
    int idx[4];
    double w[4];
    lr_recv_grid_taps(&f, lr_v3(0, 0, 0), idx, w);
    double E0 = 0.0;
    for (int i = 0; i < 4; i++)
        E0 += w[i] * t0[3 * (size_t)idx[i] + 1];
    printf("lampshade: E under the shade (G, unit intensity) %.4g W/mm^2\n", E0);
    assert_true(E0 > 0.0);
    /* At the cells' centres the per-point sum (the twin's REFERENCE mode) is the kernel's
     * (float entries: 1e-5). */
    int nu, nv;
    assert_true(lr_openings_cells(op, 0, &nu, &nv));
    double *X = malloc(3 * (size_t)nu * (size_t)nv * sizeof *X);
    assert_non_null(X);
    lr_err e0 = {0};
    assert_int_equal(lr_openings_apply(op, 0, lr_openings_B(op, 0), X, &e0), LR_OK);
    int checked = 0;
    for (int v = 0; v < nv; v += 3)
        for (int u = 0; u < nu; u += 3) {
            lr_vec3 x = lr_v3_add(f.c, lr_v3_add(lr_v3_scale(f.a, ((u + 0.5) / nu - 0.5) * f.w),
                                                 lr_v3_scale(f.b, ((v + 0.5) / nv - 0.5) * f.h)));
            double Ex[3] = {0, 0, 0};
            lr_openings_irradiance_at(op, s, 0, x, lr_scene_receiver_at(s, 0)->normal, Ex);
            for (int c = 0; c < 3; c++) {
                double k = X[3 * ((size_t)v * nu + u) + c];
                assert_true(fabs(Ex[c] - k) <= 1e-5 * k + 1e-30);
            }
            checked += X[3 * ((size_t)v * nu + u) + 1] > 0.0;
        }
    assert_true(checked > 10);
    free(X);
    double build_s, light_s;
    lr_openings_times(op, &build_s, &light_s);
    printf("lampshade: kernel %.2f s, B and grids %.2f s\n", build_s, light_s);
    /* An intensity change: per unit intensity, nothing recomputed, same grid. */
    lr_err e = {0};
    assert_int_equal(lr_scene_set(s, "lights[0].intensity", "0.5", NULL, &e), LR_OK);
    assert_int_equal(lr_openings_update(&op, s, NULL, 0, &e), LR_OK);
    lr_openings_times(op, &build_s, &light_s);
    printf("lampshade: after an intensity change: kernel %.3f s, B and grids %.3f s\n", build_s,
           light_s);
    assert_true(build_s == 0.0);
    assert_true(grid_sum(lr_openings_grid(op, 0, 0)) == st);
    /* A light move recomputes B (not the kernel) and changes the light. */
    assert_int_equal(lr_scene_set(s, "lights[0].position", "0,0,280", NULL, &e), LR_OK);
    assert_int_equal(lr_openings_update(&op, s, NULL, 0, &e), LR_OK);
    lr_openings_times(op, &build_s, &light_s);
    assert_true(build_s == 0.0);
    assert_true(grid_sum(lr_openings_grid(op, 0, 0)) != st);
    lr_openings_destroy(op);
    lr_scene_destroy(s);
}

static void test_field(void **state)
{
    (void)state;
    lr_scene *s = lr_test_scene("lampshade", NULL, NULL);
    lr_err e = {0};
    unsigned dirty = 0;
    assert_int_equal(lr_scene_set(s, "render.opening_light", "false", &dirty, &e), LR_OK);
    assert_false(lr_openings_needed(s));
    assert_int_equal(lr_scene_set(s, "render.opening_light", "true", &dirty, &e), LR_OK);
    assert_true(dirty & LR_DIRTY_SETTINGS);
    assert_true(lr_openings_needed(s));
    assert_int_not_equal(lr_scene_set(s, "render.opening_light", "1", NULL, &e), LR_OK);
    assert_non_null(strstr(e.msg, "opening_light"));
    assert_int_equal(lr_scene_set(s, "render.lpv", "16", NULL, &e), LR_OK);
    assert_false(lr_openings_needed(s));
    assert_int_equal(lr_scene_set(s, "render.lpv", "0", NULL, &e), LR_OK);
    assert_int_equal(lr_scene_set(s, "objects[0].model", "translucent_radiosity", NULL, &e),
                     LR_OK);
    assert_false(lr_openings_needed(s));
    lr_scene_destroy(s);
    /* default off: a scene that does not name it */
    lr_scene *c = lr_test_scene("candle", NULL, NULL);
    assert_false(lr_scene_render(c)->opening_light);
    assert_false(lr_openings_needed(c));
    lr_openings *op = NULL;
    assert_int_equal(lr_openings_update(&op, c, NULL, 0, &e), LR_OK);
    assert_null(op);
    lr_scene_destroy(c);
}

static void test_grid_emitters_carry_the_field(void **state)
{
    (void)state;
    static const char *const sets[] = {"render.opening_light=true",
                                       "objects[0].model=diffusion_grid",
                                       "objects[0].dgrid_h_mm=6", NULL};
    lr_scene *s = lr_test_scene("jar_candle", sets, NULL);
    lr_dscene *d = NULL;
    lr_err e = {0};
    assert_int_equal(lr_dscene_create(&d, &e), LR_OK);
    if (lr_dscene_update(d, s, &e))
        fail_msg("%s", e.msg);
    lr_openings *op = NULL;
    if (lr_openings_update(&op, s, d, 0, &e))
        fail_msg("%s", e.msg);
    assert_non_null(op);
    lr_dfield_view f;
    assert_true(lr_dscene_field(d, 0, 0, &f));
    const double *B = lr_openings_B(op, 0);
    assert_non_null(B);
    size_t ne = lr_openings_emitter_count(op, NULL), lit = 0;
    assert_true(ne > 50); /* the pool's walls and floor */
    for (size_t j = 0; j < ne; j++) {
        lr_vec3 x, n;
        double a, want[3];
        assert_true(lr_openings_emitter(op, j, &x, &n, &a));
        lr_dfield_eval(f.data, f.n, f.origin, f.h, x, want);
        for (int c = 0; c < 3; c++)
            assert_near(B[3 * j + c], want[c], 1e-12 + 1e-9 * want[c]);
        lit += want[0] > 0.0;
    }
    assert_true(lit > ne / 2);
    /* Without the field the grid's emitters give nothing (the twin and the GPU always pass it). */
    lr_openings *none = NULL;
    if (lr_openings_update(&none, s, NULL, 0, &e))
        fail_msg("%s", e.msg);
    const double *B0 = lr_openings_B(none, 0);
    for (size_t j = 0; j < 3 * ne; j++)
        assert_true(B0[j] == 0.0);
    print_message("jar_candle, diffusion_grid: %zu emitters, %zu lit, carry the field\n", ne, lit);
    lr_openings_destroy(none);
    lr_openings_destroy(op);
    lr_dscene_destroy(d);
    lr_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_tube_closed_form),
        cmocka_unit_test(test_closed_shell_sends_nothing),
        cmocka_unit_test(test_lampshade),
        cmocka_unit_test(test_field),
        cmocka_unit_test(test_grid_emitters_carry_the_field),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
