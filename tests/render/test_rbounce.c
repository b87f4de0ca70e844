/* Receiver inter-reflection for every model (render/bounce/rbounce.h, issue 12 part 4) against
 * closed forms, through the module's own scene build (receivers as 30 mm patches, objects as
 * occluders, 512 cosine rays per patch):
 *  - the plate-to-plate form factor (area-weighted sum of the patches') of perpendicular
 *    rectangles with a common edge (Hottel / Howell C-14) and of directly opposed ones (C-11),
 *    within 1 %;
 *  - a closed box of six inward planes, albedo rho, a unit point light inside: all orders of
 *    the bounce carry rho P0 / (1 - rho) (P0 = 4 pi), on the patches and integrated over the
 *    texel grids; the same with a uniform VPL irradiance X and no light: rho X A / (1 - rho);
 *  - linearity in intensity (another slot at 2.5x) and superposition of direct and VPL light;
 *  - an object between two plates cuts their exchange;
 *  - the field (default off, a SETTINGS change) and not needed with translucent_radiosity or
 *    render.lpv (both bounce between the receivers already). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/bounce/objlight.h"
#include "render/bounce/rbounce.h"
#include "render/core/recv_grid.h"
#include "render/scene/dirty.h"
#include "tests/support/near.h"
#include "tests/support/render.h"

static const char *const on[] = {"render.receiver_bounce=true", NULL};

/* A scene of plane receivers (JSON array text) with a far 1 mm ball (objects are required)
 * or the given object, and one point light at L. */
static lr_scene *scene(const char *receivers, const char *object, lr_vec3 L)
{
    char doc[4096];
    snprintf(doc, sizeof doc,
             "{\"name\":\"t\",\"objects\":[%s],"
             "\"lights\":[{\"type\":\"point\",\"position\":[%g,%g,%g],\"intensity\":1}],"
             "\"camera\":{\"position\":[0,-3000,100],\"target\":[0,0,0]},"
             "\"receivers\":[%s]}",
             object ? object
                    : "{\"name\":\"o\",\"material\":\"candle_wax\",\"mesh\":{\"type\":\"sphere\","
                      "\"radius\":1},\"transform\":{\"translate\":[0,0,-5000]}}",
             L.x, L.y, L.z, receivers);
    return lr_test_scene_text(doc, on);
}

static lr_rbounce *bounce_of(const lr_scene *s)
{
    lr_rbounce *rb = NULL;
    lr_err e = {0};
    if (lr_rbounce_update(&rb, s, NULL, &e))
        fail_msg("%s", e.msg);
    assert_non_null(rb);
    return rb;
}

/* F from receiver a to receiver b: sum_p A_p sum_q F_pq / A_a. */
static double plate_ff(const lr_rbounce *rb, int a, int b)
{
    const lr_tr *t = lr_rbounce_solver(rb);
    int f0 = lr_rbounce_first_receiver(rb);
    size_t pa, na, pb, nb;
    lr_tr_surface_patches(t, f0 + a, &pa, &na);
    lr_tr_surface_patches(t, f0 + b, &pb, &nb);
    double sum = 0, area = 0;
    for (size_t p = pa; p < pa + na; p++) {
        double A, f = 0;
        lr_vec3 c, n;
        lr_tr_patch_geometry(t, p, &c, &n, &A);
        for (size_t q = pb; q < pb + nb; q++)
            f += lr_tr_form_factor(t, p, q);
        sum += A * f;
        area += A;
    }
    return sum / area;
}

static double ff_opposed(double X, double Y)
{
    double a = sqrt((1 + X * X) * (1 + Y * Y) / (1 + X * X + Y * Y));
    return 2 / (M_PI * X * Y) *
           (log(a) + X * sqrt(1 + Y * Y) * atan(X / sqrt(1 + Y * Y)) +
            Y * sqrt(1 + X * X) * atan(Y / sqrt(1 + X * X)) - X * atan(X) - Y * atan(Y));
}

/* Howell C-14: from a plate of width w to one of height h sharing an edge of length l,
 * W = w / l, H = h / l. */
