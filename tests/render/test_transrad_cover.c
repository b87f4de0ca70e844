/* The part of a plane receiver under a closed body (render/transrad/cover.c): a coaster, a
 * closed 45 x 45 mm box, stands on a 120 x 120 mm floor of 30 mm cells across four of
 * them (a quarter, two halves and a whole cell under it), a 300 x 300 mm ceiling 100 mm above.
 * (0.1 mm high). Against closed forms integrated over each cell's open part (200 x 200 midpoints):
 *  - each cell's open fraction: 1 less the footprint's overlap, within 0.005 (the fraction is
 *    counted over F's 40000 stratified origin points);
 *  - F from each floor cell to the ceiling, the mean over the open part of the differential
 *    element to a parallel rectangle (Howell B-11, four corner rectangles by superposition),
 *    within 1 % (binomial SE of 20000 rays on F ~ 0.7: 0.3 %); a fully covered cell has an
 *    empty row;
 *  - a point light's direct irradiance cos / d^2 over the open part (1024 stratified points),
 *    within 0.5 % (the coaster's edge shadows a 0.02 mm band); 0 under the coaster;
 *  - without `covers` the same coaster leaves the cells' rows at open x F (the deficit the
 *    receivers' bounce had under a candle's foot), which the flag removes;
 *  - a ray onto the floor beside it (lr_tr_cast): the cells' bilinear weights scaled by their
 *    open fractions, the covered cell left out, the rest summing to 1;
 *  - lr_tr_set_albedo: a plane's albedo set after create; out of [0, 1], another surface,
 *    NULL refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/mesh/shapes.h"
#include "render/scene/scene.h"
#include "render/transrad/transrad.h"
#include "tests/support/near.h"
#include "tests/support/objects.h"

#define FLOOR 120.0
#define CELL 30.0
#define CEIL_Z 100.0
#define CEIL 300.0
/* The coaster's height: thin, so that its edges' shadow (a band of about COASTER_H x 0.2 mm
 * under the light at 80 mm) and the hemisphere its sides take from the cells beside it stay
 * under 0.2 % (1 mm took 1.3 % of the quarter-covered cell's light and F). */
#define COASTER_H 0.1
/* The coaster's footprint. */
static const double cx0 = -15, cx1 = 30, cy0 = -15, cy1 = 30;

typedef struct rig {
    lr_mesh *floor, *ceiling, *coaster;
    lr_bvh *bf, *bc, *bk;
    lr_tr *t;
} rig;

static lr_mesh *quad(lr_vec3 c, lr_vec3 n, double s)
{
    lr_quad_desc q = {.center = c, .normal = n, .u_dir = lr_v3(1, 0, 0), .size_u = s,
                      .size_v = s};
    lr_mesh *m;
    lr_err e = {0};
    if (lr_mesh_quad(&q, &m, &e))
        fail_msg("%s", e.msg);
    return m;
}

static void rig_build(rig *r, bool covers, int rays, int direct)
{
    lr_err e = {0};
    r->floor = quad(lr_v3(0, 0, 0), lr_v3(0, 0, 1), FLOOR);
    r->ceiling = quad(lr_v3(0, 0, CEIL_Z), lr_v3(0, 0, -1), CEIL);
    lr_box_desc bd = {.center = lr_v3((cx0 + cx1) / 2, (cy0 + cy1) / 2, COASTER_H / 2),
                      .size = lr_v3(cx1 - cx0, cy1 - cy0, COASTER_H)};
    if (lr_mesh_box(&bd, &r->coaster, &e))
        fail_msg("%s", e.msg);
    r->bf = lrt_bvh(r->floor);
    r->bc = lrt_bvh(r->ceiling);
    r->bk = lrt_bvh(r->coaster);
    lr_tr_surface_desc d[3] = {
        {.kind = LR_TR_DIFFUSE, .mesh = r->coaster, .bvh = r->bk, .patch_mm = 1e5,
         .covers = covers},
        {.kind = LR_TR_PLANE, .mesh = r->floor, .bvh = r->bf, .center = lr_v3(0, 0, 0),
         .normal = lr_v3(0, 0, 1), .u_dir = lr_v3(1, 0, 0), .size_u = FLOOR, .size_v = FLOOR,
         .patch_mm = CELL, .albedo = {0.5, 0.5, 0.5}},
        {.kind = LR_TR_PLANE, .mesh = r->ceiling, .bvh = r->bc, .center = lr_v3(0, 0, CEIL_Z),
         .normal = lr_v3(0, 0, -1), .u_dir = lr_v3(1, 0, 0), .size_u = CEIL, .size_v = CEIL,
         .cells_u = 1, .cells_v = 1, .albedo = {0.5, 0.5, 0.5}},
    };
    lr_tr_settings set = {.rays_per_patch = rays, .direct_samples = direct, .seed = 3};
    if (lr_tr_create(d, 3, &set, &r->t, &e))
        fail_msg("%s", e.msg);
}

