/* Hard cases of the render passes (docs/ARCHITECTURE.md, "Hard cases that must stay finite
 * and sensible"): a light exactly on the surface, an object smaller than one map texel, a
 * zero-thickness shade, albedo -> 1 (spectralon), a light outside the object. Each must give
 * finite, non-negative HDR images, maps and VPLs, and an emergent power within the bounds
 * argued at check_energy. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/plan/limits.h"
#include "render/renderer.h"
#include "render/renderer_debug.h"
#include "tests/support/gl.h"
#include "tests/support/near.h"
#include "tests/support/render.h"

#define W 48
#define H 36

LR_TEST_GL_FIXTURE(gl) /* tests/support/gl.h: setup(), teardown() */

/* Renders to convergence and checks every HDR pixel, map texel and VPL; returns the emergent
 * power per band for unit intensity, sum_v B_v A_v, divided by 4 pi (the power of a unit
 * point light), and the HDR image in *hdr_out unless that is NULL (the caller frees it). */
static void scan_renderer(lr_renderer *r, double frac[3], float **hdr_out)
{
    lr_test_converge(r, 8);
    float *hdr = lr_test_hdr(r);
    for (int i = 0; i < W * H * 3; i++)
        if (!(isfinite(hdr[i]) && hdr[i] >= 0.0f))
            fail_msg("HDR value %d = %g", i, hdr[i]);
    if (hdr_out)
        *hdr_out = hdr;
    else
        free(hdr);
    /* Object pixels no map sees: a few at silhouettes with K = 6 maps; never a large part. */
    int uncovered = -1;
    lr_err e0 = {0};
    if (lr_renderer_debug_uncovered(r, &uncovered, &e0))
        fail_msg("%s", e0.msg);
    printf("uncovered object pixels: %d of %d\n", uncovered, W * H);
    assert_true(uncovered >= 0 && uncovered < W * H / 20);
    lr_debug_map_info mi;
    lr_renderer_debug_map_info(r, &mi);
    size_t n = (size_t)mi.size * mi.size;
    float *B = malloc(n * 3 * sizeof *B);
    lr_err e = {0};
    for (int k = 0; k < mi.K; k++) {
        if (lr_renderer_debug_read_map(r, k, B, NULL, NULL, NULL, &e))
            fail_msg("%s", e.msg);
        for (size_t t = 0; t < n * 3; t++)
            if (!(isfinite(B[t]) && B[t] >= 0.0f))
                fail_msg("map %d texel %zu = %g", k, t / 3, B[t]);
    }
    free(B);
    int nv = lr_renderer_debug_vpl_count(r);
    lr_debug_vpl *v = calloc((size_t)nv, sizeof *v);
    if (lr_renderer_debug_read_vpls(r, v, &e))
        fail_msg("%s", e.msg);
    frac[0] = frac[1] = frac[2] = 0.0;
    for (int i = 0; i < nv; i++) {
        if (!v[i].valid)
            continue;
        assert_true(isfinite(v[i].area) && v[i].area > 0.0);
        for (int c = 0; c < 3; c++) {
            assert_true(isfinite(v[i].B[c]) && v[i].B[c] >= 0.0);
            frac[c] += v[i].B[c] * v[i].area / (4.0 * M_PI);
        }
    }
    free(v);
}

static void render_and_scan_hdr(lr_scene *s, double frac[3], float **hdr_out)
{
    lr_renderer *r = lr_test_renderer(gl, s, W, H, false, 1);
    scan_renderer(r, frac, hdr_out);
    lr_renderer_destroy(r);
}

static void render_and_scan(lr_scene *s, double frac[3])
{
    render_and_scan_hdr(s, frac, NULL);
}

/* Energy. Maps are for a unit point light (4 pi W); sum_v B_v A_v estimates the power that
 * leaves the outer surface. It cannot exceed what the light emits: the fraction must be
 * <= 1, and we allow 1.6 for the estimate's own errors: the VPL areas A_v (48 directions over
 * a cylinder or cone: ~20% quadrature error) and Monte Carlo noise after 2 frames of N = 4
 * (~30% per VPL, ~5% over 48). A lower bound `lo` per case says light does come out. */
static void check_energy(const char *what, const double frac[3], double lo)
{
    for (int c = 0; c < 3; c++) {
        printf("%s band %d: emergent power / light power = %.4g\n", what, c, frac[c]);
        if (!(frac[c] >= lo && frac[c] <= 1.6))
            fail_msg("%s band %d: emergent fraction %g outside [%g, 1.6]", what, c, frac[c], lo);
    }
}

