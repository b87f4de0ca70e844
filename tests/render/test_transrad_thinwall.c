/* Translucent radiosity on thin walls (render/transrad/thinwall.c): S columns that send the
 * slab multipole's R_tot out of the lit face and T_tot out of the far one.
 *  - a flat 0.1 mm paper slab (a 60 x 60 x 0.1 mm box, 12 mm patches) lit from below by a point
 *    light: the power leaving the lit face, the far face and the rims over the power that
 *    entered is the multipole's R_tot + T_tot, the rims' share (light spread past the edge)
 *    at most the uniform-entry estimate, the faces R_tot and T_tot less it; with the rule off
 *    (the profile at the centroids) the far face gets 1.26 T_tot (2.1 T_tot on the led_shade);
 *  - the votive's 7 mm wax wall: its end faces (rims) let out the share of the light the
 *    spread carries past the edge, 4 E[r] / (pi side) per profile for uniform entry;
 *  - the same forced on for an index-mismatched (eta 1.5) 0.3 mm wall under diffuse light: the
 *    split of the T_hem that enters, and the Fresnel-reflected rest;
 *  - the lateral spread: one lit 4 mm patch of a 1.5 mm porcelain slab sends into the patch
 *    above it the share of T that the profile's convolution with the square gives (a
 *    quadrature), and keeps the share of R that lands in itself;
 *  - energy: a slab without absorption lets out all that entered;
 *  - the rule: d <= patch_mm (paper 0.1 mm, porcelain 1.5 and 3 mm, wax 7 and 12 mm thin at
 *    12 mm patches; wax 40 mm not), and bad settings.
 *
 * Tolerances. The lit and far faces' shares are sums of the same numbers the column was
 * built from, so they hold to what the sparse S drops: entries below 1e-7 of a column's input
 * (at most n_s = 70 per column, 7e-6) plus float storage (6e-8): 1e-4 relative. The lateral
 * shares are Monte Carlo over 256 stratified entry points (one exit each): the standard error
 * of a hit fraction f is at most sqrt(f (1 - f) / 256) <= 0.031; the tests allow 4 of it
 * (a normal error's two-sided 4 sigma: 6e-5), plus 1e-3 for the tabulated CDF.
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

#include "render/mesh/shapes.h"
#include "render/transrad/tr_priv.h"
#include "tests/support/near.h"

typedef struct slab {
    lr_mesh *mesh;
    lr_bvh *bvh;
    lr_coeffs co;
    lr_tr *t;
} slab;

static const lr_medium paper = {.sigma_a = {0.156, 0.156, 0.442},
                                .sigma_s_prime = {56.1, 56.1, 56.2}, .eta = 1.0};
static const lr_medium porcelain = {.sigma_a = {0.098, 0.123, 0.18},
                                    .sigma_s_prime = {5.23, 5.57, 5.97}, .eta = 1.5};

/* A side x side x d box at the origin (faces at z = +-d/2) of medium m as a translucent
 * radiosity object with slab thickness d. */
static void slab_make(slab *s, const lr_medium *m, double side, double d, double patch_mm,
                      int thin_wall)
{
    lr_err e = {0};
    lr_box_desc bd = {.center = lr_v3(0, 0, 0), .size = lr_v3(side, side, d)};
    if (lr_mesh_box(&bd, &s->mesh, &e) || lr_bvh_create(s->mesh, &s->bvh, &e) ||
        lr_coeffs_derive(m, &s->co, &e))
        fail_msg("%s", e.msg);
    lr_tr_surface_desc sd = {.kind = LR_TR_TRANSLUCENT, .mesh = s->mesh, .bvh = s->bvh,
                             .coeffs = &s->co, .model = LR_SSS_TRANSLUCENT_RADIOSITY,
                             .thickness_mm = d, .patch_mm = patch_mm};
    lr_tr_settings set = {.rays_per_patch = 64, .thin_wall = thin_wall, .seed = 3};
    if (lr_tr_create(&sd, 1, &set, &s->t, &e))
        fail_msg("%s", e.msg);
}

static void slab_free(slab *s)
{
    lr_tr_destroy(s->t);
    lr_bvh_destroy(s->bvh);
    lr_mesh_destroy(s->mesh);
}

