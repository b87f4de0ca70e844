/* CPU twin, passes 2-4 as a whole (render/cpu/maps.h, vpl.h, frame.h): map texels, progressive
 * convergence against the reference (1, 4, 16, 64 frames), Algorithm 1, VPL placement and
 * areas, direct light and shadows on receivers, emergent light where the light cannot reach,
 * and whole images (twin and reference) that stay finite on every shipped scene. */
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
#include "render/cpu/frame.h"
#include "render/cpu/maps.h"
#include "render/base/rng.h"
#include "render/core/vpl.h"
#include "render/material/material.h"
#include "tests/support/near.h"
#include "tests/support/objects.h"

static lr_medium preset(const char *name)
{
    lr_material m;
    lr_err e = {0};
    if (lr_material_find(name, &m, &e))
        fail_msg("%s", e.msg);
    return m.medium;
}

static lr_scene *load(const char *name)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/scenes/%s.json", lr_configs_dir(), name);
    lr_scene *s;
    lr_err e = {0};
    if (lr_scene_load(path, NULL, &s, &e))
        fail_msg("%s", e.msg);
    return s;
}

/* The lamp-shade-like configuration where the pass is unbiased: marble shell R 40 with a 37 mm
 * cavity, the light at its centre. */
static void shell(lrt_object *o, lr_light *l)
{
    lr_medium m = preset("marble");
    lrt_object_make(lrt_shell_mesh(40, 37, 4), &m, o);
    *l = lrt_point_light(lr_v3(0, 0, 0));
}

/* Texels: every valid texel holds a point of the outer sphere (|x| = 40 within the facets'
 * sag, 0.05 mm at 4 subdivisions) facing the map (n . d_k > 0), at the depth of its distance
 * from the eye plane; the covered fraction of the map is the disk's pi/4 within 5 %. */
static void test_map_texels(void **state)
{
    (void)state;
    lrt_object o;
    lr_light l;
    shell(&o, &l);
    lr_cpu_maps_desc d = {.object = &o.obj, .light = &l, .K = 4, .map_size = 32, .N = 1};
    lr_cpu_maps *m;
    lr_err e = {0};
    assert_int_equal(lr_cpu_maps_create(&d, &m, &e), 0);
    for (int k = 0; k < 4; k++) {
        lr_vec3 dk = lr_cpu_maps_direction(m, k), eye, right, up;
        lr_vec3 want = lr_halton_sphere((unsigned)k + 1);
        assert_near(dk.x, want.x, 1e-15);
        lr_cpu_maps_basis(m, k, &eye, &right, &up);
        int valid = 0;
        for (int j = 0; j < 32; j++)
            for (int i = 0; i < 32; i++) {
                const lr_cpu_texel *t = lr_cpu_maps_texel(m, k, i, j);
                if (!t->valid)
                    continue;
                valid++;
                assert_near(lr_v3_len(t->x), 40.0, 0.1);
                assert_true(lr_v3_dot(t->n, dk) > 0.0);
                assert_near(t->depth, lr_v3_dot(lr_v3_sub(eye, t->x), dk), 1e-9);
            }
        assert_near_rel(valid / 1024.0, M_PI / 4.0, 0.05);
    }
    assert_null(lr_cpu_maps_texel(m, 4, 0, 0));
    lr_cpu_maps_destroy(m);
    lrt_object_free(&o);
}

/* Progressive convergence (issue 3): RMS relative error of map 0's texels against the
 * reference after 1, 4, 16, 64 frames of N = 4 falls like F^-1/2 (slope -0.5 within 0.1). The
 * reference's own variance (2048 samples per texel) is subtracted from the mean squared error,
 * so what is measured is the twin's error alone. */
