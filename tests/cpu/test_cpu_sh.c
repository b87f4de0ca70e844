/* CPU twin of the sh_translucency model (render/models/twin/sh.h): the thickness against ray casts
 * through a sphere (closed-form chords), the projection through the G-buffer cameras against
 * the closed-form power and lit area of a sphere, and the stored preset scales against the fit. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdlib.h>

#include "render/models/twin/radiosity.h"
#include "render/models/twin/sh.h"
#include "render/material/material.h"
#include "tests/support/near.h"
#include "tests/support/objects.h"

#define R_MM 20.0
#define SUB 5 /* icosphere subdivisions: 20 480 triangles */

static const lr_medium wax = {.sigma_a = {0.00105, 0.00205, 0.00355},
                              .sigma_s_prime = {1.095, 1.31, 1.5}, .eta = 1.44};

/* Largest gap between the icosphere (every vertex on the sphere) and the sphere: at a
 * triangle's centre, R (1 - cos(e / (sqrt(3) R))) for its longest edge e (the centre is e /
 * sqrt(3) from the vertices); e <= 1.3 x 1.05 R / 2^SUB (the icosahedron's edge is 1.05 R,
 * subdivision halves it, projection onto the sphere stretches it by < 1.3). */
static double sagitta(void)
{
    double e = 1.3 * 1.05 * R_MM / (1 << SUB);
    return R_MM * (1.0 - cos(e / (sqrt(3.0) * R_MM)));
}

/* Point light at distance D on +z, a ray at angle a off the axis: the chord through the sphere
 * is 2 sqrt(R^2 - b^2), b = D sin a. x_o is the far end found by a ray cast from beyond the
 * sphere back toward the light; the thickness (light distance to x_o minus the first hit)
 * matches the chord within the two ends' sagittas over the cosine at the surface, 2 s / cos. */
static void test_thickness_chords(void **state)
{
    (void)state;
    lrt_object o;
    lrt_object_make(lrt_shell_mesh(R_MM, 0.0, SUB), &wax, &o);
    double D = 60.0;
    lr_light L = lrt_point_light(lr_v3(0, 0, D));
    for (int k = 0; k < 12; k++) {
        double b = 0.9 * R_MM * k / 11.0, a = asin(b / D);
        lr_vec3 u = lr_v3(sin(a) * cos(0.7 * k), sin(a) * sin(0.7 * k), -cos(a));
        /* From 3 D beyond, back along -u: the first hit is the far end of the chord. */
        lr_vec3 far = lr_v3_add(L.position, lr_v3_scale(u, 3.0 * D));
        lr_hit hit;
        assert_true(lr_bvh_intersect(o.bvh, far, lr_v3_scale(u, -1.0), 0.0, INFINITY, &hit));
        lr_vec3 xo = lr_v3_add(far, lr_v3_scale(u, -hit.t));
        double d;
        assert_true(lr_cpu_sh_thickness(&o.obj, &L, xo, NULL, &d, NULL));
        double chord = 2.0 * sqrt(R_MM * R_MM - b * b), cosr = sqrt(1.0 - (b / R_MM) * (b / R_MM));
        assert_near(d, chord, 2.0 * sagitta() / cosr + 1e-9);
    }
    /* On the lit side x_o is the first surface itself: thickness 0. */
    double d;
    assert_true(lr_cpu_sh_thickness(&o.obj, &L, lr_v3(0, 0, R_MM), NULL, &d, NULL));
    assert_near(d, 0.0, sagitta());
    /* A directional light along -z: the chord along z at (x, 0). */
    lr_light Ld = lrt_directional_light(lr_v3(0, 0, -1));
    lr_vec3 xo = lr_v3(0.5 * R_MM, 0, 0);
    lr_hit hit;
    assert_true(lr_bvh_intersect(o.bvh, lr_v3(0.5 * R_MM, 0, -3 * R_MM), lr_v3(0, 0, 1), 0.0,
                                 INFINITY, &hit));
    xo.z = -3 * R_MM + hit.t;
    assert_true(lr_cpu_sh_thickness(&o.obj, &Ld, xo, NULL, &d, NULL));
    assert_near(d, 2.0 * sqrt(0.75) * R_MM, 2.0 * sagitta() / sqrt(0.75) + 1e-9);
    lrt_object_free(&o);
}