static double ff_perpendicular(double W, double H)
{
    double W2 = W * W, H2 = H * H, s = sqrt(H2 + W2);
    double l = log((1 + W2) * (1 + H2) / (1 + W2 + H2)) +
               W2 * log(W2 * (1 + W2 + H2) / ((1 + W2) * (W2 + H2))) +
               H2 * log(H2 * (1 + H2 + W2) / ((1 + H2) * (H2 + W2)));
    return (W * atan(1 / W) + H * atan(1 / H) - s * atan(1 / s) + 0.25 * l) / (M_PI * W);
}

static void test_form_factors(void **state)
{
    (void)state;
    /* A table (x: l, y: w) and a wall at y = 0 facing +y (x: l, z: h), common edge along x. */
    const double l = 600, w = 420, h = 720;
    char rc[1024];
    snprintf(rc, sizeof rc,
             "{\"name\":\"table\",\"type\":\"plane\",\"center\":[0,%g,0],\"normal\":[0,0,1],"
             "\"size\":[%g,%g],\"albedo\":[0.5,0.5,0.5]},"
             "{\"name\":\"wall\",\"type\":\"plane\",\"center\":[0,0,%g],\"normal\":[0,1,0],"
             "\"size\":[%g,%g],\"albedo\":[0.5,0.5,0.5]}",
             w / 2, l, w, h / 2, l, h);
    lr_scene *s = scene(rc, NULL, lr_v3(0, 100, 100));
    lr_rbounce *rb = bounce_of(s);
    double f01 = plate_ff(rb, 0, 1), f10 = plate_ff(rb, 1, 0);
    double F01 = ff_perpendicular(w / l, h / l), F10 = ff_perpendicular(h / l, w / l);
    print_message("perpendicular plates: F %.5f / %.5f, closed form %.5f / %.5f\n", f01, f10,
                  F01, F10);
    assert_near_rel(f01, F01, 0.01);
    assert_near_rel(f10, F10, 0.01);
    lr_rbounce_destroy(rb);
    lr_scene_destroy(s);

    /* Directly opposed a x b at distance c. */
    const double a = 600, b = 360, c = 480;
    snprintf(rc, sizeof rc,
             "{\"name\":\"floor\",\"type\":\"plane\",\"center\":[0,0,0],\"normal\":[0,0,1],"
             "\"size\":[%g,%g],\"albedo\":[0.5,0.5,0.5]},"
             "{\"name\":\"ceiling\",\"type\":\"plane\",\"center\":[0,0,%g],\"normal\":[0,0,-1],"
             "\"size\":[%g,%g],\"albedo\":[0.5,0.5,0.5]}",
             a, b, c, a, b);
    s = scene(rc, NULL, lr_v3(0, 0, 100));
    rb = bounce_of(s);
    double f = plate_ff(rb, 0, 1), F = ff_opposed(a / c, b / c);
    print_message("opposed plates: F %.5f / %.5f, closed form %.5f\n", f, plate_ff(rb, 1, 0), F);
    assert_near_rel(f, F, 0.01);
    assert_near_rel(plate_ff(rb, 1, 0), F, 0.01);
    lr_rbounce_destroy(rb);
    lr_scene_destroy(s);
}

/* The inside of a cube of edge 2 h centred at the origin: six planes facing in (the floor,
 * z = -h, first), with the given object (NULL: scene()'s far ball). */
static lr_scene *cube(double h, double rho, lr_vec3 L, const char *object)
{
    static const int ax[6][3] = {{0, 0, 1}, {0, 0, -1}, {0, 1, 0}, {0, -1, 0}, {1, 0, 0}, {-1, 0, 0}};
    char rc[3072];
    size_t k = 0;
    for (int i = 0; i < 6; i++)
        k += (size_t)snprintf(rc + k, sizeof rc - k,
                              "%s{\"name\":\"f%d\",\"type\":\"plane\",\"center\":[%g,%g,%g],"
                              "\"normal\":[%d,%d,%d],\"size\":[%g,%g],\"albedo\":[%g,%g,%g]}",
                              i ? "," : "", i, -h * ax[i][0], -h * ax[i][1], -h * ax[i][2],
                              ax[i][0], ax[i][1], ax[i][2], 2 * h, 2 * h, rho, rho, rho);
    return scene(rc, object, L);
}