/* The flame on the melt pool's surface (z = 112) rather than 5 mm above it: G-buffer texels
 * right under the light sit at distance 0, where the inverse-square law and the dipole are
 * singular. */
static void test_light_on_surface(void **state)
{
    static const char *const sets[] = {"light.position=0,0,112", NULL};
    lr_scene *s = lr_test_scene("candle", lr_test_small_settings, sets);
    double f[3];
    render_and_scan(s, f);
    check_energy("light on the surface", f, 1e-3);
    lr_scene_destroy(s);
}

/* A 0.02 mm bead beside the candle: far below one texel of any map (~0.8 mm here) or the
 * G-buffer. */
static void test_object_smaller_than_a_texel(void **state)
{
    static const char text[] =
        "{\"name\": \"bead\", \"objects\": ["
        " {\"name\": \"pillar\", \"material\": \"candle_wax\","
        "  \"mesh\": {\"type\": \"candle\", \"radius\": 35, \"height\": 120, \"pool_depth\": 8}},"
        " {\"name\": \"bead\", \"material\": \"marble\","
        "  \"mesh\": {\"type\": \"sphere\", \"radius\": 0.01, \"subdivisions\": 2},"
        "  \"transform\": {\"translate\": [45, 0, 100]}}],"
        " \"lights\": [{\"type\": \"point\", \"position\": [0, 0, 117], \"intensity\": 0.005}],"
        " \"camera\": {\"position\": [0, -450, 230], \"target\": [0, 40, 70]},"
        " \"receivers\": [{\"name\": \"table\", \"type\": \"plane\", \"center\": [0, -75, 0],"
        "  \"normal\": [0, 0, 1], \"size\": [1200, 650], \"albedo\": [0.75, 0.72, 0.68]}],"
        " \"render\": {\"exposure\": 3e6}}";
    lr_scene *s = lr_test_scene_text(text, lr_test_small_settings);
    double f[3];
    render_and_scan(s, f);
    check_energy("bead beside the candle", f, 1e-3);
    lr_scene_destroy(s);
}

/* A shade of thickness 0: one surface, drawn two-sided. */
static void test_zero_thickness_shade(void **state)
{
    static const char *const sets[] = {"objects[shade].mesh.thickness=0", NULL};
    lr_scene *s = lr_test_scene("lampshade", lr_test_small_settings, sets);
    double f[3];
    render_and_scan(s, f);
    check_energy("zero-thickness shade", f, 1e-3);
    lr_scene_destroy(s);
}

/* Spectralon (sigma_a = 0: albedo' = 1, sigma_tr = 0): the radii are uniform on [0, r_max],
 * r_max = 20 bounding radii, so only ~5% of the samples land on the object; 8 frames of N = 8
 * so that every band gets enough of them for the lower bound. */
static void test_albedo_one(void **state)
{
    static const char *const sets[] = {"objects[pillar].material=spectralon", "render.frames=8",
                                       "render.N=8", NULL};
    lr_scene *s = lr_test_scene("candle", lr_test_small_settings, sets);
    double f[3];
    render_and_scan(s, f);
    check_energy("spectralon candle", f, 1e-3);
    lr_scene_destroy(s);
}

/* A point light outside the object: the 2D perspective G-buffer. */
static void test_light_outside(void **state)
{
    static const char *const sets[] = {"objects[ball].material=marble", "light.position=0,0,120", NULL};
    lr_scene *s = lr_test_scene("sphere", lr_test_small_settings, sets);
    double f[3];
    render_and_scan(s, f);
    check_energy("marble ball lit from outside", f, 1e-3);
    lr_scene_destroy(s);
}

/* A directional light (orthographic G-buffer, unit radiance) and a spot light (perspective
 * G-buffer along its axis, angular profile) on a marble ball over a table: finite,
 * non-negative, and the ball and the table are lit. */
