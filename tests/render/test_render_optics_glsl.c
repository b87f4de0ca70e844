/* The GLSL optics (render/shaders/lib/optics.glsl) against the C reference (render/optics/),
 * evaluated by a fragment shader on a grid of inputs: directional dipole S_d with and without
 * Fresnel transmission, Fresnel reflectance, exponential radius sampling and its density.
 *
 * Tolerance. The shader computes in IEEE float (highp: 24-bit significand, unit roundoff
 * u = 6e-8); the C reference in double. GLSL ES 3.10 (section "Range and Precision") bounds
 * exp/exp2 by (3 + 2|x|) ULP and log, sqrt, inversesqrt, division by 3 ULP or less; S_d takes
 * exp(-s) with s = sigma_tr d <= 87 (beyond it both sides give 0), i.e. at most ~180 ULP =
 * 1.1e-5 relative, plus ~60 roundings in the geometry (<= 4e-6). The clamped difference
 * real - virtual source amplifies relative error by real / (real - virt), which on this grid
 * (x_o at >= 0.05 mfp from x_i) stays below ~20: 20 * 1.5e-5 = 3e-4. We assert 1e-3 relative
 * plus an absolute floor of 1e-5 times the case's largest band (a band that cancels to nearly
 * 0 while the others do not). Fresnel: a handful of operations, 1e-5 absolute. Sampling:
 * the float log1p/expm1 forms of the shader keep 1e-5 relative.
 *
 * Standard dipole (the model switch's other S_d, Jensen 2001 R_d(r) / pi): a sum of two
 * positive source terms, each exp(-s) with s <= 87 (<= 177 ULP = 1.1e-5) and ~10 roundings, no
 * cancellation: 1e-4 relative, with the same absolute floor (1e-5 of the largest band) for a
 * band near float underflow. The switch is checked for both models (even materials standard,
 * odd directional) against lr_sss_sd_fresnel. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <GLES3/gl31.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/gl/gl.h"
#include "render/gl/shader.h"
#include "render/gl/tex.h"
#include "render/material/material.h"
#include "render/optics/optics.h"
#include "render/passes/defines.h"
#include "render/passes/material_pack.h"
#include "tests/support/gl.h"
#include "tests/support/near.h"

#define NMAT 5

typedef struct tcase {
    lr_vec3 xi, ni, wi, xo, no;
    int mat;
    double cos_i, eta, xi_s, r_max;
} tcase;

LR_TEST_GL_FIXTURE(gl) /* tests/support/gl.h: setup(), teardown() */

static lr_vec3 unit(double x, double y, double z)
{
    return lr_v3_normalize(lr_v3(x, y, z));
}

/* The shader sees float inputs: the reference gets the same rounded values. */
static lr_vec3 f3(lr_vec3 v)
{
    return lr_v3((float)v.x, (float)v.y, (float)v.z);
}

static void load_coeffs(lr_coeffs c[NMAT])
{
    static const char *const names[] = {"marble", "candle_wax", "spectralon", "ketchup"};
    lr_err e = {0};
    for (int i = 0; i < 4; i++) {
        lr_material m;
        if (lr_material_find(names[i], &m, &e) || lr_coeffs_derive(&m.medium, &c[i], &e))
            fail_msg("%s: %s", names[i], e.msg);
    }
    /* eta < 1 (a medium optically thinner than outside): total internal reflection on entry. */
    lr_medium thin = {{0.01, 0.02, 0.05}, {1.0, 1.5, 2.0}, 0.8, 0.0};
    if (lr_coeffs_derive(&thin, &c[4], &e))
        fail_msg("%s", e.msg);
}

/* The model switch's choice per test material: even standard, odd directional. */
static enum lr_sss_model model_of(int m)
{
    return m % 2 == 0 ? LR_SSS_STANDARD_DIPOLE : LR_SSS_DIRECTIONAL_DIPOLE;
}