static void test_progressive_convergence(void **state)
{
    (void)state;
    lrt_object o;
    lr_light l;
    shell(&o, &l);
    const int S = 12;
    lr_cpu_maps_desc d = {.object = &o.obj, .light = &l, .K = 1, .map_size = S, .N = 4};
    lr_cpu_maps *m;
    assert_int_equal(lr_cpu_maps_create(&d, &m, NULL), 0);
    double ref[12 * 12][3], rvar[12 * 12][3];
    lr_cpu_radiosity_desc rd = {.N = 2048, .sampler = LR_CPU_REFERENCE};
    for (int t = 0; t < S * S; t++) {
        const lr_cpu_texel *tx = lr_cpu_maps_texel(m, 0, t % S, t / S);
        if (!tx->valid)
            continue;
        lr_cpu_estimate est;
        lr_cpu_radiosity(&o.obj, &l, tx->x, tx->n, &rd, lr_rng_key(99, (uint64_t)t, 0, 0), &est);
        for (int c = 0; c < 3; c++) {
            ref[t][c] = est.mean[c];
            rvar[t][c] = est.var[c] / est.n;
        }
    }
    const int frames[] = {1, 4, 16, 64};
    double lx[4], ly[4];
    for (int f = 0; f < 4; f++) {
        lr_cpu_maps_accumulate(m, frames[f] - lr_cpu_maps_frames(m));
        assert_int_equal(lr_cpu_maps_frames(m), frames[f]);
        double se = 0, n = 0;
        for (int t = 0; t < S * S; t++) {
            const lr_cpu_texel *tx = lr_cpu_maps_texel(m, 0, t % S, t / S);
            if (!tx->valid)
                continue;
            assert_int_equal(tx->samples, 4L * frames[f]);
            for (int c = 0; c < 3; c++) {
                double dlt = (tx->mean[c] - ref[t][c]) / ref[t][c];
                se += dlt * dlt - rvar[t][c] / (ref[t][c] * ref[t][c]);
                n++;
            }
        }
        double rms = sqrt(fmax(se / n, 1e-30));
        print_message("%2d frames: RMS relative error %.4f\n", frames[f], rms);
        lx[f] = log(frames[f]);
        ly[f] = log(rms);
    }
    double mx = (lx[0] + lx[1] + lx[2] + lx[3]) / 4, my = (ly[0] + ly[1] + ly[2] + ly[3]) / 4;
    double sxx = 0, sxy = 0;
    for (int f = 0; f < 4; f++) {
        sxx += (lx[f] - mx) * (lx[f] - mx);
        sxy += (lx[f] - mx) * (ly[f] - my);
    }
    print_message("slope %.3f\n", sxy / sxx);
    assert_near(sxy / sxx, -0.5, 0.1);
    lr_cpu_maps_destroy(m);
    lrt_object_free(&o);
}

/* Algorithm 1 on the shell with the light at its centre, where B is the same everywhere on the
 * outer surface by symmetry (up to facets): at 64 surface points in all directions, 16 maps of
 * 24^2, the composed B is never a fallback and agrees with the reference within 4 sigma + 3 %
 * (the bilinear blend of neighbouring texels over a faceted sphere). Same seed, same maps:
 * the result does not depend on the number of threads. */
static void test_compose_uniform_sphere(void **state)
{
    (void)state;
    lrt_object o;
    lr_light l;
    shell(&o, &l);
    lr_cpu_maps_desc d = {.object = &o.obj, .light = &l, .K = 16, .map_size = 24, .N = 16,
                          .threads = 1};
    lr_cpu_maps *m, *m2;
    assert_int_equal(lr_cpu_maps_create(&d, &m, NULL), 0);
    d.threads = 2;
    assert_int_equal(lr_cpu_maps_create(&d, &m2, NULL), 0);
    lr_cpu_maps_accumulate(m, 2);
    lr_cpu_maps_accumulate(m2, 2);
    lr_cpu_radiosity_desc rd = {.N = 20000, .sampler = LR_CPU_REFERENCE};
    lr_cpu_estimate ref;
    lr_vec3 xo, no;
    assert_true(lr_first_surface(&o.obj, lr_v3(0, 0, 100), lr_v3(0, 0, -1), 0, &xo, &no));
    lr_cpu_radiosity(&o.obj, &l, xo, no, &rd, 5, &ref);
    for (int p = 0; p < 64; p++) {
        lr_vec3 u = lr_halton_sphere((unsigned)p + 100);
        assert_true(lr_first_surface(&o.obj, lr_v3_scale(u, 100), lr_v3_scale(u, -1), 0, &xo, &no));
        double B[3], V[3], B2[3];
        bool fb = true;
        lr_cpu_maps_compose(m, xo, no, B, V, &fb);
        lr_cpu_maps_compose(m2, xo, no, B2, NULL, NULL);
        assert_false(fb);
        for (int c = 0; c < 3; c++) {
            assert_true(B[c] == B2[c]);
            assert_near(B[c], ref.mean[c], 4.0 * sqrt(V[c] + ref.var[c] / ref.n) + 0.03 * ref.mean[c]);
        }
    }
    lr_cpu_maps_destroy(m);
    lr_cpu_maps_destroy(m2);
    lrt_object_free(&o);
}

