/* Light-propagation volumes on the CPU (render/lpv/, seed 004 Sec. 4.3-4.4 after Kaplanyan &
 * Dachsbacher 2010): the clamped-cosine SH lobe and the cosine convolution against
 * quadrature, the 30 face transfers of Eq. 12-14 against Monte Carlo, no energy gain step by
 * step over random injections with and without blockers, an opaque wall, the 1/r^2 falloff of
 * a point source, homogeneity in the light, and refused parameters. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/rng.h"
#include "render/lpv/lpv.h"
#include "render/lpv/sh4.h"
#include "render/lpv/stencil.h"
#include "tests/support/near.h"

static lr_vec3 random_dir(lr_rng *r)
{
    double z = 2.0 * lr_rng_next(r) - 1.0, ph = 2.0 * M_PI * lr_rng_next(r);
    double s = sqrt(fmax(0.0, 1.0 - z * z));
    return lr_v3(s * cos(ph), s * sin(ph), z);
}

/* integral over the sphere of f(w) y_i(w), by a 400 x 800 midpoint rule in (cos theta, phi). */
static void project(double (*f)(lr_vec3, const void *), const void *ctx, double c[4])
{
    const int nt = 400, np = 800;
    memset(c, 0, 4 * sizeof *c);
    for (int a = 0; a < nt; a++) {
        double z = -1.0 + (a + 0.5) * 2.0 / nt, s = sqrt(1.0 - z * z);
        for (int b = 0; b < np; b++) {
            double ph = (b + 0.5) * 2.0 * M_PI / np;
            lr_vec3 w = lr_v3(s * cos(ph), s * sin(ph), z);
            double y[4], fw = f(w, ctx) * (2.0 / nt) * (2.0 * M_PI / np);
            lr_sh4_basis(w, y);
            for (int i = 0; i < 4; i++)
                c[i] += fw * y[i];
        }
    }
}

static double clamped_cos(lr_vec3 w, const void *ctx)
{
    return fmax(0.0, lr_v3_dot(w, *(const lr_vec3 *)ctx));
}

static void test_cosine_lobe_exact(void **st)
{
    (void)st;
    lr_rng r = lr_rng_init(1);
    for (int t = 0; t < 6; t++) {
        lr_vec3 n = random_dir(&r);
        double c[4], q[4];
        lr_sh4_cosine_lobe(n, c);
        /* The closed form: sqrt(pi)/2 and sqrt(pi/3) n. */
        assert_near(c[0], sqrt(M_PI) / 2.0, 1e-15);
        assert_near(c[3], sqrt(M_PI / 3.0) * n.z, 1e-15);
        project(clamped_cos, &n, q);
        for (int i = 0; i < 4; i++)
            assert_near(c[i], q[i], 1e-4); /* the midpoint rule across the kink */
        /* Eq. 4 / 10: the lobe (Phi / pi) max(0, n.w) carries Phi. */
        double l[4];
        for (int i = 0; i < 4; i++)
            l[i] = c[i] * 7.0 / M_PI;
        assert_near_rel(lr_sh4_flux(l), 7.0, 1e-15);
        /* Cosine convolution of the projected lobe along d against quadrature of the
         * two-band function itself. */
        lr_vec3 d = random_dir(&r);
        double exact = 0.0;
        const int nt = 400, np = 800;
        for (int a = 0; a < nt; a++) {
            double z = -1.0 + (a + 0.5) * 2.0 / nt, s = sqrt(1.0 - z * z);
            for (int b = 0; b < np; b++) {
                double ph = (b + 0.5) * 2.0 * M_PI / np;
                lr_vec3 w = lr_v3(s * cos(ph), s * sin(ph), z);
                exact += lr_sh4_eval(c, w) * fmax(0.0, lr_v3_dot(d, w)) * (2.0 / nt) *
                         (2.0 * M_PI / np);
            }
        }
        assert_near(lr_sh4_cosine_integral(c, d), exact, 1e-4);
    }
}

/* Which of the 30 faces (main m, face f) a ray from the source cell's centre along w leaves
 * through: the neighbour is across the source's face of largest |w_a|; inside it (cell units,
 * spanning [0.5, 1.5] along main), the exit is the nearest of its five far faces. */