/* Sum over the receivers' patches of A_p E_b,p (band 0), and the same integrated over the
 * texel grids. */
static void bounced_power(const lr_rbounce *rb, const lr_scene *s, int slot, double *patches,
                          double *grid)
{
    const lr_tr *t = lr_rbounce_solver(rb);
    int f0 = lr_rbounce_first_receiver(rb);
    *patches = *grid = 0;
    for (int r = 0; r < lr_scene_receiver_count(s); r++) {
        size_t p0, np;
        lr_tr_surface_patches(t, f0 + r, &p0, &np);
        for (size_t p = p0; p < p0 + np; p++) {
            double A, X[3];
            lr_vec3 c, n;
            lr_tr_patch_geometry(t, p, &c, &n, &A);
            lr_tr_indirect(t, slot, p, X);
            *patches += A * X[0];
        }
        const float *g = lr_rbounce_grid(rb, r, slot);
        assert_non_null(g);
        const lr_receiver *rc = lr_scene_receiver_at(s, r);
        double dA = rc->size[0] * rc->size[1] / ((double)LR_RECV_GRID * LR_RECV_GRID), sum = 0;
        for (size_t q = 0; q < (size_t)LR_RECV_GRID * LR_RECV_GRID; q++)
            sum += g[3 * q];
        *grid += sum * dA;
    }
}

static void test_closed_box(void **state)
{
    (void)state;
    const double rho = 0.6, h = 150;
    lr_scene *s = cube(h, rho, lr_v3(10, -20, 15), NULL);
    lr_rbounce *rb = bounce_of(s);
    lr_err e = {0};
    const double w[1][3] = {{1, 1, 1}};
    if (lr_rbounce_solve(rb, 0, w, &e))
        fail_msg("%s", e.msg);
    double P = rho * 4 * M_PI / (1 - rho), pp, pg;
    bounced_power(rb, s, 0, &pp, &pg);
    print_message("closed box, light: bounced power %.4f (patches) %.4f (grids), closed form %.4f\n",
                  pp, pg, P);
    assert_near_rel(pp, P, 0.01);
    assert_near_rel(pg, P, 0.02);

    /* Linearity: slot 1, cold, at 2.5x the intensity, texel by texel. */
    const double w2[1][3] = {{2.5, 2.5, 2.5}};
    if (lr_rbounce_solve(rb, 1, w2, &e))
        fail_msg("%s", e.msg);
    for (int r = 0; r < 6; r++) {
        const float *g0 = lr_rbounce_grid(rb, r, 0), *g1 = lr_rbounce_grid(rb, r, 1);
        for (size_t q = 0; q < 3 * (size_t)LR_RECV_GRID * LR_RECV_GRID; q++)
            assert_near_rel(g1[q], 2.5 * g0[q], 1e-5);
    }

    /* A uniform VPL irradiance X and no light: rho X A_total / (1 - rho). */
    const double X = 3e-4;
    const size_t n = (size_t)LR_RECV_GRID * LR_RECV_GRID;
    double *vg = malloc(6 * n * sizeof *vg);
    assert_non_null(vg);
    for (size_t q = 0; q < n; q++)
        for (int c = 0; c < 6; c++)
            vg[6 * q + (size_t)c] = c < 3 ? X : 1e9; /* the variance columns are not read */
    for (int r = 0; r < 6; r++)
        lr_rbounce_vpl_d(rb, r, vg, 6);
    if (lr_rbounce_solve(rb, 2, NULL, &e))
        fail_msg("%s", e.msg);
    double Pv = rho * X * 6 * 4 * h * h / (1 - rho), vp, vgp;
    bounced_power(rb, s, 2, &vp, &vgp);
    print_message("closed box, VPL grid: bounced power %.4f / %.4f, closed form %.4f\n", vp, vgp, Pv);
    assert_near_rel(vp, Pv, 0.01);
    assert_near_rel(vgp, Pv, 0.02);

    /* Superposition: light + VPLs (slot 3) = slot 0 + slot 2, per texel, within the solver's
     * 1e-4 stopping tolerance. */
    if (lr_rbounce_solve(rb, 3, w, &e))
        fail_msg("%s", e.msg);
    double d = 0, m = 0;
    for (int r = 0; r < 6; r++) {
        const float *a = lr_rbounce_grid(rb, r, 0), *b = lr_rbounce_grid(rb, r, 2),
                    *c = lr_rbounce_grid(rb, r, 3);
        for (size_t q = 0; q < 3 * n; q++) {
            d += fabs(c[q] - (a[q] + b[q]));
            m += fabs(c[q]);
        }
    }
    print_message("superposition: relative L1 %.2e\n", d / m);
    assert_true(d / m < 2e-3);
    free(vg);

    /* The next update forgets the VPL grids (a new accumulation frame brings new ones) and
     * keeps F (same geometry): slot 2, warm-started from its VPL solution, then decays to
     * nothing (the sweeps shrink it by about rho each: 50 sweeps). */
    if (lr_rbounce_update(&rb, s, NULL, &e))
        fail_msg("%s", e.msg);
    double bs;
    lr_rbounce_times(rb, &bs, NULL, NULL);
    assert_true(bs == 0);
    if (lr_rbounce_solve(rb, 2, NULL, &e))
        fail_msg("%s", e.msg);
    bounced_power(rb, s, 2, &vp, &vgp);
    assert_true(vp < 1e-6 * Pv && vgp < 1e-6 * Pv);
    lr_rbounce_destroy(rb);
    lr_scene_destroy(s);
}

