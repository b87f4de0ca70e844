/* A scene's light-propagation volume on the plane receivers (render/lpv/scene_lpv.h) on
 * led_shade (4 LED quads in a paper shade, table and wall): the receivers never gather more
 * than was injected, the table under the shade and the wall receive indirect light, nothing
 * lands outside the volume, further bounces add light within R / (1 - R); a point light over
 * a table beside a wall injects the closed-form integral of albedo E over both planes; the
 * spot with a cone wider than the planes injects the same, a narrow one less; the
 * lampshade's point light lights its receivers; a bad light index and n = 1 are refused. */
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
#include "render/lpv/scene_lpv.h"
#include "tests/support/near.h"
#include "tests/support/render.h"

#define TEXELS ((size_t)LR_RECV_GRID * LR_RECV_GRID)

static lr_scene *load(const char *path)
{
    lr_scene *s = NULL;
    lr_err e = {0};
    if (lr_scene_load(path, NULL, &s, &e))
        fail_msg("%s", e.msg);
    return s;
}

/* E at world point x from receiver i's grid (bilinear). */
static double at(const lr_scene *s, const double *g, int i, lr_vec3 x)
{
    lr_recv_grid_frame f;
    assert_true(lr_recv_grid_frame_of(lr_scene_receiver_at(s, i), &f));
    int idx[4];
    double w[4], E = 0.0;
    lr_recv_grid_taps(&f, x, idx, w);
    for (int k = 0; k < 4; k++)
        E += w[k] * g[(size_t)idx[k] * 3];
    return E;
}

static void test_led_shade(void **st)
{
    (void)st;
    lr_scene *s = load("configs/scenes/led_shade.json");
    assert_int_equal(lr_scene_receiver_count(s), 2);
    double *g[2] = {calloc(TEXELS * 3, sizeof(double)), calloc(TEXELS * 3, sizeof(double))};
    assert_non_null(g[0]);
    assert_non_null(g[1]);
    lr_lpv_scene_desc d = {.n = 16};
    lr_lpv_scene_stats stats;
    lr_err e = {0};
    if (lr_lpv_scene_indirect(s, 0, &d, g, &stats, &e))
        fail_msg("%s", e.msg);
    printf("n 16: cell %.1f mm, %d receiver and %d object samples; injected %.4g, gathered %.4g "
           "(R), receivers' direct %.4g per unit radiance\n",
           stats.cell_mm, stats.samples_receivers, stats.samples_objects, stats.injected[0],
           stats.gathered[0], stats.direct_receivers);
    for (int c = 0; c < 3; c++) {
        assert_true(stats.injected[c] > 0.0);
        assert_true(stats.gathered[c] > 0.0);
        assert_true(stats.gathered[c] <= stats.injected[c]);
    }
    /* Under the shade (its axis at x = y = 0) and on the wall behind it. */
    assert_true(at(s, g[0], 0, lr_v3(0, 0, 0)) > 0.0);
    assert_true(at(s, g[1], 1, lr_v3(0, 250, 250)) > 0.0);
    /* The table's far corner lies outside the volume: exactly nothing. */
    assert_near(at(s, g[0], 0, lr_v3(-690, -440, 0)), 0.0, 0.0);
    /* Two more bounces off the shade's inner wall (R 0.79): more light, still bounded. */
    d.bounces = 2;
    lr_lpv_scene_stats more;
    if (lr_lpv_scene_indirect(s, 0, &d, g, &more, &e))
        fail_msg("%s", e.msg);
    printf("2 more bounces: injected %.4g, gathered %.4g (R)\n", more.injected[0],
           more.gathered[0]);
    for (int c = 0; c < 3; c++) {
        assert_true(more.injected[c] > stats.injected[c]);
        assert_true(more.gathered[c] > stats.gathered[c]);
        assert_true(more.gathered[c] <= more.injected[c]);
    }
    /* The bounces add light that a first bounce injected and the shade absorbed: at most
     * R / (1 - R) with R <= 0.8 times the first injection. */
    assert_true(more.injected[0] <= stats.injected[0] * (1.0 + 0.8 / 0.2));
    lr_scene_destroy(s);
    free(g[0]);
    free(g[1]);
}

/* A point light 30 mm over a 100 x 100 mm table, beside a 100 x 30 mm wall 50 mm away, a
 * sphere above the light (it sets the volume: 140 mm side, z from -30 to 110) that shadows
 * neither plane. */
static const char *const POINT_SCENE =
    "{\"name\": \"lpv_point\", \"objects\": [{\"name\": \"ball\", \"material\": "
    "{\"name\": \"m\", \"source\": \"marble preset\", \"base\": \"marble\"}, "
    "\"mesh\": {\"type\": \"sphere\", \"radius\": 20, "
    "\"subdivisions\": 3}, \"transform\": {\"translate\": [0, 0, 40]}}],"
    " \"lights\": [{\"type\": \"point\", \"name\": \"bulb\", \"position\": [0, 0, 10], "
    "\"intensity\": 0.5}],"
    " \"camera\": {\"position\": [0, -300, 120], \"target\": [0, 0, 0], \"fov_deg\": 30},"
    " \"receivers\": [{\"name\": \"table\", \"type\": \"plane\", \"center\": [0, 0, -20], "
    "\"normal\": [0, 0, 1], \"size\": [100, 100], \"albedo\": [0.75, 0.5, 0.25]},"
    " {\"name\": \"wall\", \"type\": \"plane\", \"center\": [0, 50, -5], \"normal\": [0, -1, 0], "
    "\"size\": [100, 30], \"albedo\": [0.85, 0.8, 0.6]}]}";