static void rig_free(rig *r)
{
    lr_tr_destroy(r->t);
    lr_bvh_destroy(r->bf);
    lr_bvh_destroy(r->bc);
    lr_bvh_destroy(r->bk);
    lr_mesh_destroy(r->floor);
    lr_mesh_destroy(r->ceiling);
    lr_mesh_destroy(r->coaster);
}

static bool under_coaster(double x, double y)
{
    return x > cx0 && x < cx1 && y > cy0 && y < cy1;
}

/* Howell B-11: from a differential element to a parallel rectangle of sides a, b at height c
 * with a corner above the element; odd in a and in b, so signed sides superpose. */
static double ff_corner(double a, double b, double c)
{
    double A = a / c, B = b / c, sa = sqrt(1 + A * A), sb = sqrt(1 + B * B);
    return (A / sa * atan(B / sa) + B / sb * atan(A / sb)) / (2 * M_PI);
}

static double ff_point_ceiling(double x, double y)
{
    double h = CEIL / 2;
    return ff_corner(h - x, h - y, CEIL_Z) - ff_corner(-h - x, h - y, CEIL_Z) -
           ff_corner(h - x, -h - y, CEIL_Z) + ff_corner(-h - x, -h - y, CEIL_Z);
}

/* Mean of F (which 0) or of a point light's irradiance at L (which 1) over the open part of
 * the cell centred at (x, y), and the open fraction. */
static double open_mean(double x, double y, int which, lr_vec3 L, double *open)
{
    const int M = 200;
    double sum = 0;
    int n = 0;
    for (int j = 0; j < M; j++)
        for (int i = 0; i < M; i++) {
            double px = x + ((i + 0.5) / M - 0.5) * CELL, py = y + ((j + 0.5) / M - 0.5) * CELL;
            if (under_coaster(px, py))
                continue;
            n++;
            if (which == 0) {
                sum += ff_point_ceiling(px, py);
            } else {
                double dx = L.x - px, dy = L.y - py, d2 = dx * dx + dy * dy + L.z * L.z;
                sum += L.z / (d2 * sqrt(d2));
            }
        }
    *open = (double)n / (M * M);
    return n ? sum / n : 0;
}