/* cube() with a closed box of candle wax of the given size centred at c. */
static lr_scene *cube_with_wax_box(double h, double rho, lr_vec3 size, lr_vec3 c)
{
    char box[512];
    snprintf(box, sizeof box,
             "{\"name\":\"box\",\"material\":\"candle_wax\",\"mesh\":{\"type\":\"box\","
             "\"size\":[%g,%g,%g]},\"transform\":{\"translate\":[%g,%g,%g]}}",
             size.x, size.y, size.z, c.x, c.y, c.z);
    return cube(h, rho, lr_v3(10, -20, 15), box);
}

/* A coaster (a closed 45 x 45 x 0.1 mm box of wax) stands on the closed cube's floor across
 * four 30 mm cells (a quarter, two halves and the whole of one under it); a uniform VPL
 * irradiance X on every open texel and a bright one (1000 X) on the texels under the coaster,
 * which no camera sees. In the closed cube every open texel's bounce is rho X / (1 - rho)
 * (render/transrad/cover.c: the cells' F, E and solution over their open part; the grid
 * written by open-weighted bilinear; the covered texels left out of the cells' means), less
 * what the coaster's top absorbs (under 1 %); within 2 %. Counting the covered part as
 * surface, the texels beside the coaster read about half of it. */
static void test_covered_cells(void **state)
{
    (void)state;
    const double rho = 0.6, h = 150, X = 3e-4;
    lr_scene *s = cube_with_wax_box(h, rho, lr_v3(45, 45, 0.1), lr_v3(7.5, 7.5, -149.95));
    assert_true(lr_scene_object_at(s, 0)->closed);
    lr_rbounce *rb = bounce_of(s);
    const lr_tr *t = lr_rbounce_solver(rb);
    int f0 = lr_rbounce_first_receiver(rb);
    size_t p0, np;
    lr_tr_surface_patches(t, f0, &p0, &np);
    int partial = 0;
    for (size_t p = p0; p < p0 + np; p++)
        partial += lr_tr_open_fraction(t, p) < 1;
    assert_int_equal(partial, 4);
    const size_t n = (size_t)LR_RECV_GRID * LR_RECV_GRID;
    double *vg = malloc(6 * n * sizeof *vg);
    unsigned char *under = malloc(n);
    assert_non_null(vg);
    assert_non_null(under);
    for (size_t q = 0; q < n; q++)
        under[q] = lr_tr_plane_point_covered(t, f0, ((double)(q % LR_RECV_GRID) + 0.5) / LR_RECV_GRID,
                                             ((double)(q / LR_RECV_GRID) + 0.5) / LR_RECV_GRID);
    for (int r = 0; r < 6; r++) {
        for (size_t q = 0; q < n; q++)
            for (int c = 0; c < 6; c++)
                vg[6 * q + (size_t)c] = c < 3 ? (r == 0 && under[q] ? 1000 * X : X) : 1e9;
        lr_rbounce_vpl_d(rb, r, vg, 6);
    }
    lr_err e = {0};
    if (lr_rbounce_solve(rb, 0, NULL, &e))
        fail_msg("%s", e.msg);
    const float *g = lr_rbounce_grid(rb, 0, 0);
    double want = rho * X / (1 - rho), lo = INFINITY, hi = 0;
    size_t n_under = 0;
    for (size_t q = 0; q < n; q++) {
        if (under[q]) {
            n_under++;
            continue;
        }
        double v = g[3 * q];
        lo = fmin(lo, v);
        hi = fmax(hi, v);
    }
    print_message("floor with a coaster: %zu texels under it; open texels' bounce %.4e .. %.4e, "
                  "closed form %.4e\n", n_under, lo, hi, want);
    /* The footprint is 45 x 45 mm of the 300 x 300 floor's 256^2 texels. */
    assert_near_rel((double)n_under, 45.0 * 45 / (300.0 * 300) * (double)n, 0.05);
    assert_near_rel(lo, want, 0.02);
    assert_near_rel(hi, want, 0.02);
    free(vg);
    free(under);
    lr_rbounce_destroy(rb);
    lr_scene_destroy(s);
}