static void test_optics_glsl_matches_c(void **state)
{
    lr_coeffs co[NMAT];
    load_coeffs(co);
    /* The grid. */
    static const double radii_mfp[] = {0.05, 0.3, 1.0, 3.0, 10.0, 30.0};
    static const double wi_deg[] = {0.0, 30.0, 60.0, 85.0};
    static const double no_tilt[] = {0.0, 40.0, 120.0};
    int n = NMAT * 6 * 4 * 3;
    tcase *cs = calloc((size_t)n, sizeof *cs);
    int k = 0;
    for (int m = 0; m < NMAT; m++)
        for (int a = 0; a < 6; a++)
            for (int b = 0; b < 4; b++)
                for (int t = 0; t < 3; t++, k++) {
                    tcase *c = &cs[k];
                    double r = radii_mfp[a] * co[m].mfp[1];
                    c->mat = m;
                    c->xi = lr_v3(1.0, -2.0, 0.5);
                    c->ni = unit(0.0, 0.2, 1.0);
                    double w = wi_deg[b] * M_PI / 180.0;
                    c->wi = unit(sin(w), 0.1, cos(w));
                    double phi = 0.7 * a + 0.3 * b;
                    c->xo = lr_v3_add(c->xi, lr_v3(r * cos(phi), r * sin(phi), 0.1 * r));
                    double tt = no_tilt[t] * M_PI / 180.0;
                    c->no = unit(sin(tt), 0.0, cos(tt));
                    c->cos_i = (k % 17) / 16.0;
                    c->eta = m == 4 ? 0.8 : co[m].eta;
                    c->xi_s = (k % 13) / 13.0;
                    c->r_max = m == 2 ? 500.0 : 50.0;
                }
    /* Inputs: 6 texels per case. */
    float *in = calloc((size_t)n * 6 * 4, sizeof *in);
    for (int i = 0; i < n; i++) {
        const tcase *c = &cs[i];
        lr_vec3 v[5] = {c->xi, c->ni, c->wi, c->xo, c->no};
        for (int j = 0; j < 5; j++) {
            in[(i * 6 + j) * 4 + 0] = (float)v[j].x;
            in[(i * 6 + j) * 4 + 1] = (float)v[j].y;
            in[(i * 6 + j) * 4 + 2] = (float)v[j].z;
        }
        in[(i * 6) * 4 + 3] = (float)c->mat;
        float *s = in + (i * 6 + 5) * 4;
        s[0] = (float)c->cos_i;
        s[1] = (float)c->eta;
        s[2] = (float)c->xi_s;
        s[3] = (float)c->r_max;
    }
    lr_err e = {0};
    lr_shader_defines defs; /* the renderer's: material.glsl compares against LR_SSS_* */
    lr_tex *tin = NULL, *tout = NULL;
    lr_fb *fb = NULL;
    lr_program *p = NULL;
    if (lr_tex_create(gl, &(lr_tex_desc){.width = 6, .height = n}, &tin, &e) ||
        lr_tex_upload(tin, 0, in, &e) ||
        lr_tex_create(gl, &(lr_tex_desc){.width = 5, .height = n}, &tout, &e) ||
        lr_fb_create(gl, &(lr_fb_desc){.color = {{tout, 0}}}, &fb, &e) ||
        lr_program_create(&(lr_program_desc){.vertex = "render/shaders/fullscreen.vert",
                                             .fragment = "tests/shaders/optics_eval.frag",
                                             .defines = lr_passes_defines(&defs)},
                          &p, &e))
        fail_msg("%s", e.msg);
    float coef[5 * 4 * LR_MAX_OBJECTS] = {0};
    float sss[3 * 4 * LR_MAX_OBJECTS] = {0};
    for (int m = 0; m < NMAT; m++) {
        lr_passes_pack_coeffs(&co[m], coef + 20 * m);
        lr_passes_pack_sss(&co[m], model_of(m), sss + 12 * m);
    }
    lr_fb_bind(fb);
    glUseProgram(lr_program_id(p));
    glUniform4fv(lr_program_uniform(p, "u_coef"), 5 * LR_MAX_OBJECTS, coef);
    glUniform4fv(lr_program_uniform(p, "u_sss"), 3 * LR_MAX_OBJECTS, sss);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, lr_tex_id(tin));
    glUniform1i(lr_program_uniform(p, "u_cases"), 0);
    lr_gl_draw_fullscreen(gl);
    float *out = calloc((size_t)n * 5 * 4, sizeof *out);
    if (lr_fb_read(fb, 0, 0, 0, 5, n, out, &e))
        fail_msg("%s", e.msg);

    double worst_sd = 0.0, worst_std = 0.0;
    int nonzero = 0, nonzero_std = 0;
    for (int i = 0; i < n; i++) {
        tcase cr = cs[i];
        const tcase *c = &cr;
        cr.xi = f3(cr.xi);
        cr.ni = f3(cr.ni);
        cr.wi = f3(cr.wi);
        cr.xo = f3(cr.xo);
        cr.no = f3(cr.no);
        cr.cos_i = (float)cr.cos_i;
        cr.eta = (float)cr.eta;
        const lr_coeffs *cf = &co[c->mat];
        double sd[3], sdf[3];
        lr_dirpole_sd(cf, c->xi, c->ni, c->wi, c->xo, c->no, sd);
        lr_dirpole_sd_fresnel(cf, c->xi, c->ni, c->wi, c->xo, c->no, sdf);
        const float *g = out + (size_t)i * 5 * 4;
        double mx = fmax(sd[0], fmax(sd[1], sd[2]));
        for (int j = 0; j < 3; j++) {
            double tol = 1e-3 * fabs(sd[j]) + 1e-5 * mx;
            if (getenv("LR_TEST_VERBOSE") && !(fabs(g[j] - sd[j]) <= tol))
                printf("case %d (material %d) band %d: GLSL S_d %.9g, C %.9g\n", i, c->mat, j,
                       g[j], sd[j]);
            else if (!(fabs(g[j] - sd[j]) <= tol))
                fail_msg("case %d (material %d) band %d: GLSL S_d %.9g, C %.9g", i, c->mat, j,
                         g[j], sd[j]);
            if (sd[j] > 0.0) {
                nonzero++;
                worst_sd = fmax(worst_sd, fabs(g[j] - sd[j]) / sd[j]);
            }
            double mf = fmax(sdf[0], fmax(sdf[1], sdf[2]));
            assert_near(g[4 + j], sdf[j], 1e-3 * fabs(sdf[j]) + 1e-5 * mf);
        }
        assert_near(g[8], lr_fresnel_reflectance(c->cos_i, c->eta), 1e-5);
        double sw[3], st[3];
        lr_sss_sd_fresnel(model_of(c->mat), cf, 0.0, c->xi, c->ni, c->wi, c->xo, c->no, sw);
        lr_dipole_sd(cf, c->xi, c->xo, st);
        double mw = fmax(sw[0], fmax(sw[1], sw[2])), mt = fmax(st[0], fmax(st[1], st[2]));
        for (int j = 0; j < 3; j++) {
            /* The directional model keeps its own tolerance (above); the standard 1e-4. */
            double rel = model_of(c->mat) == LR_SSS_STANDARD_DIPOLE ? 1e-4 : 1e-3;
            assert_near(g[12 + j], sw[j], rel * fabs(sw[j]) + 1e-5 * mw);
            assert_near(g[16 + j], st[j], 1e-4 * fabs(st[j]) + 1e-5 * mt);
            if (st[j] > 0.0)
                worst_std = fmax(worst_std, fabs(g[16 + j] - st[j]) / st[j]);
            nonzero_std += st[j] > 1e-30;
        }
        double rs = lr_exp_radius_sample(cf->sigma_tr[0], c->r_max, (float)c->xi_s);
        assert_near(g[9], rs, 1e-5 * rs + 1e-6);
        assert_near_rel(g[10], lr_exp_radius_pdf(cf->sigma_tr[0], c->r_max, rs), 1e-4);
    }
    /* The grid must exercise the model, not compare zeros. */
    assert_true(nonzero > n);
    assert_true(nonzero_std > n);
    printf("GLSL vs C standard dipole: worst relative S_d difference %.3g\n", worst_std);
    printf("GLSL vs C optics: %d cases, worst relative S_d difference %.3g\n", n, worst_sd);
    lr_program_destroy(p);
    lr_fb_destroy(fb);
    lr_tex_destroy(tin);
    lr_tex_destroy(tout);
    free(out);
    free(in);
    free(cs);
}

