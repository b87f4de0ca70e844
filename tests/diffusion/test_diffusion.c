/* The grid diffusion solver of seed 001 (render/diffusion/) against closed forms.
 *
 *  1. 1-D slab (thickness 10.3 mm, boundaries between nodes), lit on one face: the exitance
 *     on the lit face R and on the far face T against the closed form of D phi'' = mu phi with
 *     the Robin conditions phi -+ 2 A D phi' = 4 q / (1 - F_dr); within 1 % at h = 0.25 mm and
 *     second order: each halving of h divides the error by more than 2^1.7.
 *  2. Sphere (R = 10 mm) lit by q = 1 + cos(theta)/2: phi = c0 i0(r/delta) + c1 i1(r/delta)
 *     cos(theta) (modified spherical Bessel functions); B on 400 surface points through the
 *     renderer's field (lr_dfield_eval) within 1 % RMS at h = 0.5 mm, order > 1.7.
 *  3. Energy: integral of (q - B) over the surface equals mu times the integral of phi over the
 *     volume, both from the discrete solution, within 1.5 % at h = 0.5 mm (the ghost-fluid form
 *     is not conservative, so the balance holds to its discretisation error), and the gap
 *     at least halves from h = 1 mm.
 *  4. Warm start: re-solving for a slightly moved light from the last solution takes fewer
 *     iterations than the cold coarse-to-fine solve, and the same light again none.
 *  5. Volume files: a layered file parses and samples; malformed ones fail with FILE:LINE.
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

#include "render/diffusion/dgrid.h"

static const double SA = 0.01, SS = 1.0, ETA = 1.3;

static lr_dmaterial wax(void)
{
    lr_dmaterial m = {{SA, SA, SA}, {SS, SS, SS}, ETA, NULL};
    /* bands differ so that band mix-ups show */
    m.sigma_a[1] = 0.02;
    m.sigma_a[2] = 0.04;
    return m;
}

/* ---- slab ---- */

typedef struct slab_light {
    double L;
} slab_light;

static double slab_q(const void *ctx, lr_vec3 b, lr_vec3 n)
{
    const slab_light *s = ctx;
    return b.z < 0.5 * s->L ? 1.0 : 0.0;
}

static void slab_exact(double D, double mu, double A, double Fdr, double L, double *R, double *T)
{
    double delta = sqrt(D / mu), K = 2.0 * A * D / delta, lam = L / delta;
    double S0 = 4.0 / (1.0 - Fdr);
    double c1 = cosh(lam) + K * sinh(lam), c2 = sinh(lam) + K * cosh(lam);
    double b = -S0 * c1 / (K * c1 + c2), a = S0 + K * b;
    *R = (a - 2.0) / (2.0 * A);
    *T = (a * cosh(lam) + b * sinh(lam)) / (2.0 * A);
}

static void field_of(lr_dsolver *s, lr_dirradiance_fn q, const void *ctx, float **field)
{
    const lr_dgrid *g = lr_dsolver_grid(s);
    *field = malloc(4 * lr_dgrid_node_count(g) * sizeof(float));
    assert_non_null(*field);
    lr_err e = {0};
    assert_int_equal(lr_dsolver_field(s, 0, q, ctx, *field, &e), LR_OK);
}