static void test_directional_and_spot(void **state)
{
    static const char *const lights[] = {
        "{\"type\": \"directional\", \"direction\": [0.3, 0.2, -1], \"radiance\": 1e-3}",
        "{\"type\": \"spot\", \"position\": [0, -60, 120], \"direction\": [0, 0.4, -1],"
        " \"inner_deg\": 15, \"outer_deg\": 25, \"intensity\": 1}"};
    for (int i = 0; i < 2; i++) {
        char text[2048];
        snprintf(text, sizeof text,
                 "{\"name\": \"ball\", \"objects\": [{\"name\": \"ball\", \"material\": \"marble\","
                 " \"mesh\": {\"type\": \"sphere\", \"radius\": 40}}], \"lights\": [%s],"
                 " \"camera\": {\"position\": [0, -300, 120], \"target\": [0, 0, 0]},"
                 " \"receivers\": [{\"name\": \"table\", \"type\": \"plane\", \"center\": [0, 0, -40],"
                 " \"normal\": [0, 0, 1], \"size\": [600, 600], \"albedo\": [0.8, 0.8, 0.8]}]}",
                 lights[i]);
        lr_scene *s = lr_test_scene_text(text, lr_test_small_settings);
        double f[3];
        float *hdr;
        render_and_scan_hdr(s, f, &hdr); /* the scanned image itself: no second render */
        /* The centre pixel is on the ball, the bottom-centre one on the table in front. */
        size_t ball = 3 * ((size_t)(H / 2) * W + W / 2), table = 3 * ((size_t)2 * W + W / 2);
        printf("%s: ball %g, table %g\n", i ? "spot" : "directional", hdr[ball], hdr[table]);
        assert_true(hdr[ball] > 0.0f && hdr[table] > 0.0f);
        free(hdr);
        lr_scene_destroy(s);
    }
}

/* fp16 accumulation (the RGBA16F fallback for drivers without EXT_float_blend). The maps keep
 * a running mean, which stays O(B), and store B R^2 so that the values sit in half floats'
 * normal range. Drivers may still round the blended result toward zero (llvmpipe does): the
 * mean then drifts down by ~2^-13 per frame (measured: -1.1% after 64 frames, -16% after
 * 1024), so half-float maps stop accumulating at LR_HALF_MAX_FRAMES = 32 frames however large
 * render.frames is. Against RGBA32F maps with the same seed and 32 frames the mean relative
 * texel difference must stay below 1% (drift ~0.6% plus fp16 rounding of 2^-12), and no texel
 * may exceed 1.1x its fp32 value or be NaN. */
static void test_fp16_accumulation(void **state)
{
    static const char *const sets[] = {"render.K=2", "render.N=1", "render.map_size=16",
                                       "render.gbuffer_size=32", "render.frames=1024", NULL};
    lr_scene *s = lr_test_scene("sphere", sets, (const char *const[]){"objects[ball].material=marble",
                                                                      "light.position=0,0,120", NULL});
    float *maps[2];
    int *obj = malloc(16 * 16 * sizeof *obj);
    for (int h = 0; h < 2; h++) {
        lr_renderer *r = lr_test_renderer_desc(&(lr_renderer_desc){
            .gl = gl, .scene = s, .width = 8, .height = 8, .no_vpl = true, .seed = 3, .half_maps = !h});
        if (h) {
            for (int f = 0; f < 32; f++)
                lr_test_frame(r);
        } else {
            assert_int_equal(lr_test_converge(r, 2000), 32);
            assert_non_null(strstr(lr_renderer_info(r), "RGBA16F"));
        }
        maps[h] = malloc(2 * 16 * 16 * 3 * sizeof *maps[h]);
        lr_err e = {0};
        for (int k = 0; k < 2; k++)
            if (lr_renderer_debug_read_map(r, k, maps[h] + k * 16 * 16 * 3, NULL, NULL, obj, &e))
                fail_msg("%s", e.msg);
        lr_renderer_destroy(r);
    }
    double diff = 0.0, sum = 0.0, sdiff = 0.0;
    for (int i = 0; i < 2 * 16 * 16 * 3; i++) {
        float half = maps[0][i], full = maps[1][i];
        assert_true(isfinite(half) && half >= 0.0f);
        assert_true(half <= 1.1f * full + 1e-12f);
        diff += fabs(half - full);
        sdiff += half - full;
        sum += full;
    }
    printf("fp16 vs fp32 maps after 32 frames: mean relative difference %.3g (signed %.3g)\n",
           diff / sum, sdiff / sum);
    assert_true(sum > 0.0);
    assert_true(diff / sum < 0.01);
    free(maps[0]);
    free(maps[1]);
    free(obj);
    lr_scene_destroy(s);
}