/* VPLs on a sphere of radius 40: every one valid, on the surface, normal outward, and the areas
 * sum to the sphere's area (4 pi R^2 (4 pi / N) sum 1/|n.u| with n = u: exactly 4 pi R^2 up to
 * facets, 0.5 %). On the open lamp shade some directions leave through the openings: fewer
 * VPLs, each still on the outer surface. */
static void test_vpl_placement(void **state)
{
    (void)state;
    lrt_object o;
    lr_light l;
    shell(&o, &l);
    lr_vpl_point v[256];
    lr_vpl_place(&o.obj, 256, v);
    double area = 0;
    for (int i = 0; i < 256; i++) {
        assert_true(v[i].valid);
        assert_near(lr_v3_len(v[i].x), 40.0, 0.1);
        assert_true(lr_v3_dot(v[i].n, v[i].u) > 0.99);
        area += v[i].area;
    }
    assert_near_rel(area, 4 * M_PI * 40 * 40, 5e-3);
    lrt_object_free(&o);

    lr_scene *s = load("lampshade");
    const lr_scene_object *sh = lr_scene_object_at(s, 0);
    lr_vpl_place(sh, 256, v);
    int valid = 0;
    for (int i = 0; i < 256; i++) {
        if (!v[i].valid)
            continue;
        valid++;
        assert_true(lr_v3_dot(lr_v3_sub(v[i].x, sh->center), v[i].u) > 0.0);
        assert_true(v[i].area > 0.0 && isfinite(v[i].area));
    }
    print_message("lampshade: %d of 256 VPL directions meet the shade\n", valid);
    assert_true(valid > 100 && valid < 256);
    lr_scene_destroy(s);
}

/* Receivers in the candle scene: a wall point above the rim sees the flame (direct irradiance
 * I cos / d^2, exact), a table point beside the candle's foot is in its shadow (0 direct); the
 * VPLs light it (E_vpl > 0): the emergent light of issue 3's first test, on the CPU. */
static void test_receivers_direct_shadow_vpl(void **state)
{
    (void)state;
    lr_scene *s = load("candle");
    const lr_light *fl = lr_scene_light_at(s, 0);
    lr_vec3 wall = lr_v3(0, 250, 300), nw = lr_v3(0, -1, 0);
    lr_vec3 to = lr_v3_sub(fl->position, wall);
    double d = lr_v3_len(to);
    assert_near_rel(lr_direct_irradiance(s, fl, wall, nw), lr_v3_dot(nw, to) / (d * d * d), 1e-12);
    lr_vec3 table = lr_v3(0, -60, 0), nt = lr_v3(0, 0, 1);
    assert_true(lr_direct_irradiance(s, fl, table, nt) == 0.0);

    const lr_scene_object *o = lr_scene_object_at(s, 0);
    lr_vpl_point v[64];
    lr_vpl_place(o, 64, v);
    for (int i = 0; i < 64; i++)
        if (v[i].valid)
            for (int c = 0; c < 3; c++)
                v[i].B[c] = 1.0; /* unit radiosity: the geometry alone */
    double E[3] = {0};
    lr_vpl_point_irradiance(v, 64, o->coeffs.eta, table, nt, E, NULL);
    print_message("table point in the candle's shadow: E_vpl = %.4g per unit B\n", E[0]);
    assert_true(E[0] > 0.0 && isfinite(E[0]));
    /* Bounded geometry term: a receiver point on a VPL gets at most F_t B / pi * cos_v cos_x. */
    double Eon[3] = {0};
    lr_vec3 xv = lr_v3_add(v[0].x, lr_v3_scale(v[0].n, 1e-9));
    lr_vpl_point_irradiance(v, 1, o->coeffs.eta, xv, lr_v3_scale(v[0].n, -1.0), Eon, NULL);
    assert_true(isfinite(Eon[0]) && Eon[0] <= 1.0 / M_PI + 1e-12);
    lr_scene_destroy(s);
}

