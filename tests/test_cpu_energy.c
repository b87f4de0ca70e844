/* Energy (issue 3): "a closed sphere of non-absorbing material around a point light emits the
 * light's power within 5 %". What the model of PIPELINE.md (directional dipole S_d, B of seed
 * 003 Eq. 4, L_o = F_t B / pi) gives, measured with the CPU twin:
 *
 *   emitted power  Phi = int_A int_2pi L_o cos d(omega) dA = T_hem int_A B dA,
 *   T_hem = 2 int_0^1 F_t(mu, eta) mu d(mu)   (1 for eta = 1; 0.908 for eta = 1.5),
 *
 * against 4 pi I. Findings (each asserted below):
 *  1. The directional dipole is not energy conserving at albedo 1: on a half-space at normal
 *     incidence T_hem pi int S_d dA = 1.340 (eta = 1), 1.240 (1.3), 1.197 (1.5) times the power
 *     that entered, where the standard dipole's total diffuse reflectance is exactly 1.
 *  2. The shipped sphere.json has the light INSIDE the material (enclosure SOLID). Every ray
 *     from the light meets the surface from behind (n_i . w_i < 0), which PIPELINE.md counts as
 *     no light: Phi = 0 exactly. A surface-incidence BSSRDF has no term for a source embedded in
 *     the medium.
 *  3. With the light in a cavity (a hollow sphere, the lamp-shade/votive configuration), the
 *     model's bookkeeping is right: power out of the outer surface plus power back into the
 *     cavity = 4 pi I F_t(0) x (the half-space albedo of 1.) within 5 % for a thick shell
 *     (curvature and finite thickness are the remaining model error). But the outer surface
 *     alone emits far less than 4 pi I: the model has no inter-reflection in the cavity, where
 *     most of the light comes back out (and, since the albedo of 1. exceeds 1, a bounce series
 *     would diverge instead of converging to 4 pi I).
 * So no configuration of this model meets "4 pi I within 5 %" at sigma_a = 0; the test below
 * that does hold to 5 % is the bookkeeping identity 3. */
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
#include "render/cpu/radiosity.h"
#include "render/cpu/rng.h"
#include "render/material/material.h"
#include "tests/support/near.h"
#include "tests/support/objects.h"
#include "tests/support/quadrature.h"

/* Marble's scattering, no absorption (sphere.json's material), relative index eta. */
static lr_medium white(double eta)
{
    lr_material m;
    lr_err e = {0};
    if (lr_material_find("marble", &m, &e))
        fail_msg("%s", e.msg);
    for (int c = 0; c < 3; c++)
        m.medium.sigma_a[c] = 0.0;
    m.medium.eta = eta;
    return m.medium;
}

static double ft_mu(double mu, void *p) { return lr_fresnel_transmittance(mu, *(double *)p) * mu; }

/* Hemispherical cosine-weighted transmittance 2 int F_t mu d(mu), by quadrature. */
static double t_hem(double eta)
{
    return 2.0 * lrt_gl_integrate(ft_mu, &eta, 0.0, 1.0, 16, 64);
}

struct plane_ctx {
    const lr_coeffs *c;
};

static double plane_integrand(double u, void *p)
{
    struct plane_ctx *k = p;
    double r = exp(u), sd[3];
    lr_vec3 z = lr_v3(0, 0, 1);
    lr_dirpole_sd(k->c, lr_v3(r, 0, 0), z, z, lr_v3(0, 0, 0), z, sd);
    return sd[0] * 2.0 * M_PI * r * r;
}

/* Half-space albedo of the model at normal incidence: power out / power that entered. At
 * sigma_a = 0 it does not depend on sigma_s' (every length scales with the mean free path);
 * S_d ~ r^-3 far out, so the integral to 1e7 mean free paths misses < 1e-6 of it. */
static double planar_albedo(double eta)
{
    lr_medium m = white(eta);
    lr_coeffs c;
    lr_err e = {0};
    if (lr_coeffs_derive(&m, &c, &e))
        fail_msg("%s", e.msg);
    struct plane_ctx k = {&c};
    double mfp = c.mfp[0];
    return M_PI * lrt_gl_integrate(plane_integrand, &k, log(1e-9 * mfp), log(1e7 * mfp), 16, 400) *
           t_hem(eta);
}