/* Power per band leaving the bottom face (n_z < -0.5), the top face (n_z > 0.5) and the rims,
 * from W (all of it) or, with sss, the part that scattered inside (map value x T_hem). */
static void faces(const slab *s, bool sss, double bottom[3], double top[3], double rims[3])
{
    double th = lr_hemi_transmittance(s->co.eta);
    for (int b = 0; b < 3; b++)
        bottom[b] = top[b] = rims[b] = 0;
    for (size_t p = 0; p < lr_tr_patch_count(s->t); p++) {
        lr_vec3 n;
        double A, W[3];
        lr_tr_patch_geometry(s->t, p, NULL, &n, &A);
        if (sss) {
            lr_tr_map_radiosity(s->t, 0, p, W);
            for (int b = 0; b < 3; b++)
                W[b] *= th;
        } else {
            lr_tr_radiosity(s->t, 0, p, W);
        }
        double *acc = n.z < -0.5 ? bottom : n.z > 0.5 ? top : rims;
        for (int b = 0; b < 3; b++)
            acc[b] += A * W[b];
    }
}

/* Power entering the bottom face from a point light (eta 1: all of the irradiance enters). */
static void entered_bottom(const slab *s, double out[3])
{
    for (int b = 0; b < 3; b++)
        out[b] = 0;
    for (size_t p = 0; p < lr_tr_patch_count(s->t); p++) {
        lr_vec3 n;
        double A, H[3];
        lr_tr_patch_geometry(s->t, p, NULL, &n, &A);
        lr_tr_irradiance(s->t, 0, p, H);
        if (n.z < -0.5)
            for (int b = 0; b < 3; b++)
                out[b] += A * H[b];
    }
}

static void light_below(slab *s)
{
    lr_light L = {.type = LR_LIGHT_POINT, .position = lr_v3(5, -3, -40), .intensity = 1,
                  .color = {1, 1, 1}};
    lr_tr_stats st;
    lr_err e = {0};
    if (lr_tr_solve_light(s->t, &L, 0, &st, &e))
        fail_msg("%s", e.msg);
}

/* The share of the light entering a side x side face that a spread of profile `which` carries
 * past the face's edge, for entry uniform over the face: a displacement r in a uniform
 * direction crosses an edge x away with probability E[max(0, r cos phi - x)] over x uniform,
 * E[r] / (pi side) per edge (Buffon), 4 E[r] / (pi side) for the square. E[r] from the
 * tabulated inverse CDF (midpoint rule). A point light below weights the middle more, so the
 * measured share is below this. */
static double edge_share(const lr_coeffs *co, double d, int which, int b, double side)
{
    lr_tr_spread sp;
    lr_tr_spread_build(co, d, &sp);
    double mean = 0;
    enum { U = 4096 };
    for (int k = 0; k < U; k++)
        mean += lr_tr_spread_radius(&sp, which, b, (k + 0.5) / U) / U;
    return 4 * mean / (M_PI * side);
}

/* Irradiance 1 on every patch of the bottom face (diffuse light from below), solved; returns
 * the face's area. */
static double light_bottom_evenly(slab *s)
{
    size_t n = lr_tr_patch_count(s->t);
    double *E = calloc(3 * n, sizeof *E), Ab = 0;
    assert_non_null(E);
    for (size_t p = 0; p < n; p++) {
        lr_vec3 nn;
        double A;
        lr_tr_patch_geometry(s->t, p, NULL, &nn, &A);
        if (nn.z < -0.5) {
            E[3 * p] = E[3 * p + 1] = E[3 * p + 2] = 1;
            Ab += A;
        }
    }
    lr_tr_stats st;
    lr_err e = {0};
    int rc = lr_tr_solve_irradiance(s->t, E, 0, &st, &e);
    free(E);
    if (rc)
        fail_msg("%s", e.msg);
    return Ab;
}