static void test_covered_cells(void **state)
{
    (void)state;
    rig r, old;
    rig_build(&r, true, 40000, 1024);
    rig_build(&old, false, 40000, 16);
    size_t f0, nf, c0, nc;
    lr_tr_surface_patches(r.t, 1, &f0, &nf);
    lr_tr_surface_patches(r.t, 2, &c0, &nc);
    assert_int_equal(nf, 16);
    assert_int_equal(nc, 1);
    const lr_vec3 L = lr_v3(7.5, 7.5, 80);
    lr_light light = {.type = LR_LIGHT_POINT, .position = L, .intensity = 1, .color = {1, 1, 1}};
    double *E = calloc(3 * lr_tr_patch_count(r.t), sizeof *E);
    assert_non_null(E);
    lr_err e = {0};
    if (lr_tr_direct_irradiance(r.t, &light, E, &e))
        fail_msg("%s", e.msg);
    int partial = 0, covered = 0;
    for (size_t p = f0; p < f0 + nf; p++) {
        lr_vec3 c, n;
        double A, open;
        lr_tr_patch_geometry(r.t, p, &c, &n, &A);
        double F = open_mean(c.x, c.y, 0, L, &open);
        double Ed = open_mean(c.x, c.y, 1, L, &open);
        double f = lr_tr_open_fraction(r.t, p), Fr = lr_tr_form_factor(r.t, p, c0);
        print_message("cell (%5.1f, %5.1f): open %.4f (exact %.4f), F %.5f (%.5f), "
                      "E %.4e (%.4e), without covers F %.5f\n",
                      c.x, c.y, f, open, Fr, F, E[3 * p], Ed, lr_tr_form_factor(old.t, p, c0));
        assert_near(f, open, 0.005);
        assert_near(lr_tr_open_fraction(old.t, p), 1.0, 0.0);
        if (open == 0) {
            covered++;
            assert_true(Fr == 0 && E[3 * p] == 0 && lr_tr_escape(r.t, p) == 0);
            continue;
        }
        partial += open < 1;
        assert_near_rel(Fr, F, 0.01);
        assert_near_rel(E[3 * p], Ed, 0.005);
        /* The row sums to 1 over the open part: the ceiling, the escape, the coaster's sides. */
        assert_near(Fr + lr_tr_escape(r.t, p), 1.0, 0.01);
        /* Without the flag, the origins inside the coaster end on its inner faces. */
        assert_near(lr_tr_form_factor(old.t, p, c0), open * F, 0.015 * F);
    }
    assert_int_equal(partial, 3);
    assert_int_equal(covered, 1);
    /* Texel-point queries: a point under the coaster, one beside it, one on the ceiling. */
    assert_true(lr_tr_plane_point_covered(r.t, 1, (10 + FLOOR / 2) / FLOOR, (10 + FLOOR / 2) / FLOOR));
    assert_false(lr_tr_plane_point_covered(r.t, 1, (-20 + FLOOR / 2) / FLOOR, 0.5));
    assert_false(lr_tr_plane_point_covered(r.t, 2, 0.5, 0.5));
    assert_false(lr_tr_plane_point_covered(old.t, 1, (10 + FLOOR / 2) / FLOOR, 0.6));
    /* A ray onto the floor beside the coaster (lr_tr_cast, the receivers' light on the
     * objects): the four cells around the hit, bilinear weights scaled by their open fractions
     * and renormalised; the covered cell (15, 15) gets none. */
    lr_tr_cast_hit hit;
    const double hx = 35, hy = 20;
    assert_true(lr_tr_cast(r.t, lr_v3(hx, hy, 50), lr_v3(0, 0, -1), &hit));
    assert_int_equal(hit.surface, 1);
    double want[4], ws = 0, fu = (hx - 15) / CELL, fv = (hy - 15) / CELL;
    const double cxs[4] = {15, 45, 15, 45}, cys[4] = {15, 15, 45, 45};
    size_t cell[4];
    for (int k = 0; k < 4; k++) {
        int u = (int)((cxs[k] + FLOOR / 2) / CELL), v = (int)((cys[k] + FLOOR / 2) / CELL);
        cell[k] = f0 + (size_t)v * 4 + (size_t)u;
        want[k] = ((k & 1) ? fu : 1 - fu) * ((k & 2) ? fv : 1 - fv) *
                  lr_tr_open_fraction(r.t, cell[k]);
        ws += want[k];
    }
    assert_true(lr_tr_open_fraction(r.t, cell[0]) == 0);
    assert_int_equal(hit.n, 3);
    double sum = 0;
    for (int i = 0; i < hit.n; i++) {
        int k = 0;
        while (k < 4 && cell[k] != hit.patch[i])
            k++;
        assert_true(k > 0 && k < 4);
        assert_near(hit.w[i], want[k] / ws, 1e-12);
        sum += hit.w[i];
    }
    assert_near(sum, 1.0, 1e-12);

    /* The albedo of a diffuse or plane surface changes after create (F does not depend on
     * it); bad values and surfaces are refused with the field named. */
    const double grey[3] = {0.3, 0.3, 0.3}, bright[3] = {0.3, 1.5, 0.3};
    assert_int_equal(lr_tr_set_albedo(r.t, 1, grey, &e), LR_OK);
    e = (lr_err){0};
    assert_int_not_equal(lr_tr_set_albedo(r.t, 1, bright, &e), LR_OK);
    assert_non_null(strstr(e.msg, "albedo"));
    assert_int_not_equal(lr_tr_set_albedo(r.t, 7, grey, &e), LR_OK);
    assert_int_not_equal(lr_tr_set_albedo(NULL, 0, grey, &e), LR_OK);
    free(E);
    rig_free(&r);
    rig_free(&old);
}