/* A sphere under a directional light, projected through the orthographic G-buffer camera:
 * the light crossing the beam's disk pi R^2 enters with the hemispherical transmittance,
 * power = pi R^2 T_hem(eta) (2 int F_t mu dmu, lr_hemi_transmittance), over the lit hemisphere's
 * area 2 pi R^2. Quadrature over 256^2 texels of the disk's bounding square and the mesh: the
 * disk's rim texels (perimeter / texel of them, each at most one texel area off) bound the
 * error: 2 pi R (2R/256) / (pi R^2) = 1.6 % of the power; the area's grazing texels (cos < 0.05
 * of them are cut at LR_SH_MIN_COS, the rest weigh 1/cos) make the area converge slower:
 * 4 % allowed. By symmetry E_lm's l = 1 part points along the light: E_1m ~ (0, 0, -1). */
static void test_env_directional_sphere(void **state)
{
    (void)state;
    lrt_object o;
    lrt_object_make(lrt_shell_mesh(R_MM, 0.0, SUB), &wax, &o);
    lr_light L = lrt_directional_light(lr_v3(0, 0, -1));
    lr_gb_camera cam;
    lr_gb_camera_make(&L, o.obj.center, o.obj.radius, false, &cam);
    assert_int_equal(cam.mode, LR_GB_ORTHO);
    lr_sh_env env;
    lr_cpu_sh_env(&o.obj, &L, &cam, 256, NULL, 0, 0, &env);
    double disk = M_PI * R_MM * R_MM;
    assert_near_rel(env.power, disk * lr_hemi_transmittance(wax.eta), 0.016);
    assert_near_rel(env.area, 2.0 * disk, 0.04);
    /* Y_10 ~ z: the light travels toward -z, E_10 < 0; x and y parts vanish by symmetry. */
    assert_true(env.E[2] < 0.0);
    assert_near(env.E[1], 0.0, 0.02 * fabs(env.E[2]));
    assert_near(env.E[3], 0.0, 0.02 * fabs(env.E[2]));
    lrt_object_free(&o);
}

/* A point light outside, eta = 1 (no interface, F_t = 1): the power is the solid angle of the
 * sphere seen from the light, 2 pi (1 - sqrt(1 - R^2/D^2)), and the lit area the cap
 * 2 pi R^2 (1 - R/D). Through the perspective G-buffer camera at 256^2: rim texels as above
 * (the cone's rim: 2 pi rho / texel of them), 1.5 %; area 4 %. */
static void test_env_point_sphere(void **state)
{
    (void)state;
    lr_medium m = wax;
    m.eta = 1.0;
    lrt_object o;
    lrt_object_make(lrt_shell_mesh(R_MM, 0.0, SUB), &m, &o);
    double D = 60.0;
    lr_light L = lrt_point_light(lr_v3(0, 0, D));
    lr_gb_camera cam;
    lr_gb_camera_make(&L, o.obj.center, o.obj.radius, false, &cam);
    assert_int_equal(cam.mode, LR_GB_PERSPECTIVE);
    lr_sh_env env;
    lr_cpu_sh_env(&o.obj, &L, &cam, 256, NULL, 0, 0, &env);
    double q = R_MM / D;
    assert_near_rel(env.power, 2.0 * M_PI * (1.0 - sqrt(1.0 - q * q)), 0.015);
    assert_near_rel(env.area, 2.0 * M_PI * R_MM * R_MM * (1.0 - q), 0.04);
    /* The same light enclosed in a cavity of the shell: the cube G-buffer sees the whole inner
     * sphere, power 4 pi (solid angles tile the sphere), area 4 pi r_i^2 (normal incidence). */
    lrt_object sh;
    lrt_object_make(lrt_shell_mesh(R_MM, 10.0, SUB), &m, &sh);
    lr_light Li = lrt_point_light(lr_v3(0, 0, 0));
    lr_gb_camera_make(&Li, sh.obj.center, sh.obj.radius, true, &cam);
    assert_int_equal(cam.mode, LR_GB_CUBE);
    lr_cpu_sh_env(&sh.obj, &Li, &cam, 64, NULL, 0, 0, &env);
    assert_near_rel(env.power, 4.0 * M_PI, 1e-9);
    assert_near_rel(env.area, 4.0 * M_PI * 100.0, 2e-3);
    /* Light from the centre travels every way alike: E(n) the same for every n (l >= 1 vanish
     * by symmetry up to the icosphere's): the mean entering irradiance P/A = 1/r^2 times the
     * clamped cosine's mean over the sphere, pi / (4 pi) = 1/4 (against 17/16 for light that
     * all travels along n: sh_translucency.h, LR_SH_DELTA_GAIN). */
    assert_near_rel(lr_sh_env_irradiance(&env, lr_v3(0, 0, 1)), 0.25 / 100.0, 5e-3);
    assert_near_rel(lr_sh_env_irradiance(&env, lr_v3_normalize(lr_v3(1, -2, 0.5))), 0.25 / 100.0,
                    5e-3);
    lrt_object_free(&sh);
    lrt_object_free(&o);
}