/* A wax block (60 x 60 x 80 mm, closed) stands on the closed cube's floor; a uniform VPL
 * irradiance X on the six planes, no light. The block's patches reflect the receivers' light
 * with the albedo wax shows diffuse light (lr_objlight_albedo: 1 - <F_t> + <F_t> R, about
 * 0.8) and the floor's cells under it count only their open part, so the power put in,
 * sum over the planes of A f X (A f a cell's open area), equals the power absorbed,
 * sum A f (1 - rho)(X + E_b) over the planes plus sum A (1 - rho_o) E_b over the block, per
 * band; within 1.5 % (F's reciprocity by 512 rays a patch). With the block absorbing all it
 * gets (albedo 0, as an absorbing block would) the balance misses by the block's reflected share. */
static void test_object_reflects(void **state)
{
    (void)state;
    const double rho = 0.6, h = 150, X = 3e-4;
    lr_scene *s = cube_with_wax_box(h, rho, lr_v3(60, 60, 80), lr_v3(20, -10, -110));
    lr_rbounce *rb = bounce_of(s);
    const lr_tr *t = lr_rbounce_solver(rb);
    int f0 = lr_rbounce_first_receiver(rb);
    double rho_o[3];
    lr_objlight_albedo(lr_scene_object_at(s, 0), rho_o);
    for (int b = 0; b < 3; b++)
        assert_true(rho_o[b] > 0.5 && rho_o[b] < 1);
    const size_t n = (size_t)LR_RECV_GRID * LR_RECV_GRID;
    double *vg = malloc(6 * n * sizeof *vg);
    assert_non_null(vg);
    for (size_t q = 0; q < 6 * n; q++)
        vg[q] = q % 6 < 3 ? X : 1e9;
    for (int r = 0; r < 6; r++)
        lr_rbounce_vpl_d(rb, r, vg, 6);
    lr_err e = {0};
    if (lr_rbounce_solve(rb, 0, NULL, &e))
        fail_msg("%s", e.msg);
    double in = 0, out[3] = {0, 0, 0}, reflected = 0;
    for (size_t p = 0; p < lr_tr_patch_count(t); p++) {
        double A, Xb[3];
        lr_vec3 c, nrm;
        lr_tr_patch_geometry(t, p, &c, &nrm, &A);
        lr_tr_indirect(t, 0, p, Xb);
        bool object = lr_tr_patch_surface(t, p) < f0;
        double Af = A * lr_tr_open_fraction(t, p);
        if (!object)
            in += Af * X;
        for (int b = 0; b < 3; b++)
            out[b] += object ? A * (1 - rho_o[b]) * Xb[b] : Af * (1 - rho) * (X + Xb[b]);
        reflected += object ? A * rho_o[0] * Xb[0] : 0;
    }
    print_message("a wax block on the floor: power in %.5g, absorbed %.5g %.5g %.5g; the block "
                  "reflects %.2f %% of it\n", in, out[0], out[1], out[2], 100 * reflected / in);
    for (int b = 0; b < 3; b++)
        assert_near_rel(out[b], in, 0.015);
    assert_true(reflected > 0.03 * in);

    /* The albedo follows the material (a preset, a translucency knob) without rebuilding F:
     * each block patch leaves rho_o times what reaches it, before and after (within the
     * solve's stopping residual, 1e-4 relative over the scene). */
    for (int k = 0; k < 2; k++) {
        if (k == 1) {
            unsigned dirty = 0;
            assert_int_equal(lr_scene_set(s, "objects[0].material", "ketchup", &dirty, &e), LR_OK);
            if (lr_rbounce_update(&rb, s, NULL, &e))
                fail_msg("%s", e.msg);
            for (int r = 0; r < 6; r++) /* an update forgets the VPL grids */
                lr_rbounce_vpl_d(rb, r, vg, 6);
            if (lr_rbounce_solve(rb, 0, NULL, &e))
                fail_msg("%s", e.msg);
            double bs;
            lr_rbounce_times(rb, &bs, NULL, NULL);
            assert_true(bs == 0);
            double was = rho_o[2];
            lr_objlight_albedo(lr_scene_object_at(s, 0), rho_o);
            print_message("block of ketchup: albedo %.3f %.3f %.3f (wax's blue %.3f)\n", rho_o[0],
                          rho_o[1], rho_o[2], was);
            assert_true(fabs(rho_o[2] - was) > 0.05);
        }
        int checked = 0;
        for (size_t p = 0; p < lr_tr_patch_count(t); p++) {
            if (lr_tr_patch_surface(t, p) >= f0)
                continue;
            double W[3], H[3];
            lr_tr_radiosity(t, 0, p, W);
            lr_tr_irradiance(t, 0, p, H);
            for (int b = 0; b < 3 && H[b] > 0; b++, checked++)
                assert_near_rel(W[b], rho_o[b] * H[b], 2e-3); /* H after the last sweep */
        }
        assert_true(checked > 0);
    }
    free(vg);
    lr_rbounce_destroy(rb);
    lr_scene_destroy(s);
}