static void test_slab(void **state)
{
    (void)state;
    const double L = 10.3;
    lr_dslab slab = {L};
    lr_dshape shape = lr_dshape_slab(&slab);
    slab_light light = {L};
    lr_dmaterial m = wax();
    double err[3][2] = {{0}};
    const double hs[3] = {1.0, 0.5, 0.25};
    for (int k = 0; k < 3; k++) {
        lr_dsolver *s;
        lr_err e = {0};
        assert_int_equal(lr_dsolver_create(&shape, hs[k], 2, &m, &s, &e), LR_OK);
        assert_int_equal(lr_dsolver_solve(s, 0, slab_q, &light, 1e-11, &e), LR_OK);
        float *f;
        field_of(s, slab_q, &light, &f);
        const lr_dgrid *g = lr_dsolver_grid(s);
        int n[3];
        lr_dgrid_dims(g, n);
        const lr_dsystem *sys = lr_dsolver_system(s, 0);
        for (int c = 0; c < 3; c += 2) {
            double D = 1.0 / (3.0 * (m.sigma_a[c] + SS)), R, T;
            slab_exact(D, m.sigma_a[c], lr_dsystem_A(sys), lr_dsystem_Fdr(sys), L, &R, &T);
            double Bl[3], Bf[3];
            lr_dfield_eval(f, n, lr_dgrid_origin(g), hs[k], lr_v3(0, 0, 0), Bl);
            lr_dfield_eval(f, n, lr_dgrid_origin(g), hs[k], lr_v3(0, 0, L), Bf);
            double er = fmax(fabs(Bl[c] / R - 1.0), fabs(Bf[c] / T - 1.0));
            err[k][c / 2] = er;
            printf("slab h %.3f band %d: R %.6f (exact %.6f) T %.6f (exact %.6f) rel err %.2e\n",
                   hs[k], c, Bl[c], R, Bf[c], T, er);
        }
        free(f);
        lr_dsolver_destroy(s);
    }
    for (int c = 0; c < 2; c++) {
        assert_true(err[2][c] < 0.01);
        for (int k = 0; k < 2; k++) {
            double order = log2(err[k][c] / err[k + 1][c]);
            printf("slab order %d->%d band %d: %.2f\n", k, k + 1, 2 * c, order);
            assert_true(order > 1.7);
        }
    }
}

/* ---- sphere ---- */

static const double RS = 10.0;

static double sphere_q(const void *ctx, lr_vec3 b, lr_vec3 n)
{
    (void)ctx;
    return 1.0 + 0.5 * (b.z / RS);
}

static double i0(double x) { return sinh(x) / x; }
static double i1(double x) { return cosh(x) / x - sinh(x) / (x * x); }

typedef struct sphere_exact {
    double c0, c1, delta, A;
} sphere_exact;

static sphere_exact sphere_solution(double D, double mu, double A, double Fdr)
{
    sphere_exact s;
    s.delta = sqrt(D / mu);
    s.A = A;
    double x = RS / s.delta, K = 2.0 * A * D / s.delta, S = 4.0 / (1.0 - Fdr);
    double d0 = i1(x), d1 = i0(x) - 2.0 * i1(x) / x;
    s.c0 = S / (i0(x) + K * d0);
    s.c1 = 0.5 * S / (i1(x) + K * d1);
    return s;
}

static lr_vec3 fib(int k, int n)
{
    double z = 1.0 - (2.0 * k + 1.0) / n, r = sqrt(1.0 - z * z), a = k * 2.399963229728653;
    return lr_v3(r * cos(a), r * sin(a), z);
}