/* The scale stored with each shipped preset ("sh_scale", configs/materials) is lr_sh_fit_scale
 * at LR_SH_FIT_MM of the preset's medium, to the 4 significant digits written (5e-4). */
static void test_preset_scales(void **state)
{
    (void)state;
    char **names;
    int n;
    lr_err e = {0};
    if (lr_material_names(&names, &n, &e))
        fail_msg("%s", e.msg);
    int with = 0;
    for (int i = 0; i < n; i++) {
        lr_material m;
        if (lr_material_find(names[i], &m, &e))
            fail_msg("%s", e.msg);
        lr_coeffs c;
        assert_int_equal(lr_coeffs_derive(&m.medium, &c, &e), LR_OK);
        double fit[3];
        lr_sh_fit_scale(&c, LR_SH_FIT_MM, fit);
        if (!(m.sh_scale[0] > 0.0))
            continue;
        with++;
        for (int b = 0; b < 3; b++)
            if (!(fabs(m.sh_scale[b] / fit[b] - 1.0) <= 5e-4))
                fail_msg("%s sh_scale[%d] = %.6g, fit %.6g", names[i], b, m.sh_scale[b], fit[b]);
    }
    lr_material_names_free(names, n);
    assert_true(with >= 2); /* at least the candle's wax and the shade's porcelain */
}

/* The estimator entry point dispatches on the model: deterministic B (variance 0), the same
 * as lr_cpu_sh_B with the environment given; without one it projects its own. */
static void test_estimator_dispatch(void **state)
{
    (void)state;
    lrt_object o;
    lrt_object_make(lrt_shell_mesh(R_MM, 0.0, 3), &wax, &o);
    o.obj.sss_model = LR_SSS_SH_TRANSLUCENCY;
    lr_light L = lrt_point_light(lr_v3(0, 0, 60));
    lr_gb_camera cam;
    lr_gb_camera_make(&L, o.obj.center, o.obj.radius, false, &cam);
    lr_sh_env env;
    lr_cpu_sh_env(&o.obj, &L, &cam, 64, NULL, 0, 1, &env);
    lr_vec3 xo = lr_v3(0, 0, -R_MM * 0.999), no = lr_v3(0, 0, -1);
    lr_cpu_radiosity_desc d = {.N = 4, .sh_env = &env};
    lr_cpu_estimate est;
    lr_cpu_radiosity(&o.obj, &L, xo, no, &d, 1, &est);
    double B[3];
    lr_cpu_sh_B(&o.obj, &L, &env, xo, no, NULL, B);
    for (int c = 0; c < 3; c++) {
        assert_true(B[c] > 0.0);
        assert_near(est.mean[c], B[c], 0.0);
        assert_near(est.var[c], 0.0, 0.0);
    }
    /* Back-lit transmission decays with the band's sigma_tr: R (17 mm) > G > B (8 mm). */
    assert_true(B[0] > B[1] && B[1] > B[2]);
    /* The lit pole takes the direct term on top: rho_c F_t(1) / r^2 (lr_dipole_rd_total; the
     * light on the axis, x_o the mesh's first surface there, n_o the axis), the scattering
     * term as lr_sh_translucency_B at d = 0 (clamped to one mean free path). */
    lr_hit hit;
    assert_true(lr_bvh_intersect(o.bvh, L.position, lr_v3(0, 0, -1), 0.0, INFINITY, &hit));
    lr_vec3 top = lr_v3(0, 0, 60.0 - hit.t), up = lr_v3(0, 0, 1);
    double s[3], rho[3], T[3];
    lr_cpu_sh_B(&o.obj, &L, &env, top, up, NULL, B);
    lr_sh_object_scale(&o.obj.coeffs, NULL, s);
    lr_sh_translucency_B(&o.obj.coeffs, s, &env, up, 0.0, T);
    lr_dipole_rd_total(&o.obj.coeffs, rho);
    for (int c = 0; c < 3; c++)
        assert_near_rel(B[c] - T[c], rho[c] * lr_fresnel_transmittance(1.0, wax.eta) /
                                         (hit.t * hit.t), 1e-9);
    lrt_object_free(&o);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_thickness_chords),
        cmocka_unit_test(test_env_directional_sphere),
        cmocka_unit_test(test_env_point_sphere),
        cmocka_unit_test(test_preset_scales),
        cmocka_unit_test(test_estimator_dispatch),
    };
    return cmocka_run_group_tests_name("cpu_sh", tests, NULL, NULL);
}