static void test_paper_slab_split(void **state)
{
    (void)state;
    slab s;
    slab_make(&s, &paper, 60, 0.1, 12, LR_TR_THIN_AUTO);
    assert_true(lr_tr_wall_thin(&s.co, 0.1, 12));
    light_below(&s);
    double R[3], T[3], in[3], bot[3], top[3], rim[3];
    lr_multipole_total(&s.co, 0.1, R, T);
    entered_bottom(&s, in);
    faces(&s, false, bot, top, rim);
    for (int b = 0; b < 3; b++) {
        /* Light spread past the slab's edge leaves through its rims (the end faces), at most
         * the uniform-entry share of each profile; the rest splits as R and T. */
        double rim_max = R[b] * edge_share(&s.co, 0.1, 0, b, 60) +
                         T[b] * edge_share(&s.co, 0.1, 1, b, 60);
        printf("  band %d: lit face %.5f (R %.5f), far face %.5f (T %.5f), rims %.2e (uniform "
               "entry %.2e)\n", b, bot[b] / in[b], R[b], top[b] / in[b], T[b], rim[b] / in[b],
               rim_max);
        assert_true(in[b] > 0);
        assert_near_rel((bot[b] + top[b] + rim[b]) / in[b], R[b] + T[b], 1e-4);
        assert_true(rim[b] <= 1.5 * rim_max * in[b]);
        assert_true(bot[b] / in[b] <= R[b] * (1 + 1e-4) && top[b] / in[b] <= T[b] * (1 + 1e-4));
        assert_true(bot[b] / in[b] >= R[b] * (1 - 1e-4) - 1.5 * rim_max);
        assert_true(top[b] / in[b] >= T[b] * (1 - 1e-4) - 1.5 * rim_max);
    }
    /* The split query lights every patch, the rims too (4 x 60 x 0.1 mm of 7224 mm^2); a rim
     * keeps its light (its ray along -n runs along the wall, not across it). */
    double lit[3], opp[3], rim_share = 24.0 / (2 * 3600 + 24);
    lr_tr_subsurface_split(s.t, 0, lit, opp);
    for (int b = 0; b < 3; b++) {
        assert_true(fabs(lit[b] - R[b]) <= rim_share * (R[b] + T[b]) + 1e-4 * R[b]);
        assert_true(fabs(opp[b] - T[b]) <= rim_share * (R[b] + T[b]) + 1e-4 * T[b]);
    }
    slab_free(&s);

    /* The profile at the centroids (the rule off): the far face gets more than T, since the
     * point sums see the profiles' tails, where R(r) and T(r) agree: 0.284 = 1.26 T here
     * where the two faces' patches line up, 0.47 on the led_shade where they do not. */
    slab_make(&s, &paper, 60, 0.1, 12, LR_TR_THIN_OFF);
    lr_tr_subsurface_split(s.t, 0, lit, opp);
    printf("  rule off: lit %.4f far %.4f\n", lit[0], opp[0]);
    assert_true(opp[0] > 1.15 * T[0]);
    slab_free(&s);
}

/* eta 1.5, forced thin: diffuse irradiance 1 on the bottom face enters with T_hem; R_tot and
 * T_tot of it leave the two faces; the bottom also reflects (1 - T_hem). */
static void test_fresnel_slab_split(void **state)
{
    (void)state;
    slab s;
    slab_make(&s, &porcelain, 60, 0.3, 12, LR_TR_THIN_ON);
    double Ab = light_bottom_evenly(&s);
    double th = lr_hemi_transmittance(1.5), R[3], T[3], bot[3], top[3], rim[3], wb[3], wt[3];
    lr_multipole_total(&s.co, 0.3, R, T);
    faces(&s, true, bot, top, rim);
    faces(&s, false, wb, wt, rim);
    for (int b = 0; b < 3; b++) {
        /* Uniform entry: the rims (end faces) take the share edge_share gives, the faces the
         * rest; energy to the sparse S's 1e-4. */
        double rim_share = R[b] * edge_share(&s.co, 0.3, 0, b, 60) +
                           T[b] * edge_share(&s.co, 0.3, 1, b, 60);
        printf("  band %d: rims %.3e of what entered (uniform entry %.3e)\n", b,
               rim[b] / (th * Ab), rim_share);
        assert_near_rel(bot[b] + top[b] + rim[b], (R[b] + T[b]) * th * Ab, 1e-4);
        /* A 0.3 mm strip by the edge is thinner than the 256 entry points' spacing in a
         * 12 mm patch (0.75 mm), so the column's count of entries there is a quadrature of
         * the strip, not its area (measured 0.60 of the estimate); the wax slab below, whose
         * spread is millimetres, checks the estimate itself. */
        assert_true(rim[b] > 0 && rim[b] <= 1.5 * rim_share * th * Ab);
        assert_true(bot[b] <= R[b] * th * Ab * (1 + 1e-4) &&
                    bot[b] >= (R[b] * (1 - 1e-4) - 1.25 * rim_share) * th * Ab);
        assert_true(top[b] <= T[b] * th * Ab * (1 + 1e-4) &&
                    top[b] >= (T[b] * (1 - 1e-4) - 1.25 * rim_share) * th * Ab);
        assert_near_rel(wt[b], top[b], 1e-6);                 /* nothing reflected on top */
        assert_near_rel(wb[b] - bot[b], (1 - th) * Ab, 1e-4); /* the Fresnel-reflected rest */
    }
    slab_free(&s);
}