static void test_sphere(void **state)
{
    (void)state;
    lr_dsphere sph = {lr_v3(0.3, -0.2, 0.0), RS};
    lr_dshape shape = lr_dshape_sphere(&sph);
    lr_dmaterial m = wax();
    const double hs[3] = {2.0, 1.0, 0.5};
    double err[3], energy[3] = {0};
    const int band = 2;
    const int NP = 400;
    for (int k = 0; k < 3; k++) {
        lr_dsolver *s;
        lr_err e = {0};
        assert_int_equal(lr_dsolver_create(&shape, hs[k], 3, &m, &s, &e), LR_OK);
        /* q depends on b.z relative to the centre's z = 0.1: shift the light's frame. */
        assert_int_equal(lr_dsolver_solve(s, 0, sphere_q, NULL, 1e-10, &e), LR_OK);
        float *f;
        field_of(s, sphere_q, NULL, &f);
        const lr_dgrid *g = lr_dsolver_grid(s);
        int n[3];
        lr_dgrid_dims(g, n);
        const lr_dsystem *sys = lr_dsolver_system(s, band);
        double D = 1.0 / (3.0 * (m.sigma_a[band] + SS));
        sphere_exact ex = sphere_solution(D, m.sigma_a[band], lr_dsystem_A(sys), lr_dsystem_Fdr(sys));
        double se = 0.0, sb = 0.0, emax = 0.0;
        double qin = 0.0, bout = 0.0;
        for (int p = 0; p < NP; p++) {
            lr_vec3 u = fib(p, NP);
            lr_vec3 x = lr_v3_add(sph.c, lr_v3_scale(u, RS));
            double q = sphere_q(NULL, x, u);
            /* sphere_q reads b.z / R, so the exact solution's cos(theta) is x.z / R too */
            double cos_t = x.z / RS;
            double phi_r = ex.c0 * i0(RS / ex.delta) + (q - 1.0) * 2.0 * ex.c1 * i1(RS / ex.delta);
            (void)cos_t;
            double Bex = (phi_r - 2.0 * q) / (2.0 * ex.A);
            double B[3];
            lr_dfield_eval(f, n, lr_dgrid_origin(g), hs[k], x, B);
            se += (B[band] - Bex) * (B[band] - Bex);
            sb += Bex;
            emax = fmax(emax, fabs(B[band] / Bex - 1.0));
            qin += q;
            bout += B[band];
        }
        err[k] = sqrt(se / NP) / (sb / NP);
        printf("sphere h %.2f: B rms rel err %.2e, max %.2e, %zu unknowns, %d iterations\n",
               hs[k], err[k], emax, lr_dgrid_unknown_count(g), lr_dsolver_last_iters(s));
        if (k >= 1) {
            /* 3. energy: int (q - B) dA against mu int phi dV (Gauss-Legendre in r and
             * cos theta, uniform in azimuth, over the trilinear discrete phi). */
            double area = 4.0 * M_PI * RS * RS;
            double absorbed_surface = (qin - bout) / NP * area;
            static const double gx[8] = {-0.9602898564975363, -0.7966664774136267,
                                         -0.5255324099163290, -0.1834346424956498,
                                         0.1834346424956498,  0.5255324099163290,
                                         0.7966664774136267,  0.9602898564975363};
            static const double gw[8] = {0.1012285362903763, 0.2223810344533745,
                                         0.3137066458778873, 0.3626837833783620,
                                         0.3626837833783620, 0.3137066458778873,
                                         0.2223810344533745, 0.1012285362903763};
            const double *phi = lr_dsolver_phi(s, 0, band);
            double vol = 0.0;
            for (int a = 0; a < 8; a++)
                for (int b = 0; b < 8; b++)
                    for (int c = 0; c < 16; c++) {
                        double r = 0.5 * RS * (gx[a] + 1.0), ct = gx[b], st = sqrt(1 - ct * ct);
                        double az = 2.0 * M_PI * (c + 0.5) / 16.0;
                        lr_vec3 x = lr_v3_add(sph.c, lr_v3(r * st * cos(az), r * st * sin(az), r * ct));
                        vol += gw[a] * gw[b] * (0.5 * RS) * r * r * (2.0 * M_PI / 16.0) *
                               lr_dgrid_sample(g, phi, x);
                    }
            double absorbed_volume = m.sigma_a[band] * vol;
            energy[k] = fabs(absorbed_surface / absorbed_volume - 1.0);
            printf("energy h %.2f: surface %.6f volume %.6f (ratio %.5f)\n", hs[k],
                   absorbed_surface, absorbed_volume, absorbed_surface / absorbed_volume);
        }
        free(f);
        lr_dsolver_destroy(s);
    }
    assert_true(err[2] < 0.01);
    /* The balance holds to the discretisation error, and that error falls with h: absorbed
     * power is about 40 % of q here, so B's 0.5 % error at h = 0.5 mm moves it by ~1 %. */
    assert_true(energy[2] < 0.015);
    assert_true(energy[2] < 0.5 * energy[1]);
    for (int k = 0; k < 2; k++) {
        double order = log2(err[k] / err[k + 1]);
        printf("sphere order %d->%d: %.2f\n", k, k + 1, order);
        assert_true(order > 1.7);
    }
}

/* ---- warm start ---- */

typedef struct point_light {
    lr_vec3 p;
} point_light;

static double point_q(const void *ctx, lr_vec3 b, lr_vec3 n)
{
    const point_light *l = ctx;
    lr_vec3 d = lr_v3_sub(l->p, b);
    double r2 = lr_v3_dot(d, d), c = lr_v3_dot(d, n) / sqrt(r2);
    return c > 0.0 ? c / r2 : 0.0;
}