static void exit_face(const lr_lpv_stencil *st, lr_vec3 w, int *m, int *f)
{
    double ww[3] = {w.x, w.y, w.z};
    int a = 0;
    for (int b = 1; b < 3; b++)
        if (fabs(ww[b]) > fabs(ww[a]))
            a = b;
    *m = 2 * a + (ww[a] < 0);
    int sgn = st->dir[*m][a];
    double tbest = 1.5 / fabs(ww[a]);
    *f = 0;
    for (int k = 1; k < 5; k++) {
        int ax = -1, s = 0;
        for (int b = 0; b < 3; b++)
            if (st->face_n[*m][k][b]) {
                ax = b;
                s = st->face_n[*m][k][b];
            }
        if (ww[ax] * s <= 0.0)
            continue;
        double t = 0.5 / fabs(ww[ax]);
        if (t < tbest) {
            tbest = t;
            *f = k;
        }
    }
    (void)sgn;
}

static void test_face_transfers(void **st_)
{
    (void)st_;
    lr_lpv_stencil st;
    lr_lpv_stencil_make(&st);
    /* The 30 faces tile the sphere: sum v_f = integral y_i over 4 pi = (sqrt(4 pi), 0, 0, 0). */
    double sum[4] = {0};
    for (int m = 0; m < 6; m++)
        for (int f = 0; f < 5; f++)
            for (int i = 0; i < 4; i++)
                sum[i] += st.v[m][f][i];
    assert_near_rel(sum[0], sqrt(4.0 * M_PI), 1e-12);
    for (int i = 1; i < 4; i++)
        assert_near(sum[i], 0.0, 1e-12);
    /* Monte Carlo over directions: v_f = 4 pi E[y(w) 1(w exits through f)]. */
    enum { N = 400000 };
    static double acc[6][5][4];
    memset(acc, 0, sizeof acc);
    lr_rng r = lr_rng_init(7);
    for (int s = 0; s < N; s++) {
        lr_vec3 w = random_dir(&r);
        int m, f;
        exit_face(&st, w, &m, &f);
        double y[4];
        lr_sh4_basis(w, y);
        for (int i = 0; i < 4; i++)
            acc[m][f][i] += y[i] * 4.0 * M_PI / N;
    }
    /* Standard error of each entry: at most 4 pi k0 sqrt(p / N), p <= 0.034 the face's share:
     * 2.1e-3 * 4 sigma. */
    for (int m = 0; m < 6; m++)
        for (int f = 0; f < 5; f++)
            for (int i = 0; i < 4; i++)
                assert_near(st.v[m][f][i], acc[m][f][i], 4.0 * 4.0 * M_PI * 0.4886 *
                                                            sqrt(0.034 / N));
}

static lr_lpv *make(int n, double h)
{
    lr_lpv_desc d = {.origin = lr_v3(-n * h / 2, -n * h / 2, -n * h / 2), .cell = h, .n = n};
    lr_lpv *v = NULL;
    lr_err e = {0};
    assert_int_equal(lr_lpv_create(&d, &v, &e), LR_OK);
    return v;
}

static void random_injections(lr_lpv *v, lr_rng *r, int count, double half)
{
    lr_err e = {0};
    for (int q = 0; q < count; q++) {
        lr_vec3 p = lr_v3((2 * lr_rng_next(r) - 1) * half, (2 * lr_rng_next(r) - 1) * half,
                          (2 * lr_rng_next(r) - 1) * half);
        double phi[3] = {lr_rng_next(r), lr_rng_next(r), lr_rng_next(r)};
        if (q % 5 == 4)
            assert_int_equal(lr_lpv_inject_point(v, p, phi, &e), LR_OK);
        else
            assert_int_equal(lr_lpv_inject_lobe(v, p, random_dir(r), phi, &e), LR_OK);
    }
}

/* Per step: the flux in flight never above the previous step's, nor is the flux in flight
 * plus the absorbed record (what blocking took is recorded, not gained); for the first
 * `conserve_until` steps (before the light can reach the border) the latter is unchanged. */