/* A 7 mm wax wall (the votive's), thin by the rule at 12 mm patches, under diffuse light on
 * its lit face: light spread past the wall's edge leaves through the end faces (the votive's
 * rim glows in the reference; left where it entered it would not), the share the
 * uniform-entry estimate gives (edge_share: its spread is millimetres, wide against the
 * entries' 0.75 mm spacing). Monte Carlo over the 16 edge patches' 4096 entries, a rim share
 * of a few per cent: 10 % allowed. */
static void test_wall_end_faces(void **state)
{
    (void)state;
    const lr_medium wax = {.sigma_a = {0.00105, 0.00205, 0.00355},
                           .sigma_s_prime = {1.095, 1.31, 1.5}, .eta = 1.44};
    slab s;
    slab_make(&s, &wax, 60, 7, 12, LR_TR_THIN_AUTO);
    assert_true(lr_tr_wall_thin(&s.co, 7, 12));
    double Ab = light_bottom_evenly(&s);
    double th = lr_hemi_transmittance(1.44), R[3], T[3], bot[3], top[3], rim[3];
    lr_multipole_total(&s.co, 7, R, T);
    faces(&s, true, bot, top, rim);
    for (int b = 0; b < 3; b++) {
        double rim_share = R[b] * edge_share(&s.co, 7, 0, b, 60) +
                           T[b] * edge_share(&s.co, 7, 1, b, 60);
        printf("  band %d: lit face %.4f (R %.4f), far face %.4f (T %.4f), rims %.4f "
               "(estimate %.4f)\n", b, bot[b] / (th * Ab), R[b], top[b] / (th * Ab), T[b],
               rim[b] / (th * Ab), rim_share);
        assert_near_rel(bot[b] + top[b] + rim[b], (R[b] + T[b]) * th * Ab, 1e-4);
        assert_near_rel(rim[b], rim_share * th * Ab, 0.10);
    }
    slab_free(&s);
}

/* Share of a profile's light that lands in the square of side h it entered through, entry
 * uniform over the square: int P(|v|) (h - |v_x|)(h - |v_y|) / h^2 d^2v / P_tot, in polar
 * coordinates (midpoint rule, 4000 radii to 30 L, 256 angles). */
static double square_share(const lr_coeffs *c, double d, double L, int which, int band,
                           double h)
{
    int pairs = lr_multipole_pairs(c, d), nr = 4000, na = 256;
    double dr = 30 * L / nr, acc = 0, tot = 0;
    for (int i = 0; i < nr; i++) {
        double r = (i + 0.5) * dr, P[2][3];
        lr_multipole_profile_n(c, d, pairs, r, P[0], P[1]);
        double p = P[which][band], ov = 0;
        for (int k = 0; k < na; k++) {
            double a = 2 * M_PI * (k + 0.5) / na;
            double ox = h - fabs(r * cos(a)), oy = h - fabs(r * sin(a));
            if (ox > 0 && oy > 0)
                ov += ox * oy / (h * h);
        }
        acc += p * ov / na * 2 * M_PI * r * dr;
        tot += p * 2 * M_PI * r * dr;
    }
    return acc / tot;
}