/* The solid angle of the rectangle [u0, u1] x [v0, v1] of a plane seen from height H over
 * its origin: the integral of H / (u^2 + v^2 + H^2)^(3/2) dA, whose antiderivative is
 * atan(u v / (H sqrt(u^2 + v^2 + H^2))). */
static double rect_solid_angle(double u0, double u1, double v0, double v1, double H)
{
    double F[2][2];
    double u[2] = {u0, u1}, v[2] = {v0, v1};
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++)
            F[i][j] = atan(u[i] * v[j] / (H * sqrt(u[i] * u[i] + v[j] * v[j] + H * H)));
    return F[1][1] - F[0][1] - F[1][0] + F[0][0];
}

/* A unit-intensity point light's E = cos / d^2 = H / d^3 on an unshadowed plane: the
 * receivers' injection sum rho E A over their samples (a midpoint rule on squares of side
 * at most h / 2) equals rho times the solid angle each plane subtends. The midpoint rule's
 * error is at most (dx^2 / 24) times the integral of |laplacian E|, and |laplacian E| <= 6 E
 * / H^2 for this E (its maximum ratio, at the foot of the light), so the relative tolerance
 * is dx^2 / (4 H^2) per plane. Twice the light's intensity changes nothing (per unit
 * intensity), and the volume delivers light to both planes but never more than it got. */
static void test_point_light_closed_form(void **st)
{
    (void)st;
    lr_scene *s = lr_test_scene_text(POINT_SCENE, NULL);
    assert_int_equal(lr_scene_receiver_count(s), 2);
    double *g[2] = {calloc(TEXELS * 3, sizeof(double)), calloc(TEXELS * 3, sizeof(double))};
    assert_non_null(g[0]);
    assert_non_null(g[1]);
    lr_lpv_scene_desc d = {.n = 16};
    lr_lpv_scene_stats stats;
    lr_err e = {0};
    if (lr_lpv_scene_indirect(s, 0, &d, g, &stats, &e))
        fail_msg("%s", e.msg);
    lr_vec3 p = lr_scene_light_at(s, 0)->position;
    double dx = stats.cell_mm / 2.0, want[3] = {0, 0, 0}, tol[3] = {0, 0, 0};
    for (int i = 0; i < 2; i++) {
        const lr_receiver *rc = lr_scene_receiver_at(s, i);
        lr_recv_grid_frame f;
        assert_true(lr_recv_grid_frame_of(rc, &f));
        lr_vec3 q = lr_v3_sub(p, f.c);
        double H = lr_v3_dot(q, rc->normal), u = lr_v3_dot(q, f.a), v = lr_v3_dot(q, f.b);
        double omega = rect_solid_angle(-f.w / 2 - u, f.w / 2 - u, -f.h / 2 - v, f.h / 2 - v, H);
        for (int c = 0; c < 3; c++) {
            want[c] += rc->albedo[c] * omega;
            tol[c] += rc->albedo[c] * omega * dx * dx / (4.0 * H * H);
        }
    }
    printf("point light: cell %.2f mm, %d receiver samples; receivers inject %.6g %.6g %.6g, "
           "closed form %.6g %.6g %.6g (tolerance %.2g); injected %.4g, gathered %.4g (R)\n",
           stats.cell_mm, stats.samples_receivers, stats.injected_receivers[0],
           stats.injected_receivers[1], stats.injected_receivers[2], want[0], want[1], want[2],
           tol[0], stats.injected[0], stats.gathered[0]);
    for (int c = 0; c < 3; c++) {
        assert_true(tol[c] < 0.01 * want[c]);
        assert_near(stats.injected_receivers[c], want[c], tol[c]);
        assert_true(stats.gathered[c] > 0.0);
        assert_true(stats.gathered[c] <= stats.injected[c]);
    }
    /* The wall takes the table's light and the table the wall's. */
    assert_true(at(s, g[0], 0, lr_v3(0, 30, -20)) > 0.0);
    assert_true(at(s, g[1], 1, lr_v3(0, 50, -10)) > 0.0);
    /* Per unit intensity: the file's intensity does not enter. */
    double *h[2] = {malloc(TEXELS * 3 * sizeof(double)), malloc(TEXELS * 3 * sizeof(double))};
    assert_non_null(h[0]);
    assert_non_null(h[1]);
    unsigned dirty = 0;
    if (lr_scene_set(s, "light.intensity", "1.0", &dirty, &e))
        fail_msg("%s", e.msg);
    if (lr_lpv_scene_indirect(s, 0, &d, h, NULL, &e))
        fail_msg("%s", e.msg);
    for (int i = 0; i < 2; i++) {
        assert_memory_equal(g[i], h[i], TEXELS * 3 * sizeof(double));
        free(g[i]);
        free(h[i]);
    }
    lr_scene_destroy(s);
}