static void test_warm_start(void **state)
{
    (void)state;
    lr_dsphere sph = {lr_v3(0, 0, 0), 8.0};
    lr_dshape shape = lr_dshape_sphere(&sph);
    lr_dmaterial m = wax();
    lr_dsolver *s;
    lr_err e = {0};
    assert_int_equal(lr_dsolver_create(&shape, 1.0, 3, &m, &s, &e), LR_OK);
    point_light l = {lr_v3(0, 0, 30)};
    assert_int_equal(lr_dsolver_solve(s, 0, point_q, &l, 1e-6, &e), LR_OK);
    int cold = lr_dsolver_last_iters(s);
    assert_int_equal(lr_dsolver_solve(s, 0, point_q, &l, 1e-6, &e), LR_OK);
    assert_int_equal(lr_dsolver_last_iters(s), 0);
    l.p = lr_v3(1.0, 0, 30);
    assert_int_equal(lr_dsolver_solve(s, 0, point_q, &l, 1e-6, &e), LR_OK);
    int warm = lr_dsolver_last_iters(s);
    printf("iterations: cold %d, warm after a 1 mm move %d\n", cold, warm);
    assert_true(warm < cold);
    lr_dsolver_destroy(s);
}

/* ---- a cloned system (the solver assembles each level once, copies it per band) ---- */

static void params(size_t n_in, double scale, double *D, double *mu)
{
    for (size_t p = 0; p < n_in; p++) {
        D[p] = scale * (0.3 + 0.01 * (double)(p % 7));
        mu[p] = scale * (0.002 + 0.001 * (double)(p % 5));
    }
}

static void test_clone_is_independent(void **state)
{
    (void)state;
    lr_dsphere sph = {lr_v3(0.2, 0.1, -0.3), 6.0};
    lr_dshape shape = lr_dshape_sphere(&sph);
    lr_dgrid *g;
    lr_dsystem *a, *b, *fresh_a, *fresh_b;
    lr_err e = {0};
    assert_int_equal(lr_dgrid_create(&shape, 1.0, &g, &e), LR_OK);
    size_t n_in = lr_dgrid_inside_count(g), n = lr_dgrid_unknown_count(g);
    double *D = malloc(n_in * sizeof *D), *mu = malloc(n_in * sizeof *mu);
    double *x = malloc(n * sizeof *x), *ya = malloc(n * sizeof *ya), *yb = malloc(n * sizeof *yb);
    assert_non_null(D);
    assert_non_null(mu);
    assert_non_null(x);
    assert_non_null(ya);
    assert_non_null(yb);
    for (size_t u = 0; u < n; u++)
        x[u] = sin(0.37 * (double)u) + 1.5;
    assert_int_equal(lr_dsystem_create(g, 1.4, &a, &e), LR_OK);
    params(n_in, 1.0, D, mu);
    assert_int_equal(lr_dsystem_set_params(a, D, mu, &e), LR_OK);
    assert_int_equal(lr_dsystem_clone(a, &b, &e), LR_OK);
    params(n_in, 2.5, D, mu);
    assert_int_equal(lr_dsystem_set_params(b, D, mu, &e), LR_OK);
    /* Each against a system assembled afresh with its own parameters: equal to the bit. */
    assert_int_equal(lr_dsystem_create(g, 1.4, &fresh_b, &e), LR_OK);
    assert_int_equal(lr_dsystem_set_params(fresh_b, D, mu, &e), LR_OK);
    assert_int_equal(lr_dsystem_create(g, 1.4, &fresh_a, &e), LR_OK);
    params(n_in, 1.0, D, mu);
    assert_int_equal(lr_dsystem_set_params(fresh_a, D, mu, &e), LR_OK);
    lr_dsystem_apply(b, x, ya);
    lr_dsystem_apply(fresh_b, x, yb);
    assert_memory_equal(ya, yb, n * sizeof *ya);
    lr_dsystem_apply(a, x, ya);
    lr_dsystem_apply(fresh_a, x, yb);
    assert_memory_equal(ya, yb, n * sizeof *ya);
    /* the ghost rows' phi(b) weights came along */
    size_t nb = lr_dgrid_unknown_count(g) - n_in;
    for (size_t q = 0; q < nb; q += 17)
        assert_true(lr_dsystem_ghost_phi(b, q, x) == lr_dsystem_ghost_phi(fresh_b, q, x));
    lr_dsystem_destroy(a);
    lr_dsystem_destroy(b);
    lr_dsystem_destroy(fresh_a);
    lr_dsystem_destroy(fresh_b);
    lr_dgrid_destroy(g);
    free(D);
    free(mu);
    free(x);
    free(ya);
    free(yb);
}