static void test_lateral_spread(void **state)
{
    (void)state;
    /* 20 mm: the refinement cuts each face triangle (diagonal 28.3 mm) 15 x 15 (edges at most
     * h / 2), legs of 4/3 mm, so the 4 mm cells from the corner are exact squares. */
    const double d = 1.5, h = 4;
    slab s;
    slab_make(&s, &porcelain, 20, d, h, LR_TR_THIN_ON);
    size_t n = lr_tr_patch_count(s.t), lit = SIZE_MAX, above = SIZE_MAX;
    double best = INFINITY, best_up = INFINITY;
    /* The bottom patch at the centre and the top patch over it. */
    for (size_t p = 0; p < n; p++) {
        lr_vec3 c, nn;
        lr_tr_patch_geometry(s.t, p, &c, &nn, NULL);
        double r = hypot(c.x, c.y);
        if (nn.z < -0.5 && r < best) {
            best = r;
            lit = p;
        }
        if (nn.z > 0.5 && r < best_up) {
            best_up = r;
            above = p;
        }
    }
    assert_true(best < 1e-6 && best_up < 1e-6);
    double *E = calloc(3 * n, sizeof *E), A, Aup;
    E[3 * lit] = E[3 * lit + 1] = E[3 * lit + 2] = 1;
    lr_tr_stats st;
    lr_err e = {0};
    assert_int_equal(lr_tr_solve_irradiance(s.t, E, 0, &st, &e), LR_OK);
    lr_tr_patch_geometry(s.t, lit, NULL, NULL, &A);
    lr_tr_patch_geometry(s.t, above, NULL, NULL, &Aup);
    assert_near_rel(A, h * h, 1e-9);
    assert_near_rel(Aup, h * h, 1e-9);
    double th = lr_hemi_transmittance(1.5), R[3], T[3], Wl[3], Wu[3];
    lr_multipole_total(&s.co, d, R, T);
    lr_tr_map_radiosity(s.t, 0, lit, Wl);
    lr_tr_map_radiosity(s.t, 0, above, Wu);
    lr_tr_spread sp;
    lr_tr_spread_build(&s.co, d, &sp);
    for (int b = 0; b < 3; b++) {
        double fR = Wl[b] * th * A / (R[b] * th * A), fT = Wu[b] * th * Aup / (T[b] * th * A);
        double qR = square_share(&s.co, d, sp.L, 0, b, h), qT = square_share(&s.co, d, sp.L, 1, b, h);
        printf("  band %d: R kept in the lit patch %.3f (quadrature %.3f), T into the patch above "
               "%.3f (%.3f)\n", b, fR, qR, fT, qT);
        assert_true(fabs(fR - qR) <= 4 * sqrt(qR * (1 - qR) / 256) + 1e-3);
        assert_true(fabs(fT - qT) <= 4 * sqrt(qT * (1 - qT) / 256) + 1e-3);
        /* The spread matters here: a good part of T lands outside the patch above. */
        assert_true(qT < 0.8);
    }
    free(E);
    slab_free(&s);
}

/* No absorption: R_tot + T_tot = 1, so all that entered leaves (and escapes: F is 0 on a
 * convex slab). */
static void test_energy_no_absorption(void **state)
{
    (void)state;
    lr_medium m = paper;
    for (int b = 0; b < 3; b++)
        m.sigma_a[b] = 0;
    slab s;
    slab_make(&s, &m, 60, 0.1, 12, LR_TR_THIN_ON);
    light_below(&s);
    double R[3], T[3], in[3], bot[3], top[3], rim[3], esc[3];
    lr_multipole_total(&s.co, 0.1, R, T);
    entered_bottom(&s, in);
    faces(&s, false, bot, top, rim);
    lr_tr_escaped_power(s.t, 0, esc);
    for (int b = 0; b < 3; b++) {
        assert_near_rel(R[b] + T[b], 1.0, 1e-9);
        assert_near_rel(bot[b] + top[b] + rim[b], in[b], 1e-4);
        assert_near_rel(esc[b], in[b], 1e-4);
    }
    slab_free(&s);
}