/* The same scene with the light a spot pointing down: with a cone wider than every sample's
 * direction (inner 88.5 degrees; the wall's top samples are 88.2 degrees off the axis) the
 * receivers inject exactly what the point light gives (the same code, shape 1); a 20-degree
 * cone gives less, but some. */
static void test_spot_light(void **st)
{
    (void)st;
    lr_scene *s = lr_test_scene_text(POINT_SCENE, NULL);
    lr_lpv_scene_desc d = {.n = 16};
    lr_lpv_scene_stats point, wide, narrow;
    lr_err e = {0};
    double *g[2] = {malloc(TEXELS * 3 * sizeof(double)), malloc(TEXELS * 3 * sizeof(double))};
    assert_non_null(g[0]);
    assert_non_null(g[1]);
    if (lr_lpv_scene_indirect(s, 0, &d, g, &point, &e))
        fail_msg("%s", e.msg);
    lr_scene_destroy(s);
    const char *at_type = strstr(POINT_SCENE, "\"point\"");
    assert_non_null(at_type);
    char text[2048];
    for (int k = 0; k < 2; k++) {
        snprintf(text, sizeof text,
                 "%.*s\"spot\", \"direction\": [0, 0, -1], \"inner_deg\": %s, "
                 "\"outer_deg\": %s%s",
                 (int)(at_type - POINT_SCENE), POINT_SCENE, k ? "10" : "88.5", k ? "20" : "89.5",
                 at_type + strlen("\"point\""));
        s = lr_test_scene_text(text, NULL);
        assert_int_equal(lr_scene_light_at(s, 0)->type, LR_LIGHT_SPOT);
        if (lr_lpv_scene_indirect(s, 0, &d, g, k ? &narrow : &wide, &e))
            fail_msg("%s", e.msg);
        lr_scene_destroy(s);
    }
    printf("receivers inject (R): point %.6g, spot 88.5-89.5 deg %.6g, spot 10-20 deg %.6g\n",
           point.injected_receivers[0], wide.injected_receivers[0],
           narrow.injected_receivers[0]);
    for (int c = 0; c < 3; c++) {
        assert_near(wide.injected_receivers[c], point.injected_receivers[c],
                    1e-12 * point.injected_receivers[c]);
        assert_true(narrow.injected_receivers[c] > 0.0);
        assert_true(narrow.injected_receivers[c] < 0.5 * point.injected_receivers[c]);
    }
    free(g[0]);
    free(g[1]);
}

static void test_point_light_and_bad_index(void **st)
{
    (void)st;
    lr_scene *s = load("configs/scenes/lampshade.json");
    int nr = lr_scene_receiver_count(s);
    assert_true(nr >= 1 && nr <= 4);
    double *g[4] = {NULL, NULL, NULL, NULL};
    for (int i = 0; i < nr; i++) {
        g[i] = malloc(TEXELS * 3 * sizeof(double));
        assert_non_null(g[i]);
        for (size_t k = 0; k < TEXELS * 3; k++)
            g[i][k] = 1.0;
    }
    lr_err e = {0};
    lr_lpv_scene_desc d = {.n = 8};
    lr_lpv_scene_stats stats;
    /* The lampshade's bulb lights its receivers through the volume (the grids start at 1:
     * they are overwritten, not added to). */
    assert_int_equal(lr_lpv_scene_indirect(s, 0, &d, g, &stats, &e), LR_OK);
    printf("lampshade bulb, n 8: injected %.4g (receivers %.4g), gathered %.4g (R) per unit "
           "intensity\n", stats.injected[0], stats.injected_receivers[0], stats.gathered[0]);
    for (int c = 0; c < 3; c++) {
        assert_true(stats.injected[c] > 0.0);
        assert_true(stats.gathered[c] > 0.0);
        assert_true(stats.gathered[c] <= stats.injected[c]);
    }
    double total = 0.0;
    for (int i = 0; i < nr; i++)
        for (size_t k = 0; k < TEXELS * 3; k++) {
            assert_true(g[i][k] >= 0.0 && g[i][k] < 1.0);
            total += g[i][k];
        }
    assert_true(total > 0.0);
    assert_int_equal(lr_lpv_scene_indirect(s, 7, &d, g, NULL, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "light 7"));
    d.n = 1;
    lr_scene *a = load("configs/scenes/led_shade.json");
    assert_int_equal(lr_lpv_scene_indirect(a, 0, &d, g, NULL, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "n = 1"));
    lr_scene_destroy(a);
    lr_scene_destroy(s);
    for (int i = 0; i < nr; i++)
        free(g[i]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_led_shade),
        cmocka_unit_test(test_point_light_closed_form),
        cmocka_unit_test(test_spot_light),
        cmocka_unit_test(test_point_light_and_bad_index),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