/* Finding 1. The values are this model's (lr_dirpole_sd follows [14] and its authors' code);
 * held to 0.2 % (quadrature is good to 1e-6; the tolerance only absorbs the Fresnel fits). */
static void test_dirpole_planar_albedo(void **state)
{
    (void)state;
    const double eta[] = {1.0, 1.3, 1.5}, want[] = {1.3395, 1.2402, 1.1967};
    for (int i = 0; i < 3; i++) {
        double rho = planar_albedo(eta[i]);
        print_message("eta %.1f: T_hem %.4f, directional dipole half-space albedo at albedo' 1: "
                      "%.4f\n", eta[i], t_hem(eta[i]), rho);
        assert_near_rel(rho, want[i], 2e-3);
        /* The standard dipole's closed form is exactly 1 there. */
        lr_medium m = white(eta[i]);
        lr_coeffs c;
        assert_int_equal(lr_coeffs_derive(&m, &c, NULL), 0);
        double rd[3];
        lr_dipole_rd_total(&c, rd);
        assert_near(rd[0], 1.0, 1e-12);
    }
    /* T_hem is the directional dipole's own normalisation 1 - 2 C1(1/eta). */
    lr_medium m = white(1.5);
    lr_coeffs c;
    assert_int_equal(lr_coeffs_derive(&m, &c, NULL), 0);
    assert_near(t_hem(1.5), 1.0 / c.C_phi_norm, 5e-3);
}

/* Power through a surface: T_hem * area * mean B over points along Halton directions (the
 * sphere's area per solid angle is uniform to 0.1 %), with its standard error. inner: the
 * cavity's surface (points found from the centre outwards) instead of the outer one. */
static void surface_power(const lrt_object *o, const lr_light *l, double radius, bool inner,
                          int npts, int N, enum lr_cpu_sampler sampler, double eta, double P[3],
                          double se[3])
{
    double sum[3] = {0}, var[3] = {0};
    lr_cpu_radiosity_desc d = {.N = N, .sampler = sampler};
    for (int p = 0; p < npts; p++) {
        lr_vec3 u = lr_halton_sphere((unsigned)p + 1), xo, no;
        bool hit = inner ? lr_cpu_first_surface(&o->obj, lr_v3(0, 0, 0), u, 0, &xo, &no)
                         : lr_cpu_first_surface(&o->obj, lr_v3_scale(u, 3.0 * radius),
                                                lr_v3_scale(u, -1), 0, &xo, &no);
        assert_true(hit);
        lr_cpu_estimate est;
        lr_cpu_radiosity(&o->obj, l, xo, no, &d, lr_cpu_key(inner ? 77 : 78, (uint64_t)p, 0, 0),
                         &est);
        for (int c = 0; c < 3; c++) {
            sum[c] += est.mean[c];
            var[c] += est.var[c] / est.n;
        }
    }
    double scale = t_hem(eta) * 4.0 * M_PI * radius * radius / npts / (4.0 * M_PI); /* per 4 pi I */
    for (int c = 0; c < 3; c++) {
        P[c] = sum[c] * scale;
        se[c] = sqrt(var[c]) * scale; /* MC error only (the points are a fixed quadrature) */
    }
}

/* Finding 2: the shipped scene. */
static void test_sphere_scene_light_in_medium(void **state)
{
    (void)state;
    char path[1024];
    snprintf(path, sizeof path, "%s/scenes/sphere.json", lr_configs_dir());
    lr_scene *s;
    lr_err e = {0};
    if (lr_scene_load(path, NULL, &s, &e))
        fail_msg("%s", e.msg);
    int obj = -1;
    assert_int_equal(lr_scene_light_enclosure(s, 0, &obj), LR_ENCLOSURE_SOLID);
    const lr_scene_object *o = lr_scene_object_at(s, 0);
    const lr_light *l = lr_scene_light_at(s, 0);
    for (int c = 0; c < 3; c++)
        assert_true(o->coeffs.sigma_tr[c] == 0.0);
    lr_cpu_radiosity_desc d = {.N = 256};
    for (int p = 0; p < 16; p++) {
        lr_vec3 u = lr_halton_sphere((unsigned)p + 1), xo, no;
        assert_true(lr_cpu_first_surface(o, lr_v3_scale(u, 200), lr_v3_scale(u, -1), 0, &xo, &no));
        for (int mode = 0; mode < 2; mode++) {
            d.sampler = mode ? LR_CPU_REFERENCE : LR_CPU_PASS;
            lr_cpu_estimate est;
            lr_cpu_radiosity(o, l, xo, no, &d, lr_cpu_key(1, (uint64_t)p, 0, 0), &est);
            for (int c = 0; c < 3; c++)
                assert_true(est.mean[c] == 0.0);
        }
    }
    print_message("sphere.json (light inside the material): Phi = 0 (PIPELINE.md: light meeting "
                  "the surface from inside contributes nothing), not 4 pi I\n");
    lr_scene_destroy(s);
}