/* ---- volume files ---- */

static void test_volume(void **state)
{
    (void)state;
    lr_dvolume *v;
    lr_err e = {0};
    assert_int_equal(lr_dvolume_load("configs/materials/layered_wax.vol", &v, &e), LR_OK);
    assert_true(lr_dvolume_region_count(v) >= 2);
    lr_dvolume_destroy(v);
    const char *ok = "lamprig-volume 1\n# two layers\nbox 0 0 0 1 1 2\ndims 1 1 2\n"
                     "region a sigma_a 0.1 0.2 0.3 sigma_s_prime 1 1 1\n"
                     "region b sigma_a 0.01 0.01 0.01 sigma_s_prime 2 2 2\ndata\na\n\nb\n";
    assert_int_equal(lr_dvolume_parse(ok, "t.vol", &v, &e), LR_OK);
    double sa[3], ss[3];
    lr_dvolume_at(v, lr_v3(0.5, 0.5, 0.5), sa, ss);
    assert_true(sa[2] == 0.3 && ss[0] == 1.0);
    lr_dvolume_at(v, lr_v3(0.5, 0.5, 1.5), sa, ss);
    assert_true(sa[2] == 0.01 && ss[0] == 2.0);
    lr_dvolume_at(v, lr_v3(-5, 9, 99), sa, ss); /* clamped */
    assert_true(ss[0] == 2.0);
    lr_dvolume_destroy(v);
    struct {
        const char *text, *want;
    } bad[] = {
        {"volume 1\n", "t.vol:1:"},
        {"lamprig-volume 1\nbox 0 0 0 1 1\n", "t.vol:2: field 'box'"},
        {"lamprig-volume 1\nbox 0 0 0 1 1 1\ndims 1 1 0\n", "t.vol:3: field 'dims'"},
        {"lamprig-volume 1\nbox 0 0 0 1 1 1\ndims 1 1 1\nregion a sigma_a 1 1 sigma_s_prime 1 1 1\n",
         "t.vol:4: region 'a'"},
        {"lamprig-volume 1\nbox 0 0 0 1 1 1\ndims 3 1 1\nregion a sigma_a 1 1 1 sigma_s_prime 1 1 "
         "1\ndata\naa\n",
         "t.vol:6: data row has 2 cells"},
        {"lamprig-volume 1\nbox 0 0 0 1 1 1\ndims 2 1 1\nregion a sigma_a 1 1 1 sigma_s_prime 1 1 "
         "1\ndata\nab\n",
         "t.vol:6: column 2: 'b'"},
        {"lamprig-volume 1\nbox 0 0 0 1 1 1\ndims 1 1 2\nregion a sigma_a 1 1 1 sigma_s_prime 1 1 "
         "1\ndata\na\n",
         "data ends"},
        {"lamprig-volume 1\nbox 0 0 0 1 1 1\ndims 1 1 1\nregion a sigma_a 0 0 0 sigma_s_prime 0 0 "
         "0\ndata\na\n",
         "must be > 0"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        lr_err_clear(&e);
        v = NULL;
        assert_int_not_equal(lr_dvolume_parse(bad[k].text, "t.vol", &v, &e), LR_OK);
        assert_null(v);
        if (!strstr(e.msg, bad[k].want))
            fail_msg("case %zu: '%s' does not contain '%s'", k, e.msg, bad[k].want);
    }
    assert_int_not_equal(lr_dvolume_load("configs/materials/no_such.vol", &v, &e), LR_OK);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_slab),
        cmocka_unit_test(test_sphere),
        cmocka_unit_test(test_warm_start),
        cmocka_unit_test(test_clone_is_independent),
        cmocka_unit_test(test_volume),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
