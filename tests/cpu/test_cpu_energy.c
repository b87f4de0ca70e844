/* Energy (issue 3): "a closed sphere of non-absorbing material around a point light emits the
 * light's power within 5 %". The model of PIPELINE.md (directional dipole S_d, B of seed 003
 * Eq. 4, L_o = F_t B / pi) emits
 *
 *   Phi = int_A int_2pi L_o cos d(omega) dA = T_hem int_A B dA,
 *   T_hem = 2 int_0^1 F_t(mu, eta) mu d(mu)   (1 for eta = 1; 0.908 for eta = 1.5).
 *
 * Asserted below:
 *  1. [14]'s S_d as published is not energy conserving: its half-space albedo at albedo' 1 is
 *     1.340 / 1.240 / 1.197 (eta 1 / 1.3 / 1.5). The default S_d is multiplied per band by
 *     coeffs.sd_norm, after which the half-space total is the standard dipole's R_d total
 *     (exactly 1 at albedo' 1).
 *  2. sphere.json has the light INSIDE the material: every ray from it meets the surface from
 *     behind, so Phi = 0; the scene loader warns about it (never silently).
 *  3. Bookkeeping: in a thick shell, power out + power back into the cavity = 4 pi I F_t(0)
 *     (normalised model, albedo 1) within 5 %.
 *  4. With the cavity closure (render/core/cavity.h) the outer surface of a closed hollow
 *     non-absorbing sphere emits 4 pi I within 5 %: 2 mm, 3 mm and 20 mm walls, eta 1 and 1.5,
 *     for the pass (the twin) and the untruncated reference sampler. */
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
#include "render/models/twin/cavity_gains.h"
#include "render/models/twin/radiosity.h"
#include "render/base/rng.h"
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
    /* The library's quadrature (dirpole_norm.c, 8-point rule on 320 panels) agrees with this
     * one (16-point on 400 panels) to 1e-5, and sd_norm brings the total to the standard
     * dipole's R_d total: 1 at albedo' 1, and for every preset's bands (albedo' < 1). */
    for (int i = 0; i < 3; i++) {
        lr_medium m = white(eta[i]);
        lr_coeffs c;
        assert_int_equal(lr_coeffs_derive(&m, &c, NULL), 0);
        double lib[3];
        lr_dirpole_halfspace_albedo(&c, lib);
        assert_near_rel(lib[0], planar_albedo(eta[i]), 1e-5);
        assert_near(c.sd_norm[0] * lib[0], 1.0, 1e-9);
    }
    static const char *const presets[] = {"marble", "porcelain", "skin1", "ketchup",
                                          "wholemilk", "apple", "spectralon"};
    for (size_t i = 0; i < sizeof presets / sizeof presets[0]; i++) {
        lr_material pm;
        lr_coeffs c;
        if (lr_material_find(presets[i], &pm, NULL) || lr_coeffs_derive(&pm.medium, &c, NULL))
            fail_msg("preset %s", presets[i]);
        double lib[3], rd[3];
        lr_dirpole_halfspace_albedo(&c, lib);
        lr_dipole_rd_total(&c, rd);
        print_message("%-10s sd_norm %.4f %.4f %.4f\n", presets[i], c.sd_norm[0], c.sd_norm[1],
                      c.sd_norm[2]);
        for (int b = 0; b < 3; b++) {
            assert_true(c.sd_norm[b] > 0.0 && c.sd_norm[b] <= 1.0); /* [14] overshoots */
            assert_near_rel(c.sd_norm[b] * lib[b], rd[b], 1e-9);
        }
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
        bool hit = inner ? lr_first_surface(&o->obj, lr_v3(0, 0, 0), u, 0, &xo, &no)
                         : lr_first_surface(&o->obj, lr_v3_scale(u, 3.0 * radius),
                                                lr_v3_scale(u, -1), 0, &xo, &no);
        assert_true(hit);
        lr_cpu_estimate est;
        lr_cpu_radiosity(&o->obj, l, xo, no, &d, lr_rng_key(inner ? 77 : 78, (uint64_t)p, 0, 0),
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

static void keep_warning(void *user, const char *msg)
{
    snprintf(user, LR_ERR_MSG_MAX, "%s", msg);
}

/* Finding 2: the shipped scene. */
static void test_sphere_scene_light_in_medium(void **state)
{
    (void)state;
    char path[1024];
    snprintf(path, sizeof path, "%s/scenes/sphere.json", lr_configs_dir());
    lr_scene *s;
    lr_err e = {0};
    char warned[LR_ERR_MSG_MAX] = "";
    lr_warn_sink sink = {keep_warning, warned};
    if (lr_scene_load(path, &sink, &s, &e))
        fail_msg("%s", e.msg);
    /* Never silently dark: the loader names the light, the object and the file:line. */
    print_message("warning: %s\n", warned);
    assert_non_null(strstr(warned, "sphere.json:"));
    assert_non_null(strstr(warned, "lights[0] 'core' at (0, 0, 0) is inside the material of objects[0] 'ball'"));
    int obj = -1;
    assert_int_equal(lr_scene_light_enclosure(s, 0, &obj), LR_ENCLOSURE_SOLID);
    const lr_scene_object *o = lr_scene_object_at(s, 0);
    const lr_light *l = lr_scene_light_at(s, 0);
    for (int c = 0; c < 3; c++)
        assert_true(o->coeffs.sigma_tr[c] == 0.0);
    lr_cpu_radiosity_desc d = {.N = 256};
    for (int p = 0; p < 16; p++) {
        lr_vec3 u = lr_halton_sphere((unsigned)p + 1), xo, no;
        assert_true(lr_first_surface(o, lr_v3_scale(u, 200), lr_v3_scale(u, -1), 0, &xo, &no));
        for (int mode = 0; mode < 2; mode++) {
            d.sampler = mode ? LR_CPU_REFERENCE : LR_CPU_PASS;
            lr_cpu_estimate est;
            lr_cpu_radiosity(o, l, xo, no, &d, lr_rng_key(1, (uint64_t)p, 0, 0), &est);
            for (int c = 0; c < 3; c++)
                assert_true(est.mean[c] == 0.0);
        }
    }
    print_message("sphere.json (light inside the material): Phi = 0 (PIPELINE.md: light meeting "
                  "the surface from inside contributes nothing), not 4 pi I\n");
    lr_scene_destroy(s);
}

/* Finding 3, the bookkeeping: a thick shell (R 40, cavity 20), the light at the centre, eta = 1
 * and 1.5, without the cavity closure. Out + cavity = 4 pi I F_t(0) within 5 %; the
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
        /* Normalised model: the half-space total is sd_norm x planar_albedo = 1. */
        double want = lr_fresnel_transmittance(1.0, eta) * planar_albedo(eta) *
                      o.obj.coeffs.sd_norm[0];
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

/* Finding 4, issue 3's requirement: a closed hollow sphere (R 40) of non-absorbing material
 * around a point light at its centre, power out of the outer surface with the cavity gain =
 * 4 pi I within 5 %, for walls of 2 mm (a porcelain globe), 3 mm and 20 mm, eta 1.5 and 1.
 * The gain comes from lr_cavity_measure (its own 256 random points, stratified by area);
 * the power is integrated here over 32 Halton points (a fixed quadrature: the sphere's area
 * per solid angle is uniform), with the twin's pass sampler and with the untruncated
 * reference sampler. The reference's Monte Carlo error (4 standard errors, times the gain) is
 * required to be below 2.5 % so that the test discriminates. */
static void check_closed_shell_model(double ri, double eta, enum lr_sss_model model)
{
    lr_medium m = white(eta);
    lrt_object o;
    lrt_object_make(lrt_shell_mesh(40, ri, 4), &m, &o);
    o.obj.sss_model = model;
    o.obj.thickness_mm = 40 - ri;
    lr_light l = lrt_point_light(lr_v3(0, 0, 0));
    lr_cavity cav;
    lr_err e = {0};
    if (lr_cavity_measure(&o.obj, &l, LR_ENCLOSURE_HULL, NULL, &cav, &e))
        fail_msg("%s", e.msg);
    assert_true(cav.applies);
    assert_near(cav.C, 1.0, 1e-12); /* every direction meets the closed shell */
    assert_near(cav.F, 1.0, 1e-12); /* and everything it sends back meets it again */
    assert_near(cav.R1, lr_fresnel_reflectance(1.0, eta), 0.01); /* near-normal incidence */
    double Pm[2][3], Sm[2][3];
    for (int mode = 0; mode < 2; mode++) {
        enum lr_cpu_sampler smp = mode ? LR_CPU_REFERENCE : LR_CPU_PASS;
        double out[3], sout[3];
        surface_power(&o, &l, 40, false, 32, 4000, smp, eta, out, sout);
        for (int c = 0; c < 3; c++) {
            Pm[mode][c] = out[c] * cav.gain[c];
            Sm[mode][c] = sout[c] * cav.gain[c];
        }
        for (int c = 0; c < 3; c++) {
            double P = out[c] * cav.gain[c], se = sout[c] * cav.gain[c];
            print_message("wall %4.1f mm eta %.1f %s band %d: direct out %.4f (a %.4f), C %.3f "
                          "R1 %.4f gain %.3f -> Phi_out %.4f +- %.4f x 4 pi I\n", 40 - ri, eta,
                          mode ? "ref " : "pass", c, out[c], cav.a[c], cav.C, cav.R1,
                          cav.gain[c], P, se);
            if (mode) {
                /* The gain (up to 25 here) multiplies the error: 4 se < 2.5 % still
                 * separates 1 from 0.95. */
                assert_true(4.0 * se < 0.025);
                assert_near(P, 1.0, 0.05);
            }
        }
    }
    /* The pass (the twin) estimates the same power: its outer points face away from the
     * light, where its weights are heavy-tailed (render/cpu/README.md finding 2), so its
     * standard error at this N is 1-4 %; it agrees with the reference within 4 sigma. */
    for (int c = 0; c < 3; c++)
        assert_near(Pm[0][c], Pm[1][c], 4.0 * sqrt(Sm[0][c] * Sm[0][c] + Sm[1][c] * Sm[1][c]));
    lrt_object_free(&o);
}

static void check_closed_shell(double ri, double eta)
{
    check_closed_shell_model(ri, eta, LR_SSS_DIRECTIONAL_DIPOLE);
}

static void test_closed_shell_emits_light_power(void **state)
{
    (void)state;
    check_closed_shell(38, 1.5);
    check_closed_shell(37, 1.5);
    check_closed_shell(20, 1.5);
    check_closed_shell(38, 1.0);
}

/* The same closed shell with the slab multipole (issue 12, "model": "multipole" with the wall's
 * thickness): the closure's A is the multipole's exact R + T total (lr_sss_total, 1 at
 * sigma_a = 0), so the outer surface emits 4 pi I within 5 % here too, for the 2 mm and 3 mm
 * walls at eta 1.5 and the 2 mm wall at eta 1. */
static void test_closed_shell_multipole(void **state)
{
    (void)state;
    check_closed_shell_model(38, 1.5, LR_SSS_MULTIPOLE);
    check_closed_shell_model(37, 1.5, LR_SSS_MULTIPOLE);
    check_closed_shell_model(38, 1.0, LR_SSS_MULTIPOLE);
}

/* The raw model ("normalize": false) has no closure: gain 1, and the pass gives the published
 * model's B (1 / sd_norm times the default's). A light outside the hull gets no gain. */
static void test_closure_only_where_it_applies(void **state)
{
    (void)state;
    lr_medium m = white(1.5);
    lrt_object o;
    lrt_object_make(lrt_shell_mesh(40, 38, 3), &m, &o);
    lr_light l = lrt_point_light(lr_v3(0, 0, 0));
    lr_cavity cav;
    lr_cavity_desc d = {.points = 16, .N = 16};
    assert_int_equal(lr_cavity_measure(&o.obj, &l, LR_ENCLOSURE_NONE, &d, &cav, NULL), 0);
    assert_false(cav.applies);
    lr_vec3 xo = lr_v3(0, 0, 40), no = lr_v3(0, 0, 1);
    lr_cpu_radiosity_desc rd = {.N = 64};
    lr_cpu_estimate norm, raw;
    lr_cpu_radiosity(&o.obj, &l, xo, no, &rd, lr_rng_key(5, 0, 0, 0), &norm);
    o.obj.sd_raw = true;
    assert_int_equal(lr_cavity_measure(&o.obj, &l, LR_ENCLOSURE_HULL, &d, &cav, NULL), 0);
    assert_false(cav.applies);
    lr_cpu_radiosity(&o.obj, &l, xo, no, &rd, lr_rng_key(5, 0, 0, 0), &raw);
    for (int c = 0; c < 3; c++) {
        assert_true(cav.gain[c] == 1.0);
        /* Same random stream: exactly the factor, to rounding. */
        assert_near_rel(norm.mean[c], raw.mean[c] * o.obj.coeffs.sd_norm[c], 1e-12);
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
        cmocka_unit_test(test_closed_shell_emits_light_power),
        cmocka_unit_test(test_closed_shell_multipole),
        cmocka_unit_test(test_closure_only_where_it_applies),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