/* Optically thick and extreme materials on every model (issue 34: sh_translucency gave Inf
 * pixels from sigma_a 44 /mm or sigma_s' 1e6 /mm, translucent radiosity Inf at sigma_s' 1e6
 * and sigma_a 1e4 /mm): sigma_a in {1, 100, 1e4} x sigma_s' in {1, 1e6} /mm on a ball lit
 * from outside, over a table, each set on marble. Each combination is either refused with a
 * message that starts with the key that was set and says why in terms of sigma_tr
 * (lr_scene_set: the model's numerics, the model's max_sigma_tr, render/models/model.h;
 * lr_plan_check_models, which `lamprig render` and the rig run before rendering: the
 * planner's limits, the grid's spacing), or renders an image, maps and VPLs that are finite
 * and >= 0, with the emergent power within check_energy's bound (a finite 1e32 fails there: at
 * most 1.6 of the light's power). Cheap: one renderer per model, one frame of K 2, N 1,
 * 16^2 maps after each change. */
static void test_extreme_materials(void **state)
{
    (void)state;
    static const char *const tiny[] = {"render.K=2", "render.N=1", "render.map_size=16",
                                       "render.gbuffer_size=32", "render.vpl_map_size=8",
                                       "render.N_vpl=8", "render.frames=1", NULL};
    static const char text[] =
        "{\"name\": \"ball\", \"objects\": [{\"name\": \"ball\", \"material\": \"marble\","
        " \"mesh\": {\"type\": \"sphere\", \"radius\": 40, \"subdivisions\": 2}}],"
        " \"lights\": [{\"type\": \"point\", \"position\": [0, -60, 120], \"intensity\": 1}],"
        " \"camera\": {\"position\": [0, -300, 120], \"target\": [0, 0, 0]},"
        " \"receivers\": [{\"name\": \"table\", \"type\": \"plane\", \"center\": [0, 0, -40],"
        " \"normal\": [0, 0, 1], \"size\": [160, 160], \"albedo\": [0.8, 0.8, 0.8]}]}";
    static const char *const sa[] = {"1", "100", "1e4"}, *const ssp[] = {"1", "1e6"};
    int rendered = 0, refused = 0;
    for (int m = 0; m < LR_SSS_MODEL_COUNT; m++) {
        const char *model = lr_sss_model_name((enum lr_sss_model)m);
        lr_scene *s = lr_test_scene_text(text, tiny);
        lr_err e = {0};
        if (lr_sss_model_props_of((enum lr_sss_model)m)->needs_thickness &&
            lr_scene_set(s, "objects[0].thickness_mm", "5", NULL, &e))
            fail_msg("%s", e.msg);
        if (lr_scene_set(s, "objects[0].model", model, NULL, &e))
            fail_msg("%s: %s", model, e.msg); /* marble: within every model */
        lr_renderer *r = NULL;
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < 2; k++) {
                char a[32], b[32];
                snprintf(a, sizeof a, "%s,%s,%s", sa[i], sa[i], sa[i]);
                snprintf(b, sizeof b, "%s,%s,%s", ssp[k], ssp[k], ssp[k]);
                unsigned d0 = 0, d1 = 0, d2 = 0;
                if (lr_scene_set(s, "objects[0].material", "marble", &d0, &e))
                    fail_msg("%s", e.msg);
                const char *key = NULL;
                if (lr_scene_set(s, "objects[0].material.sigma_s_prime", b, &d1, &e))
                    key = "objects[0].material.sigma_s_prime: ";
                else if (lr_scene_set(s, "objects[0].material.sigma_a", a, &d2, &e))
                    key = "objects[0].material.sigma_a: ";
                else if (lr_plan_check_models(s, &e))
                    key = "objects[0].model: ";
                printf("%s sigma_a %s sigma_s' %s: %s\n", model, sa[i], ssp[k],
                       key ? e.msg : "rendered");
                if (key) {
                    assert_true(strncmp(e.msg, key, strlen(key)) == 0);
                    assert_non_null(strstr(e.msg, "sigma_tr"));
                    refused++;
                    continue;
                }
                if (r)
                    lr_renderer_invalidate(r, d0 | d1 | d2);
                else
                    r = lr_test_renderer(gl, s, W, H, false, 1);
                double f[3];
                scan_renderer(r, f, NULL);
                check_energy(model, f, 0.0);
                rendered++;
            }
        lr_renderer_destroy(r);
        lr_scene_destroy(s);
    }
    /* both outcomes occur (else the sweep checks only one of them) */
    assert_true(rendered > 0 && refused > 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_light_on_surface),
        cmocka_unit_test(test_object_smaller_than_a_texel),
        cmocka_unit_test(test_zero_thickness_shade),
        cmocka_unit_test(test_albedo_one),
        cmocka_unit_test(test_light_outside),
        cmocka_unit_test(test_directional_and_spot),
        cmocka_unit_test(test_fp16_accumulation),
        cmocka_unit_test(test_extreme_materials),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