/* Translucent radiosity's own scene (lr_tr_create_scene, the lamp shade's and LED shade's
 * model, and any closed object given it): a closed object covers the table cells under its
 * foot as the receivers' bounce's do. A 45 x 45 x 10 mm wax box on a 120 mm table of 30 mm
 * cells over the coaster's footprint: open fractions 0.75, 0.5, 0.5, 0 (10000 stratified
 * origin points per cell, 0.3 mm apart: the footprint's edges fall on their rows, so within
 * 0.005); the same box 1 mm above the table covers nothing (1 exactly). */
static double scene_open(double lift, size_t cell_of[4])
{
    char text[2048];
    snprintf(text, sizeof text,
             "{\"objects\": [{\"name\": \"block\", \"material\": \"candle_wax\","
             " \"model\": \"translucent_radiosity\","
             " \"mesh\": {\"type\": \"box\", \"size\": [45, 45, 10]},"
             " \"transform\": {\"translate\": [7.5, 7.5, %g]}}],"
             " \"lights\": [{\"type\": \"point\", \"position\": [7.5, 7.5, 80], \"intensity\": 1}],"
             " \"camera\": {\"position\": [0, -400, 200], \"target\": [0, 0, 0]},"
             " \"receivers\": [{\"name\": \"table\", \"type\": \"plane\", \"center\": [0, 0, 0],"
             " \"normal\": [0, 0, 1], \"size\": [%g, %g], \"albedo\": [0.5, 0.5, 0.5]}]}",
             5.0 + lift, FLOOR, FLOOR);
    lr_scene *sc;
    lr_err e = {0};
    if (lr_scene_parse(text, strlen(text), "block.json", NULL, &sc, &e))
        fail_msg("%s", e.msg);
    lr_tr *t;
    lr_tr_settings set = {.rays_per_patch = 10000, .receiver_mm = CELL, .seed = 3};
    if (lr_tr_create_scene(sc, &set, &t, &e))
        fail_msg("%s", e.msg);
    size_t f0, nf;
    lr_tr_surface_patches(t, 1, &f0, &nf);
    assert_int_equal(nf, 16);
    double sum = 0;
    for (size_t p = f0; p < f0 + nf; p++) {
        lr_vec3 c;
        lr_tr_patch_geometry(t, p, &c, NULL, NULL);
        double f = lr_tr_open_fraction(t, p);
        int k = (c.x > 0) + 2 * (c.y > 0); /* the four cells about the origin */
        if (fabs(c.x) < CELL && fabs(c.y) < CELL)
            cell_of[k] = (size_t)(1000 * f + 0.5);
        else
            assert_true(f == 1.0);
        sum += f;
    }
    lr_tr_destroy(t);
    lr_scene_destroy(sc);
    return sum;
}

static void test_scene_objects_cover(void **state)
{
    (void)state;
    size_t open[4] = {0}, lifted[4] = {0};
    double sum = scene_open(0.0, open);
    print_message("box on the table: open %.3f %.3f %.3f %.3f (0.75 0.5 0.5 0)\n",
                  open[0] / 1e3, open[1] / 1e3, open[2] / 1e3, open[3] / 1e3);
    const double want[4] = {0.75, 0.5, 0.5, 0.0};
    for (int k = 0; k < 4; k++)
        assert_near(open[k] / 1e3, want[k], 0.005);
    assert_near(sum, 16 - 2.25, 0.02); /* the footprint is 2.25 cells */
    assert_near(scene_open(1.0, lifted), 16.0, 0.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_covered_cells),
        cmocka_unit_test(test_scene_objects_cover),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