static void check_steps(lr_lpv *v, int steps, int conserve_until)
{
    lr_err e = {0};
    double prev[3], prev_all[3];
    for (int ch = 0; ch < 3; ch++) {
        prev[ch] = lr_lpv_total_flux(v, ch);
        prev_all[ch] = prev[ch] + lr_lpv_absorbed_flux(v, ch);
    }
    for (int s = 1; s <= steps; s++) {
        assert_int_equal(lr_lpv_propagate(v, 1, &e), LR_OK);
        for (int ch = 0; ch < 3; ch++) {
            double t = lr_lpv_total_flux(v, ch), all = t + lr_lpv_absorbed_flux(v, ch);
            if (!(t <= prev[ch] * (1.0 + 1e-12)))
                fail_msg("step %d channel %d: flux %.17g after %.17g", s, ch, t, prev[ch]);
            if (!(all <= prev_all[ch] * (1.0 + 1e-12)))
                fail_msg("step %d channel %d: flux + absorbed %.17g after %.17g", s, ch, all,
                         prev_all[ch]);
            if (s <= conserve_until)
                assert_near_rel(all, prev_all[ch], 1e-12);
            prev[ch] = t;
            prev_all[ch] = all;
        }
    }
}

/* Steps checked after each injection: 24, one and a half crossings of the 16-cell box (light
 * moves a cell a step), so every injection's light has met the border, and the blockers on
 * its way, before the check ends; 40 steps checked the same steps longer (the diffuse tail
 * still in flight) at 1.7 times the time. */
enum { STEPS = 24 };

static void test_no_energy_gain_empty(void **st)
{
    (void)st;
    lr_rng r = lr_rng_init(11);
    for (int trial = 0; trial < 20; trial++) {
        lr_lpv *v = make(16, 2.0);
        /* A single lobe or point in the middle: conserved exactly for the 6 steps before it
         * can reach the border (cells 5..10 of 16, 1 off the surface), then non-increasing. */
        random_injections(v, &r, trial < 10 ? 1 : 40, trial < 10 ? 4.0 : 14.0);
        check_steps(v, STEPS, trial < 10 ? 4 : 0);
        lr_lpv_destroy(v);
    }
}

static void test_no_energy_gain_blockers(void **st)
{
    (void)st;
    lr_rng r = lr_rng_init(12);
    lr_err e = {0};
    for (int trial = 0; trial < 20; trial++) {
        lr_lpv *v = make(16, 2.0);
        for (int b = 0; b < 300; b++) {
            lr_vec3 p = lr_v3((2 * lr_rng_next(&r) - 1) * 16, (2 * lr_rng_next(&r) - 1) * 16,
                              (2 * lr_rng_next(&r) - 1) * 16);
            assert_int_equal(lr_lpv_add_blocker(v, p, random_dir(&r), 8.0 * lr_rng_next(&r), &e),
                             LR_OK);
        }
        random_injections(v, &r, 30, 14.0);
        check_steps(v, STEPS, 0);
        lr_lpv_destroy(v);
    }
}

/* A plane of blocker samples x = x0 over the whole box, covering `cover` of it. */
static void wall(lr_lpv *v, double x0, double cover)
{
    lr_err e = {0};
    int n = lr_lpv_n(v), sub = 4;
    double h = lr_lpv_h(v), half = n * h / 2, a = h / sub;
    for (int j = 0; j < n * sub; j++)
        for (int k = 0; k < n * sub; k++)
            assert_int_equal(lr_lpv_add_blocker(v, lr_v3(x0, -half + (j + 0.5) * a,
                                                         -half + (k + 0.5) * a),
                                                lr_v3(1, 0, 0), a * a * cover, &e),
                             LR_OK);
}

/* A point source at x = -7, a blocker wall at x = 4 (none, half covered, opaque) and a
 * receiver plane at x = 14: the receiver's irradiance behind an opaque wall is exactly 0,
 * behind the half wall between 0.3 and 0.6 of the open case (light crosses the wall's plane
 * more than once by diffusion, so not exactly 1/2), and the wall's own front side receives. */