/* Floor and ceiling 400 x 400, 200 mm apart; a 600 x 600 x 20 mm slab of wax between them cuts
 * their exchange: the ceiling's bounce from the floor (light under the slab) goes to 0. */
static void test_object_blocks(void **state)
{
    (void)state;
    static const char rc[] =
        "{\"name\":\"floor\",\"type\":\"plane\",\"center\":[0,0,0],\"normal\":[0,0,1],"
        "\"size\":[400,400],\"albedo\":[0.8,0.8,0.8]},"
        "{\"name\":\"ceiling\",\"type\":\"plane\",\"center\":[0,0,200],\"normal\":[0,0,-1],"
        "\"size\":[400,400],\"albedo\":[0.8,0.8,0.8]}";
    static const char slab[] =
        "{\"name\":\"slab\",\"material\":\"candle_wax\",\"mesh\":{\"type\":\"box\","
        "\"size\":[600,600,20]},\"transform\":{\"translate\":[0,0,100]}}";
    lr_vec3 L = lr_v3(0, 0, 50);
    lr_scene *s0 = scene(rc, NULL, L), *s1 = scene(rc, slab, L);
    lr_rbounce *r0 = bounce_of(s0), *r1 = bounce_of(s1);
    double F0 = plate_ff(r0, 0, 1), F1 = plate_ff(r1, 0, 1);
    print_message("floor -> ceiling: F %.5f open (closed form %.5f), %.5f behind the slab\n", F0,
                  ff_opposed(2, 2), F1);
    assert_near_rel(F0, ff_opposed(2, 2), 0.01);
    assert_true(F1 == 0);
    lr_err e = {0};
    const double w[1][3] = {{1, 1, 1}};
    if (lr_rbounce_solve(r0, 0, w, &e) || lr_rbounce_solve(r1, 0, w, &e))
        fail_msg("%s", e.msg);
    const float *c0 = lr_rbounce_grid(r0, 1, 0), *c1 = lr_rbounce_grid(r1, 1, 0);
    double s_open = 0, s_blocked = 0;
    for (size_t q = 0; q < 3 * (size_t)LR_RECV_GRID * LR_RECV_GRID; q++) {
        s_open += c0[q];
        s_blocked += c1[q];
    }
    assert_true(s_open > 0);
    assert_true(s_blocked == 0);
    lr_rbounce_destroy(r0);
    lr_rbounce_destroy(r1);
    lr_scene_destroy(s0);
    lr_scene_destroy(s1);
}