static void test_rule(void **state)
{
    (void)state;
    lr_coeffs pa, po, wax;
    /* candle_wax: marble (Jensen 2001) at half its coefficients, eta 1.44 */
    lr_medium wm = {.sigma_a = {0.00105, 0.00205, 0.00355},
                    .sigma_s_prime = {1.095, 1.31, 1.5}, .eta = 1.44};
    lr_err e = {0};
    assert_int_equal(lr_coeffs_derive(&paper, &pa, &e), LR_OK);
    assert_int_equal(lr_coeffs_derive(&porcelain, &po, &e), LR_OK);
    assert_int_equal(lr_coeffs_derive(&wm, &wax, &e), LR_OK);
    assert_true(lr_tr_wall_thin(&pa, 0.1, 12));
    assert_true(lr_tr_wall_thin(&po, 1.5, 12));
    assert_true(lr_tr_wall_thin(&po, 3, 12));
    assert_true(lr_tr_wall_thin(&wax, 7, 12));
    assert_false(lr_tr_wall_thin(&wax, 40, 12));
    assert_false(lr_tr_wall_thin(&pa, 0, 12));
    assert_false(lr_tr_wall_thin(&pa, 0.1, 0));
    assert_false(lr_tr_wall_thin(NULL, 0.1, 12));
    /* The boundary: d = patch_mm. Wax's r90 (diffusion lengths 8-17 mm) is far over a
     * quarter of the patch, which an earlier rule asked for. */
    lr_tr_spread sp;
    lr_tr_spread_build(&wax, 12, &sp);
    assert_true(lr_tr_spread_r90(&sp) > 3);
    assert_true(lr_tr_wall_thin(&wax, 12, 12));
    assert_false(lr_tr_wall_thin(&wax, 12 * (1 + 1e-3), 12));
    assert_true(lr_tr_wall_thin(&pa, 0.1, 0.1));
    assert_false(lr_tr_wall_thin(&pa, 0.1, 0.1 * (1 - 1e-3)));
    /* The tabulated CDFs reach their closed-form totals' profiles: r90 of the T profile of
     * the paper sheet lies between its thickness and the slab with both extrapolated
     * boundaries, and the CDF inverse is monotone. */
    lr_tr_spread_build(&pa, 0.1, &sp);
    double prev = 0;
    for (int k = 1; k <= 100; k++) {
        double r = lr_tr_spread_radius(&sp, 1, 0, k / 100.0);
        assert_true(r >= prev);
        prev = r;
    }
    double r90T = lr_tr_spread_radius(&sp, 1, 0, 0.9);
    assert_true(r90T > 0.1 * 0.5 && r90T < 2 * sp.L);
}

static void test_bad_settings(void **state)
{
    (void)state;
    lr_err e = {0};
    lr_mesh *m;
    lr_bvh *bv;
    lr_coeffs co;
    lr_box_desc bd = {.size = lr_v3(10, 10, 0.1)};
    assert_int_equal(lr_mesh_box(&bd, &m, &e), LR_OK);
    assert_int_equal(lr_bvh_create(m, &bv, &e), LR_OK);
    assert_int_equal(lr_coeffs_derive(&paper, &co, &e), LR_OK);
    lr_tr_surface_desc sd = {.kind = LR_TR_TRANSLUCENT, .mesh = m, .bvh = bv, .coeffs = &co,
                             .model = LR_SSS_TRANSLUCENT_RADIOSITY, .thickness_mm = 0.1};
    lr_tr *t = NULL;
    for (int bad = -1; bad <= 3; bad += 4) {
        lr_tr_settings set = {.thin_wall = bad};
        assert_int_equal(lr_tr_create(&sd, 1, &set, &t, &e), LR_EINVAL);
        assert_non_null(strstr(e.msg, "thin_wall"));
        assert_null(t);
    }
    double lit[3] = {1, 1, 1}, opp[3] = {1, 1, 1};
    lr_tr_subsurface_split(NULL, 0, lit, opp);
    assert_true(lit[0] == 0 && opp[2] == 0);
    lr_bvh_destroy(bv);
    lr_mesh_destroy(m);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_paper_slab_split),
        cmocka_unit_test(test_fresnel_slab_split),
        cmocka_unit_test(test_wall_end_faces),
        cmocka_unit_test(test_lateral_spread),
        cmocka_unit_test(test_energy_no_absorption),
        cmocka_unit_test(test_rule),
        cmocka_unit_test(test_bad_settings),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