static void test_opaque_wall(void **st)
{
    (void)st;
    lr_err e = {0};
    double phi[3] = {1, 1, 1};
    lr_lpv *vs[3] = {make(24, 2.0), make(24, 2.0), make(24, 2.0)};
    double cover[3] = {0.0, 0.5, 1.0};
    for (int i = 0; i < 3; i++) {
        if (cover[i] > 0.0)
            wall(vs[i], 4.0, cover[i]);
        wall(vs[i], 14.0, 1.0);
        assert_int_equal(lr_lpv_inject_point(vs[i], lr_v3(-7, 1, 1), phi, &e), LR_OK);
        assert_int_equal(lr_lpv_propagate(vs[i], 96, &e), LR_OK);
    }
    for (int y = -12; y <= 12; y += 6) {
        lr_vec3 p = lr_v3(14, y, 1), nrm = lr_v3(-1, 0, 0);
        double E[3][3];
        for (int i = 0; i < 3; i++)
            lr_lpv_irradiance(vs[i], p, nrm, E[i]);
        assert_true(E[0][0] > 0.0);
        assert_near(E[2][0], 0.0, 0.0);
        double q = E[1][0] / E[0][0];
        if (!(q > 0.3 && q < 0.6))
            fail_msg("half wall: receiver at y %d gets %.3f of the open case", y, q);
        double Ef[3];
        lr_lpv_irradiance(vs[2], lr_v3(4, y, 1), nrm, Ef);
        assert_true(Ef[0] > 0.0);
    }
    for (int i = 0; i < 3; i++)
        lr_lpv_destroy(vs[i]);
}

/* A point source of flux 1 and an opaque plane r cells away: the irradiance at the plane's
 * foot point, times 4 pi r^2, for r = 2..8 in a 32^3 volume after 4 n steps. Vacuum gives 1;
 * the LPV's diffusive propagation spreads light sideways, and what is still in flight after
 * 128 steps (27-66 %) never arrives, so the level is 1.18-1.31 and falls beyond r = n/4
 * (0.91 at 10, 0.68 at 12: the border takes what diffuses out). Asserted: E r^2 constant
 * within +-15 % of 1.2 / (4 pi) for r = 2..8. */
static void test_point_falloff(void **st)
{
    (void)st;
    lr_err e = {0};
    const int n = 32;
    for (int r = 2; r <= 8; r += 2) {
        lr_lpv *v = make(n, 1.0);
        double x0 = 0.5 + r;
        wall(v, x0, 1.0);
        double phi[3] = {1, 1, 1};
        assert_int_equal(lr_lpv_inject_point(v, lr_v3(0.5, 0.5, 0.5), phi, &e), LR_OK);
        assert_int_equal(lr_lpv_propagate(v, 4 * n, &e), LR_OK);
        double E[3];
        lr_lpv_irradiance(v, lr_v3(x0, 0.5, 0.5), lr_v3(-1, 0, 0), E);
        double k = E[0] * 4.0 * M_PI * r * r;
        printf("r %d: E 4 pi r^2 = %.3f\n", r, k);
        assert_near(k, 1.2, 0.18);
        lr_lpv_destroy(v);
    }
}

static void test_homogeneous(void **st)
{
    (void)st;
    lr_err e = {0};
    lr_rng r1 = lr_rng_init(5), r2 = lr_rng_init(5);
    lr_lpv *a = make(12, 3.0), *b = make(12, 3.0);
    for (int q = 0; q < 20; q++) {
        lr_vec3 p = lr_v3(lr_rng_next(&r1) * 20 - 10, lr_rng_next(&r1) * 20 - 10,
                          lr_rng_next(&r1) * 20 - 10);
        lr_vec3 nn = random_dir(&r1);
        double phi[3] = {lr_rng_next(&r1), 0.5, 0.25}, phi2[3];
        for (int c = 0; c < 3; c++)
            phi2[c] = 3.0 * phi[c];
        assert_int_equal(lr_lpv_inject_lobe(a, p, nn, phi, &e), LR_OK);
        assert_int_equal(lr_lpv_inject_lobe(b, p, nn, phi2, &e), LR_OK);
    }
    (void)r2;
    wall(a, 5.0, 0.7);
    wall(b, 5.0, 0.7);
    assert_int_equal(lr_lpv_propagate(a, 10, &e), LR_OK);
    assert_int_equal(lr_lpv_propagate(b, 10, &e), LR_OK);
    const double *ga = lr_lpv_grid(a), *gb = lr_lpv_grid(b);
    for (size_t i = 0; i < 12u * 12 * 12 * 12; i++)
        assert_near(gb[i], 3.0 * ga[i], 1e-10 * fabs(ga[i]));
    const double *aa = lr_lpv_absorbed(a), *ab = lr_lpv_absorbed(b);
    for (size_t i = 0; i < 13u * 13 * 13 * 18; i++)
        assert_near(ab[i], 3.0 * aa[i], 1e-10 * fabs(aa[i]));
    assert_true(lr_lpv_absorbed_flux(a, 0) > 0.0);
    lr_lpv_destroy(a);
    lr_lpv_destroy(b);
}