static void test_field(void **state)
{
    (void)state;
    /* The field's default is off; the shipped candle scenes turn it on. */
    lr_scene *t = scene("{\"name\":\"floor\",\"type\":\"plane\",\"center\":[0,0,0],"
                        "\"normal\":[0,0,1],\"size\":[100,100],\"albedo\":[0.5,0.5,0.5]}",
                        NULL, lr_v3(0, 0, 50));
    lr_err e = {0};
    unsigned dirty = 0;
    assert_true(lr_scene_render(t)->receiver_bounce); /* scene() sets it */
    assert_int_equal(lr_scene_set(t, "render.receiver_bounce", "false", &dirty, &e), LR_OK);
    assert_true(dirty & LR_DIRTY_SETTINGS);
    assert_false(lr_rbounce_needed(t));
    lr_scene_destroy(t);
    static const char plain[] =
        "{\"name\":\"t\",\"objects\":[{\"name\":\"o\",\"material\":\"candle_wax\","
        "\"mesh\":{\"type\":\"sphere\",\"radius\":20}}],"
        "\"lights\":[{\"type\":\"point\",\"position\":[0,0,100],\"intensity\":0.01}],"
        "\"camera\":{\"position\":[0,-300,100],\"target\":[0,0,0]}}";
    t = lr_test_scene_text(plain, NULL);
    assert_false(lr_scene_render(t)->receiver_bounce);
    lr_scene_destroy(t);
    lr_scene *s = lr_test_scene("candle", NULL, NULL);
    assert_true(lr_scene_render(s)->receiver_bounce);
    assert_true(lr_rbounce_needed(s));
    assert_int_equal(lr_scene_set(s, "render.receiver_bounce", "false", &dirty, &e), LR_OK);
    assert_false(lr_rbounce_needed(s));
    assert_int_equal(lr_scene_set(s, "render.receiver_bounce", "true", &dirty, &e), LR_OK);
    assert_true(dirty & LR_DIRTY_SETTINGS);
    assert_true(lr_rbounce_needed(s));
    e = (lr_err){0};
    assert_int_not_equal(lr_scene_set(s, "render.receiver_bounce", "1", NULL, &e), LR_OK);
    assert_non_null(strstr(e.msg, "receiver_bounce"));
    /* render.lpv's volumes carry the receivers' interreflection already: not twice. */
    assert_int_equal(lr_scene_set(s, "render.lpv", "16", NULL, &e), LR_OK);
    assert_false(lr_rbounce_needed(s));
    assert_int_equal(lr_scene_set(s, "render.lpv", "0", NULL, &e), LR_OK);
    assert_true(lr_rbounce_needed(s));
    /* translucent_radiosity's solve has the receivers in F already: not twice. */
    assert_int_equal(lr_scene_set(s, "objects[0].model", "translucent_radiosity", NULL, &e), LR_OK);
    assert_false(lr_rbounce_needed(s));
    lr_rbounce *rb = NULL;
    assert_int_equal(lr_rbounce_update(&rb, s, NULL, &e), LR_OK);
    assert_null(rb);
    /* Bad calls return errors, not crashes. */
    assert_int_not_equal(lr_rbounce_update(NULL, s, NULL, &e), LR_OK);
    assert_int_not_equal(lr_rbounce_solve(NULL, 0, NULL, &e), LR_OK);
    assert_null(lr_rbounce_grid(NULL, 0, 0));
    lr_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_form_factors),
        cmocka_unit_test(test_closed_box),
        cmocka_unit_test(test_object_blocks),
        cmocka_unit_test(test_covered_cells),
        cmocka_unit_test(test_object_reflects),
        cmocka_unit_test(test_field),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