static void scan_finite(const lr_image *img, const char *what)
{
    for (long i = 0; i < 3L * img->width * img->height; i++)
        if (!isfinite(img->rgb[i]) || img->rgb[i] < 0.0f)
            fail_msg("%s: value %g at %ld", what, (double)img->rgb[i], i / 3);
}

/* Whole images of every shipped scene, twin and reference, at 24 x 18 with small settings:
 * no NaN, no Inf, no negative value in radiance or variance; some object pixels; the twin's
 * mean over object pixels within 25 % of the reference's (the pass's blind spots -- x_o facing
 * away from the light, texels near the light -- and 2 frames of noise are in that). */
static void test_images_all_scenes(void **state)
{
    (void)state;
    const char *names[] = {"candle", "lampshade", "sphere", "votive", "jar_candle"};
    for (int i = 0; i < 5; i++) {
        lr_scene *s = load(names[i]);
        lr_cpu_render_desc d = {.scene = s, .width = 24, .height = 18, .mode = LR_CPU_PASS,
                                .frames = 2, .K = 8, .map_size = 24, .N = 8, .vpl_count = 32};
        lr_image twin, tvar, ref, rvar;
        lr_cpu_render_stats ts, rs;
        lr_err e = {0};
        if (lr_cpu_render(&d, &twin, &tvar, &ts, &e))
            fail_msg("%s", e.msg);
        d.mode = LR_CPU_REFERENCE;
        d.samples = 64;
        if (lr_cpu_render(&d, &ref, &rvar, &rs, &e))
            fail_msg("%s", e.msg);
        scan_finite(&twin, "twin");
        scan_finite(&tvar, "twin variance");
        scan_finite(&ref, "reference");
        scan_finite(&rvar, "reference variance");
        assert_true(ts.object_pixels > 0 && ts.object_pixels == rs.object_pixels);
        double st = 0, sr = 0;
        for (long p = 0; p < 24 * 18; p++)
            for (int c = 0; c < 3; c++) {
                st += twin.rgb[3 * p + c];
                sr += ref.rgb[3 * p + c];
            }
        print_message("%s: %ld object pixels (%ld fallback), image mean twin %.4g reference %.4g "
                      "(%+.1f %%), reference %.3g samples/s\n", names[i], ts.object_pixels,
                      ts.fallback_pixels, st, sr, sr > 0 ? 100 * (st / sr - 1) : 0.0,
                      rs.samples_per_s);
        if (sr > 0)
            assert_near_rel(st, sr, 0.25);
        else
            assert_true(st == 0.0); /* sphere.json: light in the medium, see test_cpu_energy */
        lr_image_free(&twin);
        lr_image_free(&tvar);
        lr_image_free(&ref);
        lr_image_free(&rvar);
        lr_scene_destroy(s);
    }
}

int main(void)
{
    if (getenv("LR_TEST_FILTER"))
        cmocka_set_test_filter(getenv("LR_TEST_FILTER"));
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_map_texels),
        cmocka_unit_test(test_progressive_convergence),
        cmocka_unit_test(test_compose_uniform_sphere),
        cmocka_unit_test(test_vpl_placement),
        cmocka_unit_test(test_receivers_direct_shadow_vpl),
        cmocka_unit_test(test_images_all_scenes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