/* The multipole (model 2) through the same shader's model switch (texel 3) against
 * lr_sss_sd_fresnel: slabs of porcelain 1.5 mm, candle_wax 7 and 14 mm, marble 3 mm and a
 * 0.1 mm sheet (source at d/2); entry on the top face, exit on the same face (R) and on the
 * far face (T), at radii 0.02-4 (d + 2 z_b). Float: every pole term is one exp (<= 1.1e-5)
 * and ~12 roundings; the pairs' sum cancels at most where the profile has fallen far below
 * its peak, so the assertion is 1e-3 relative plus 1e-5 of the profile's value at r = 0
 * (the absolute floor where T(r) has decayed by orders of magnitude). */
static void test_multipole_glsl_matches_c(void **state)
{
    static const struct {
        const char *name;
        double d;
    } slabs[] = {{"porcelain", 1.5}, {"candle_wax", 7.0}, {"candle_wax", 14.0}, {"marble", 3.0},
                 {"porcelain", 0.1}};
    enum { NS = 5, NR = 8, NW = 2 };
    static const double rfrac[NR] = {0.0, 0.02, 0.1, 0.3, 0.7, 1.2, 2.0, 4.0};
    lr_coeffs co[NS];
    lr_err e = {0};
    float coef[5 * 4 * LR_MAX_OBJECTS] = {0};
    float sss[3 * 4 * LR_MAX_OBJECTS] = {0};
    for (int m = 0; m < NS; m++) {
        lr_material mt;
        if (lr_material_find(slabs[m].name, &mt, &e) || lr_coeffs_derive(&mt.medium, &co[m], &e))
            fail_msg("%s", e.msg);
        lr_passes_pack_coeffs(&co[m], coef + 20 * m);
        lr_passes_pack_sss(&co[m], LR_SSS_MULTIPOLE, sss + 12 * m);
        lr_passes_pack_multipole(&co[m], LR_SSS_MULTIPOLE, slabs[m].d, sss + 12 * m);
        assert_true(sss[12 * m + 11] == (float)lr_multipole_pairs(&co[m], slabs[m].d));
    }
    int n = NS * NR * NW;
    tcase *cs = calloc((size_t)n, sizeof *cs);
    float *in = calloc((size_t)n * 6 * 4, sizeof *in);
    for (int m = 0, k = 0; m < NS; m++)
        for (int a = 0; a < NR; a++)
            for (int w = 0; w < NW; w++, k++) {
                tcase *c = &cs[k];
                double zb = 0.5 * (co[m].z_v[1] - co[m].z_r[1]), d = slabs[m].d;
                double r = rfrac[a] * (d + 2.0 * zb), phi = 0.4 * a;
                c->mat = m;
                c->xi = f3(lr_v3(2.0, 1.0, 0.5));
                c->ni = f3(lr_v3(0, 0, 1));
                c->wi = f3(unit(0.3, 0.1, 1.0));
                c->xo = f3(lr_v3_add(c->xi, lr_v3(r * cos(phi), r * sin(phi), w ? -d : 0.0)));
                c->no = f3(lr_v3(0, 0, w ? -1 : 1));
                lr_vec3 v[5] = {c->xi, c->ni, c->wi, c->xo, c->no};
                for (int j = 0; j < 5; j++) {
                    in[(k * 6 + j) * 4 + 0] = (float)v[j].x;
                    in[(k * 6 + j) * 4 + 1] = (float)v[j].y;
                    in[(k * 6 + j) * 4 + 2] = (float)v[j].z;
                }
                in[(k * 6) * 4 + 3] = (float)m;
                in[(k * 6 + 5) * 4 + 3] = 1.0f; /* r_max of the sampling texel */
            }
    lr_tex *tin = NULL, *tout = NULL;
    lr_fb *fb = NULL;
    lr_program *p = NULL;
    lr_shader_defines defs; /* the renderer's: optics.glsl compares against LR_SSS_* */
    if (lr_tex_create(gl, &(lr_tex_desc){.width = 6, .height = n}, &tin, &e) ||
        lr_tex_upload(tin, 0, in, &e) ||
        lr_tex_create(gl, &(lr_tex_desc){.width = 5, .height = n}, &tout, &e) ||
        lr_fb_create(gl, &(lr_fb_desc){.color = {{tout, 0}}}, &fb, &e) ||
        lr_program_create(&(lr_program_desc){.vertex = "render/shaders/fullscreen.vert",
                                             .fragment = "tests/shaders/optics_eval.frag",
                                             .defines = lr_passes_defines(&defs)},
                          &p, &e))
        fail_msg("%s", e.msg);
    lr_fb_bind(fb);
    glUseProgram(lr_program_id(p));
    glUniform4fv(lr_program_uniform(p, "u_coef"), 5 * LR_MAX_OBJECTS, coef);
    glUniform4fv(lr_program_uniform(p, "u_sss"), 3 * LR_MAX_OBJECTS, sss);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, lr_tex_id(tin));
    glUniform1i(lr_program_uniform(p, "u_cases"), 0);
    lr_gl_draw_fullscreen(gl);
    float *out = calloc((size_t)n * 5 * 4, sizeof *out);
    if (lr_fb_read(fb, 0, 0, 0, 5, n, out, &e))
        fail_msg("%s", e.msg);
    double worst = 0.0;
    int nonzero = 0;
    for (int k = 0; k < n; k++) {
        const tcase *c = &cs[k];
        const lr_coeffs *cf = &co[c->mat];
        double d = slabs[c->mat].d, sw[3], R0[3], T0[3];
        lr_sss_sd_fresnel(LR_SSS_MULTIPOLE, cf, d, c->xi, c->ni, c->wi, c->xo, c->no, sw);
        lr_multipole_profile(cf, d, 0.0, R0, T0);
        bool across = c->no.z < 0.0;
        double ft = lr_fresnel_transmittance(lr_v3_dot(c->wi, c->ni), cf->eta);
        const float *g = out + (size_t)k * 5 * 4;
        for (int j = 0; j < 3; j++) {
            double floor_ = 1e-5 * ft * (across ? T0[j] : R0[j]) / M_PI;
            if (!(fabs(g[12 + j] - sw[j]) <= 1e-3 * sw[j] + floor_))
                fail_msg("case %d (%s %.1f mm, %s) band %d: GLSL %.9g, C %.9g", k,
                         slabs[c->mat].name, d, across ? "across" : "same face", j, g[12 + j],
                         sw[j]);
            if (sw[j] > 100.0 * floor_) { /* above 1e-3 of the peak */
                nonzero++;
                worst = fmax(worst, fabs(g[12 + j] - sw[j]) / sw[j]);
            }
        }
    }
    assert_true(nonzero > n);
    printf("GLSL vs C multipole: %d cases, worst relative S_d difference %.3g\n", n, worst);
    lr_program_destroy(p);
    lr_fb_destroy(fb);
    lr_tex_destroy(tin);
    lr_tex_destroy(tout);
    free(out);
    free(in);
    free(cs);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_optics_glsl_matches_c),
        cmocka_unit_test(test_multipole_glsl_matches_c),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