static void test_bad_parameters(void **st)
{
    (void)st;
    lr_err e = {0};
    lr_lpv *v = NULL;
    lr_lpv_desc d = {.origin = lr_v3(0, 0, 0), .cell = 1.0, .n = 1};
    assert_int_equal(lr_lpv_create(&d, &v, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "n = 1"));
    assert_null(v);
    d.n = 129;
    assert_int_equal(lr_lpv_create(&d, &v, &e), LR_EINVAL);
    d.n = 8;
    d.cell = 0.0;
    assert_int_equal(lr_lpv_create(&d, &v, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "cell"));
    d.cell = NAN;
    assert_int_equal(lr_lpv_create(&d, &v, &e), LR_EINVAL);
    d.cell = 1.0;
    d.origin.y = INFINITY;
    assert_int_equal(lr_lpv_create(&d, &v, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "origin"));
    assert_int_equal(lr_lpv_desc_around(lr_v3(0, 0, 0), lr_v3(-1, 1, 1), 0, 8, &d, &e), LR_EINVAL);
    assert_int_equal(lr_lpv_desc_around(lr_v3(0, 0, 0), lr_v3(0, 0, 0), 0, 8, &d, &e), LR_EINVAL);
    assert_int_equal(lr_lpv_desc_around(lr_v3(0, 0, 0), lr_v3(10, 4, 2), 1, 8, &d, &e), LR_OK);
    assert_near(d.cell, 12.0 / 8, 1e-15);
    v = make(8, 1.0);
    double phi[3] = {1, 1, 1}, neg[3] = {1, -1, 1};
    assert_int_equal(lr_lpv_inject_lobe(v, lr_v3(0, 0, 0), lr_v3(0, 0, 2), phi, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "length 2"));
    assert_int_equal(lr_lpv_inject_lobe(v, lr_v3(0, 0, 0), lr_v3(0, 0, 1), neg, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "flux[1]"));
    assert_int_equal(lr_lpv_inject_point(v, lr_v3(NAN, 0, 0), phi, &e), LR_EINVAL);
    assert_int_equal(lr_lpv_add_blocker(v, lr_v3(0, 0, 0), lr_v3(0, 0, 1), -1.0, &e), LR_EINVAL);
    assert_int_equal(lr_lpv_propagate(v, -1, &e), LR_EINVAL);
    assert_int_equal(lr_lpv_propagate(v, 33, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "steps = 33"));
    /* Outside the box: dropped and counted, not an error. */
    assert_int_equal(lr_lpv_inject_point(v, lr_v3(100, 0, 0), phi, &e), LR_OK);
    assert_near(lr_lpv_dropped(v, 2), 1.0, 0.0);
    assert_near(lr_lpv_total_flux(v, 2), 0.0, 0.0);
    lr_lpv_destroy(v);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cosine_lobe_exact),
        cmocka_unit_test(test_face_transfers),
        cmocka_unit_test(test_no_energy_gain_empty),
        cmocka_unit_test(test_no_energy_gain_blockers),
        cmocka_unit_test(test_opaque_wall),
        cmocka_unit_test(test_point_falloff),
        cmocka_unit_test(test_homogeneous),
        cmocka_unit_test(test_bad_parameters),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