/* Finding 3, the bookkeeping that holds: a thick shell (R 40, cavity 20), the light at the
 * centre, eta = 1 and 1.5. Out + cavity = 4 pi I F_t(0) albedo_plane(eta) within 5 %; the
 * Monte Carlo error (4 standard errors) is required to be below 2 % so that the test
 * discriminates. The outer surface alone: < 10 % of 4 pi I. */
static void test_shell_energy_bookkeeping(void **state)
{
    (void)state;
    const double etas[] = {1.0, 1.5};
    for (int i = 0; i < 2; i++) {
        double eta = etas[i];
        lr_medium m = white(eta);
        lrt_object o;
        lrt_object_make(lrt_shell_mesh(40, 20, 4), &m, &o);
        lr_light l = lrt_point_light(lr_v3(0, 0, 0));
        double out[3], sout[3], cav[3], scav[3];
        surface_power(&o, &l, 40, false, 32, 6000, LR_CPU_REFERENCE, eta, out, sout);
        surface_power(&o, &l, 20, true, 32, 6000, LR_CPU_REFERENCE, eta, cav, scav);
        double want = lr_fresnel_transmittance(1.0, eta) * planar_albedo(eta);
        for (int c = 0; c < 3; c++) {
            double tot = out[c] + cav[c], se = sqrt(sout[c] * sout[c] + scav[c] * scav[c]);
            print_message("eta %.1f band %d: Phi_out %.4f, Phi_cavity %.4f (x 4 pi I), sum %.4f "
                          "+- %.4f; F_t(0) albedo_plane = %.4f (%+.1f %%)\n", eta, c, out[c],
                          cav[c], tot, se, want, 100 * (tot / want - 1));
            assert_true(4.0 * se < 0.02 * want);
            assert_near_rel(tot, want, 0.05);
            assert_true(out[c] < 0.1);
        }
        lrt_object_free(&o);
    }
}

/* A thin shell (R 40, 2 mm wall, eta 1.5: a votive or porcelain globe): the outer surface emits
 * 0.30-0.50 of 4 pi I (measured 0.46, 0.40, 0.35 for marble's three bands, whose mean free paths
 * differ), the cavity gets more than 1 x 4 pi I back. Asserted as ranges. */
static void test_thin_shell_outward_power(void **state)
{
    (void)state;
    lr_medium m = white(1.5);
    lrt_object o;
    lrt_object_make(lrt_shell_mesh(40, 38, 4), &m, &o);
    lr_light l = lrt_point_light(lr_v3(0, 0, 0));
    double out[3], sout[3], cav[3], scav[3];
    surface_power(&o, &l, 40, false, 24, 2000, LR_CPU_REFERENCE, 1.5, out, sout);
    surface_power(&o, &l, 38, true, 24, 2000, LR_CPU_REFERENCE, 1.5, cav, scav);
    for (int c = 0; c < 3; c++) {
        print_message("2 mm shell band %d: Phi_out %.4f +- %.4f, Phi_cavity %.4f +- %.4f "
                      "(x 4 pi I)\n", c, out[c], sout[c], cav[c], scav[c]);
        assert_true(out[c] > 0.28 && out[c] < 0.52);
        assert_true(cav[c] > 1.0);
    }
    lrt_object_free(&o);
}

int main(void)
{
    if (getenv("LR_TEST_FILTER"))
        cmocka_set_test_filter(getenv("LR_TEST_FILTER"));
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_dirpole_planar_albedo),
        cmocka_unit_test(test_sphere_scene_light_in_medium),
        cmocka_unit_test(test_shell_energy_bookkeeping),
        cmocka_unit_test(test_thin_shell_outward_power),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
