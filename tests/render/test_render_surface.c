/* The objects' surface cache (issue 11, render/passes/surface.h, PIPELINE.md "Surface cache").
 *
 * Composition with render.surface_cache reads B_l per refined vertex instead of running
 * Algorithm 1 per pixel. Asserted:
 *  - a camera move after convergence runs compose and blend alone (no radiosity, no surface
 *    pass) and composition runs no gather; moving back gives the same image bit for bit;
 *  - accumulation frames redraw the cache (the surface pass runs with every radiosity frame);
 *  - switching the cache off is a composition-only change and composition then gathers;
 *  - the cached image against the per-pixel gather of the same maps, over object pixels, for
 *    the candle, the lamp shade and the votive: relative RMSE within the bound of PIPELINE.md,
 *    (sigma_tr h)^2 / 6 (a linear fit's error on B's smooth part, h the edge bound; only where
 *    sigma_tr h < 1, else the measured 0.10 with a margin) plus the per-pixel image's own
 *    sampling noise (the cache is a low-pass
 *    of the same maps: what it drops below the vertex spacing is that noise and detail under
 *    two map texels), the noise measured from a second seed. The figures are printed;
 *    LR_SURFACE_FRAMES=F accumulates F frames instead of 4.
 * The candle's converged renderer serves both the camera-move checks and its comparison with
 * the gather (one accumulation instead of two of the same maps and seed).
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

#include "render/cpu/frame.h"
#include "render/core/surface.h"
#include "render/mesh/bvh.h"
#include "render/mesh/lattice.h"
#include "render/optics/optics.h"
#include "render/renderer.h"
#include "render/renderer_debug.h"
#include "render/schedule.h"
#include "tests/support/gl.h"
#include "tests/support/near.h"
#include "tests/support/render.h"

LR_TEST_GL_FIXTURE(gl) /* tests/support/gl.h: setup(), teardown() */

enum { W = 160, H = 120 };

/* The scenes' own map size (the edge bound is tied to its texels), fewer maps, samples and
 * frames than they ship with; no VPLs (they light the receivers, not the objects). 4 frames:
 * the radiosity passes are 85 % of this binary's time and scale with the frames, while the
 * bound below barely moves with them: the gather's own noise between two seeds at 4, 6 and
 * 12 frames was 0.137, 0.132, 0.117 (candle), 0.150, 0.120, - (lamp shade), 0.184, 0.147, -
 * (votive), and the cache's error rises as the frames fall (candle 0.069, 0.063, 0.038;
 * votive 0.100, 0.086, -), so fewer frames do not make the comparison looser: the cache's
 * error over its bound (fit + noise) at 4 and 6 frames is candle 0.49, 0.47, votive 0.54,
 * 0.57; the lamp shade's 0.135 against its 0.15 (below). The three comparisons cost 88 s CPU
 * at 4 frames, and the radiosity passes' part of that grows with the frames. */
enum { FRAMES = 4 };
/* LR_SURFACE_FRAMES=F (4..4096) accumulates F frames instead of FRAMES (how the cache's error
 * and the noise fall with convergence; not part of the default run). */
static const char *const *test_settings(void)
{
    static char frames[32];
    static const char *s[4] = {"render.K=8", "render.N=4", NULL, NULL};
    const char *f = getenv("LR_SURFACE_FRAMES");
    int n = f ? atoi(f) : FRAMES;
    snprintf(frames, sizeof frames, "render.frames=%d", n >= 4 && n <= 4096 ? n : FRAMES);
    s[2] = frames;
    return s;
}

/* Object pixels (rows bottom up, as the HDR readback): the camera ray meets an object before
 * any receiver. */
static unsigned char *object_mask(const lr_scene *s)
{
    unsigned char *m = calloc((size_t)W * H, 1);
    assert_non_null(m);
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            lr_vec3 org, dir;
            lr_cpu_camera_ray(s, W, H, x, y, &org, &dir);
            double t_obj = INFINITY, t_rcv = INFINITY;
            lr_hit h;
            for (int i = 0; i < lr_scene_object_count(s); i++)
                if (lr_bvh_intersect(lr_scene_object_at(s, i)->bvh, org, dir, 0, t_obj, &h))
                    t_obj = fmin(t_obj, h.t);
            for (int i = 0; i < lr_scene_receiver_count(s); i++)
                if (lr_bvh_intersect(lr_scene_receiver_at(s, i)->bvh, org, dir, 0, t_rcv, &h))
                    t_rcv = fmin(t_rcv, h.t);
            m[(size_t)(H - 1 - y) * W + x] = t_obj < t_rcv;
        }
    return m;
}

/* sqrt(sum (a - b)^2 / sum b^2) over the masked pixels' bands; *worst: the largest |a - b|
 * over the RMS of b there. */
static double rel_rmse(const float *a, const float *b, const unsigned char *m, double *worst)
{
    double num = 0.0, den = 0.0, big = 0.0;
    long n = 0;
    for (size_t i = 0; i < (size_t)W * H; i++) {
        if (!m[i])
            continue;
        for (int c = 0; c < 3; c++) {
            double d = (double)a[3 * i + c] - b[3 * i + c];
            num += d * d;
            den += (double)b[3 * i + c] * b[3 * i + c];
            big = fmax(big, fabs(d));
            n++;
        }
    }
    assert_true(n > 0 && den > 0.0);
    if (worst)
        *worst = big / sqrt(den / n);
    return sqrt(num / den);
}

static bool cache_on_by_default(void)
{
    lr_scene *s = lr_test_scene("candle", NULL, NULL);
    bool on = lr_scene_render(s)->surface_cache;
    lr_scene_destroy(s);
    return on;
}

/* A converged renderer of scene `name` with the cache as asked. */
static lr_renderer *converged(lr_scene *s, unsigned seed, bool cache)
{
    lr_err e = {0};
    unsigned d = 0;
    assert_int_equal(lr_scene_set(s, "render.surface_cache", cache ? "true" : "false", &d, &e),
                     LR_OK);
    lr_renderer *r = lr_test_renderer(gl, s, W, H, true, seed);
    lr_test_converge(r, 5000);
    assert_false(lr_renderer_needs_frame(r));
    return r;
}

/* Sets key = value (none when key is NULL), runs a frame and asserts its passes and whether
 * the objects were gathered per pixel (else composed from the cache). */
static void expect_frame(lr_scene *s, lr_renderer *r, const char *key, const char *value,
                         unsigned passes, bool gathered)
{
    if (key)
        lr_test_set(s, r, key, value);
    lr_frame_stats st = lr_test_frame(r);
    assert_int_equal(st.passes, passes);
    assert_int_equal(lr_renderer_debug_compose_gathered(r), gathered);
}

/* The camera moved 40 mm sideways and 20 mm up, and back where it was, as "x,y,z" values. */
static void camera_moves(const lr_scene *s, char moved[96], char back[96])
{
    lr_vec3 c0 = lr_scene_camera(s)->position;
    snprintf(moved, 96, "%.17g,%.17g,%.17g", c0.x + 40.0, c0.y, c0.z + 20.0);
    snprintf(back, 96, "%.17g,%.17g,%.17g", c0.x, c0.y, c0.z);
}

/* The candle's renderer with the cache on, accumulated to convergence: every accumulation
 * frame redraws the cache from the maps it just updated. Then, converged: a camera move and
 * back run compose and blend alone (no radiosity, no surface pass, no gather) and give the
 * image from before the moves bit for bit; the cache off is composition alone again, now
 * with the per-pixel gather (that image is returned in *gathered); on again, the cache is
 * still that of the current maps, so no surface pass. Returns the cached image. */
static float *camera_moves_run_no_gather(lr_scene *s, lr_renderer *r, float **gathered)
{
    for (int f = 0; lr_renderer_needs_frame(r); f++) {
        lr_frame_stats st = lr_test_frame(r);
        assert_true(st.passes & LR_PASS_RADIOSITY);
        assert_true(st.passes & LR_PASS_SURFACE);
        assert_false(lr_renderer_debug_compose_gathered(r));
        assert_true(f < 100);
    }
    lr_debug_surface_info si;
    lr_renderer_debug_surface_info(r, &si);
    print_message("candle: %d cache entries, edge bound %.3f mm\n", si.entries, si.h[0]);
    assert_true(si.entries > 0 && si.h[0] > 0.0);
    float *before = lr_test_hdr(r);
    char moved[96], back[96];
    camera_moves(s, moved, back);
    enum { VIEW = LR_PASS_COMPOSE | LR_PASS_BLEND };
    expect_frame(s, r, "camera.position", moved, VIEW, false);
    expect_frame(s, r, "camera.position", back, VIEW, false);
    float *after = lr_test_hdr(r);
    assert_memory_equal(before, after, (size_t)W * H * 3 * sizeof *before);
    expect_frame(s, r, "render.surface_cache", "false", VIEW, true);
    *gathered = lr_test_hdr(r);
    expect_frame(s, r, "render.surface_cache", "true", VIEW, false);
    free(after);
    return before;
}

/* The cache was off while the maps accumulated: switching it on draws it first. */
static void test_cache_follows_the_maps(void **state)
{
    (void)state;
    lr_scene *s = lr_test_scene("candle", lr_test_small_settings, NULL);
    lr_renderer *r = converged(s, 3, false);
    lr_test_set(s, r, "render.surface_cache", "true");
    lr_frame_stats st = lr_test_frame(r);
    assert_int_equal(st.passes, LR_PASS_SURFACE | LR_PASS_COMPOSE | LR_PASS_BLEND);
    /* A material change restarts the maps: the cache is redrawn (and its meshes refined again
     * for the new sigma_tr). */
    lr_test_set(s, r, "objects[0].material", "marble");
    st = lr_test_frame(r);
    assert_true(st.passes & LR_PASS_RADIOSITY);
    assert_true(st.passes & LR_PASS_SURFACE);
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
}

/* The cached image against the per-pixel gather of the same maps, and the gather's own
 * noise from a second seed. */
static void cache_against_gather(const char *name, bool camera_moves_too)
{
    lr_scene *s = lr_test_scene(name, test_settings(), NULL);
    unsigned char *m = object_mask(s);
    float *cached, *gathered;
    lr_renderer *r;
    lr_debug_surface_info si;
    if (camera_moves_too) {
        lr_err e = {0};
        unsigned d = 0;
        assert_int_equal(lr_scene_set(s, "render.surface_cache", "true", &d, &e), LR_OK);
        r = lr_test_renderer(gl, s, W, H, true, 3);
        cached = camera_moves_run_no_gather(s, r, &gathered);
        lr_renderer_debug_surface_info(r, &si);
    } else {
        r = converged(s, 3, true);
        cached = lr_test_hdr(r);
        lr_renderer_debug_surface_info(r, &si);
        lr_test_set(s, r, "render.surface_cache", "false");
        lr_test_frame(r);
        assert_true(lr_renderer_debug_compose_gathered(r));
        gathered = lr_test_hdr(r);
    }
    lr_renderer *r2 = converged(s, 11, false);
    float *other = lr_test_hdr(r2);
    double worst_c, worst_n;
    double err = rel_rmse(cached, gathered, m, &worst_c);
    double noise = rel_rmse(other, gathered, m, &worst_n) / sqrt(2.0);
    /* The smooth part's bound with the largest sigma_tr of the scene's objects; it holds
     * where B is smooth over an edge (sigma_tr h < 1). Where it is not (the lamp shade's
     * porcelain: 1/sigma_tr 0.55 mm against h 2.2 mm) nothing is derived: the part of the
     * error that does not fall with convergence was measured, 0.10 (PIPELINE.md "Surface
     * cache", 12 and 48 frames; 0.125 at 6 frames, 0.135 at the 4 here), and 0.15 is
     * asserted. */
    double fit = 0.0;
    bool smooth = true;
    for (int i = 0; i < lr_scene_object_count(s); i++) {
        double st = 0.0;
        for (int c = 0; c < 3; c++)
            st = fmax(st, lr_scene_object_at(s, i)->coeffs.sigma_tr[c]);
        double sh = st * si.h[i];
        smooth = smooth && sh < 1.0;
        fit = fmax(fit, sh * sh / 6.0);
    }
    print_message("%s (%dx%d, K 8, N 4, %d frames, map %d): cache vs per-pixel gather: "
                  "relative RMSE %.4f, max %.3f x RMS; the gather's own noise %.4f (max %.3f x "
                  "RMS); smooth-part bound %.5f; %d entries, h %.3f mm\n",
                  name, W, H, lr_scene_render(s)->frames, lr_scene_render(s)->map_size, err,
                  worst_c, noise, worst_n, fit, si.entries, si.h[0]);
    assert_true(smooth ? err <= fit + noise : err <= 0.15);
    free(cached);
    free(gathered);
    free(other);
    free(m);
    lr_renderer_destroy(r);
    lr_renderer_destroy(r2);
    lr_scene_destroy(s);
}

/* With the camera-move checks on the same converged renderer (camera_moves_run_no_gather). */
static void test_candle_cache_vs_gather(void **state)
{
    (void)state;
    cache_against_gather("candle", true);
}

static void test_lampshade_cache_vs_gather(void **state)
{
    (void)state;
    cache_against_gather("lampshade", false);
}

static void test_votive_cache_vs_gather(void **state)
{
    (void)state;
    cache_against_gather("votive", false);
}

/* The CPU twin follows the cache (render/cpu/frame.c with the scene's render.surface_cache:
 * B at the same refined vertices, interpolated at the hit): a 32 x 24 image of the candle
 * against the GPU's, object pixels summed, within 4 sigma of the twin's variance image + 5 %
 * (test_render_parity's final-image rule), and against the twin's own per-pixel image. */
static void test_twin_follows_cache(void **state)
{
    (void)state;
    enum { TW = 32, TH = 24 };
    static const char *const small[] = {"render.K=8",          "render.N=4",
                                        "render.map_size=64",  "render.gbuffer_size=128",
                                        "render.frames=4",     "render.surface_cache=true",
                                        NULL};
    lr_scene *s = lr_test_scene("candle", small, NULL);
    lr_renderer *r = lr_test_renderer(gl, s, TW, TH, true, 3);
    lr_test_converge(r, 20);
    assert_false(lr_renderer_debug_compose_gathered(r));
    float *hdr = lr_test_hdr(r);
    lr_cpu_render_desc d = {.scene = s, .width = TW, .height = TH, .mode = LR_CPU_PASS,
                            .no_vpl = true};
    lr_image twin, var, plain;
    lr_err e = {0};
    if (lr_cpu_render(&d, &twin, &var, NULL, &e))
        fail_msg("%s", e.msg);
    unsigned dirty = 0;
    assert_int_equal(lr_scene_set(s, "render.surface_cache", "false", &dirty, &e), LR_OK);
    if (lr_cpu_render(&d, &plain, NULL, NULL, &e))
        fail_msg("%s", e.msg);
    double g = 0.0, c = 0.0, p = 0.0, v = 0.0;
    for (int y = 0; y < TH; y++)
        for (int x = 0; x < TW; x++) {
            lr_vec3 org, dir;
            lr_cpu_camera_ray(s, TW, TH, x, y, &org, &dir);
            lr_hit h;
            if (!lr_bvh_intersect(lr_scene_object_at(s, 0)->bvh, org, dir, 0, INFINITY, &h))
                continue;
            size_t k = (size_t)y * TW + x;
            for (int b = 0; b < 3; b++) {
                g += hdr[3 * ((size_t)(TH - 1 - y) * TW + x) + b];
                c += twin.rgb[3 * k + b];
                p += plain.rgb[3 * k + b];
                v += 2.0 * var.rgb[3 * k + b];
            }
        }
    print_message("candle 32x24, cache on: GPU %.5g, CPU twin %.5g (%+.2f %%, sigma %.2f %%); "
                  "twin per pixel %.5g (%+.2f %%)\n", g, c, 100 * (g / c - 1),
                  100 * sqrt(v) / c, p, 100 * (c / p - 1));
    assert_near(g, c, 4.0 * sqrt(v) + 0.05 * c);
    assert_true(fabs(c / p - 1.0) < 0.10);
    free(hdr);
    lr_image_free(&twin);
    lr_image_free(&var);
    lr_image_free(&plain);
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* The per-pixel lookup (compose_cached.frag) is the CPU's lattice interpolation
 * (lr_lattice_locate) of the GPU's own entries: at every object pixel of the candle whose
 * centre ray hits the mesh, the image divided by F_t(w_o) / pi times the interpolated B is,
 * per band, the light's intensity times the cavity gain (constant over the object). What
 * separates the two is float rounding: the rasteriser's fp32 barycentrics and positions
 * against the ray's doubles, and F_t(w_o) evaluated in fp32 (steep near grazing): measured
 * 1.2e-4 at the 95th percentile. A lookup of the wrong sub-triangle, or with wrong weights,
 * is off by B's change across a sub-triangle: B falls as exp(-sigma_tr r), sigma_tr h =
 * 0.125 x 1.085 = 0.14 at most, and beyond 1e-2 wherever B's gradient is a tenth of that.
 * The median is asserted within 1e-4 and the 95th percentile within 1e-3. The last 5 %
 * are not asserted: at a silhouette the rasteriser and the ray may see different triangles. */
static void test_lookup_is_lattice_interpolation(void **state)
{
    (void)state;
    enum { TW = 160, TH = 120 };
    static const char *const small[] = {"render.K=4", "render.N=1", "render.frames=2",
                                        "render.surface_cache=true", NULL};
    lr_scene *s = lr_test_scene("candle", small, NULL);
    lr_renderer *r = lr_test_renderer(gl, s, TW, TH, true, 3);
    lr_test_converge(r, 4);
    assert_false(lr_renderer_debug_compose_gathered(r));
    float *hdr = lr_test_hdr(r);
    lr_debug_surface_info si;
    lr_renderer_debug_surface_info(r, &si);
    float *B = malloc((size_t)si.entries * 4 * sizeof *B);
    assert_non_null(B);
    lr_err e = {0};
    if (lr_renderer_debug_read_surface(r, 0, B, &e))
        fail_msg("%s", e.msg);
    lr_refined ref;
    double h;
    if (lr_surface_refine(s, 0, lr_scene_render(s)->map_size, LR_SURFACE_MAX_VERTICES, &ref, &h,
                          &e))
        fail_msg("%s", e.msg);
    assert_int_equal((int)ref.nv, si.nv[0]);
    const lr_scene_object *o = lr_scene_object_at(s, 0);
    const float *N = lr_mesh_normals(o->mesh);
    const uint32_t *ix = lr_mesh_indices(o->mesh);
    double *q[3];
    for (int b = 0; b < 3; b++) {
        q[b] = malloc((size_t)TW * TH * sizeof *q[b]);
        assert_non_null(q[b]);
    }
    int n = 0;
    for (int y = 0; y < TH; y++)
        for (int x = 0; x < TW; x++) {
            lr_vec3 org, dir;
            lr_cpu_camera_ray(s, TW, TH, x, y, &org, &dir);
            lr_hit hit;
            if (!lr_bvh_intersect(o->bvh, org, dir, 0, INFINITY, &hit))
                continue;
            double w[3], Bi[3] = {0, 0, 0};
            size_t k = lr_lattice_locate(&ref, hit.triangle, hit.u, hit.v, w);
            for (int j = 0; j < 3; j++)
                for (int b = 0; b < 3; b++)
                    Bi[b] += w[j] * B[4 * (size_t)ref.idx[3 * k + (size_t)j] + (size_t)b];
            const uint32_t *c = ix + 3 * hit.triangle;
            double wn[3] = {1.0 - hit.u - hit.v, hit.u, hit.v};
            lr_vec3 nn = lr_v3(0, 0, 0);
            for (int j = 0; j < 3; j++)
                nn = lr_v3_add(nn, lr_v3_scale(lr_v3(N[3 * c[j]], N[3 * c[j] + 1], N[3 * c[j] + 2]),
                                               wn[j]));
            nn = lr_v3_normalize(nn);
            double sf = lr_fresnel_transmittance(fabs(lr_v3_dot(nn, dir)), o->coeffs.eta) / M_PI;
            const float *px = hdr + 3 * ((size_t)(TH - 1 - y) * TW + (size_t)x);
            if (!(Bi[0] > 0.0 && Bi[1] > 0.0 && Bi[2] > 0.0 && sf > 0.0))
                continue;
            for (int b = 0; b < 3; b++)
                q[b][n] = px[b] / (sf * Bi[b]);
            n++;
        }
    assert_true(n > 1000);
    int worst_bad = 0;
    double worst_p95 = 0.0, worst_med = 0.0;
    for (int b = 0; b < 3; b++) {
        double *d = malloc((size_t)n * sizeof *d);
        assert_non_null(d);
        memcpy(d, q[b], (size_t)n * sizeof *d);
        qsort(d, (size_t)n, sizeof *d, cmp_double);
        double med = d[n / 2];
        int bad = 0;
        for (int i = 0; i < n; i++) {
            d[i] = fabs(q[b][i] / med - 1.0);
            bad += d[i] > 1e-4;
        }
        qsort(d, (size_t)n, sizeof *d, cmp_double);
        worst_p95 = fmax(worst_p95, d[(int)(0.95 * n)]);
        worst_med = fmax(worst_med, d[n / 2]);
        worst_bad = bad > worst_bad ? bad : worst_bad;
        free(d);
    }
    print_message("candle %dx%d, cache lookup against the CPU's lattice interpolation of the "
                  "GPU's entries: %d object pixels, |ratio / median - 1| median %.2e, 95th "
                  "percentile %.2e, %d pixels beyond 1e-4 (worst band)\n",
                  TW, TH, n, worst_med, worst_p95, worst_bad);
    assert_true(worst_med < 1e-4);
    assert_true(worst_p95 < 1e-3);
    for (int b = 0; b < 3; b++)
        free(q[b]);
    lr_refined_free(&ref);
    free(B);
    free(hdr);
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
}

static void test_default(void **state)
{
    (void)state;
    /* Off by default (PIPELINE.md "Surface cache": its error is 0.7-0.9 of the converged noise
     * on the candle and the votive, above the 48-frame noise on the lamp shade) for the still
     * image; on for camera moves (render.surface_cache_moves). */
    assert_false(cache_on_by_default());
    lr_scene *s = lr_test_scene("candle", NULL, NULL);
    assert_true(lr_scene_render(s)->surface_cache_moves);
    lr_scene_destroy(s);
}

/* render.surface_cache_moves (the default): a camera move on converged maps composes from
 * the cache, drawn at the first move; the frame after it composes again with the gather, and
 * that still image is the gather's to the bit. */
static void test_moves_from_cache_still_gathered(void **state)
{
    (void)state;
    lr_scene *s = lr_test_scene("candle", lr_test_small_settings, NULL);
    lr_renderer *r = converged(s, 3, false);
    assert_true(lr_renderer_debug_compose_gathered(r));
    float *before = lr_test_hdr(r);
    char moved[96], back[96];
    camera_moves(s, moved, back);
    enum { VIEW = LR_PASS_COMPOSE | LR_PASS_BLEND };
    /* The first move draws the cache from the converged maps, then composes from it. */
    expect_frame(s, r, "camera.position", moved, LR_PASS_SURFACE | VIEW, false);
    float *moving = lr_test_hdr(r);
    /* That image is the always-on cache's: switching it on composes the same (no surface
     * pass: the cache is that of the current maps). */
    expect_frame(s, r, "render.surface_cache", "true", VIEW, false);
    float *cached = lr_test_hdr(r);
    assert_memory_equal(moving, cached, (size_t)W * H * 3 * sizeof *moving);
    /* Turning it off is not a move: the gather at once. */
    expect_frame(s, r, "render.surface_cache", "false", VIEW, true);
    assert_false(lr_renderer_needs_frame(r));
    /* Moving back: the cache is current, so composition and blend alone ... */
    expect_frame(s, r, "camera.position", back, VIEW, false);
    /* ... then the still frame: gathered per pixel, the image from before the moves. */
    assert_true(lr_renderer_needs_frame(r));
    expect_frame(s, r, NULL, NULL, VIEW, true);
    assert_false(lr_renderer_needs_frame(r));
    float *after = lr_test_hdr(r);
    assert_memory_equal(before, after, (size_t)W * H * 3 * sizeof *before);
    /* A dimmer right after a move composes the still image too (the blend alone would
     * weight the moving images). */
    expect_frame(s, r, "camera.position", moved, VIEW, false);
    expect_frame(s, r, "light.intensity", "0.002", VIEW, true);
    /* Off: a move gathers, and nothing follows it. */
    lr_test_set(s, r, "render.surface_cache_moves", "false");
    expect_frame(s, r, "camera.position", back, VIEW, true);
    assert_false(lr_renderer_needs_frame(r));
    free(before);
    free(moving);
    free(cached);
    free(after);
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
}

/* While the maps accumulate a camera move gathers (the cache would be redrawn every frame). */
static void test_moves_while_accumulating_gather(void **state)
{
    (void)state;
    lr_scene *s = lr_test_scene("candle", lr_test_small_settings, NULL);
    lr_renderer *r = lr_test_renderer(gl, s, W, H, true, 3);
    lr_test_frame(r);
    assert_true(lr_renderer_needs_frame(r));
    lr_test_set(s, r, "camera.position", "100,-400,250");
    lr_frame_stats st = lr_test_frame(r);
    assert_true(st.passes & LR_PASS_RADIOSITY);
    assert_false(st.passes & LR_PASS_SURFACE);
    assert_true(lr_renderer_debug_compose_gathered(r));
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
}

int main(void)
{
    if (getenv("LR_TEST_FILTER")) /* e.g. LR_TEST_FILTER='*votive*' to run one test */
        cmocka_set_test_filter(getenv("LR_TEST_FILTER"));
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_default),
        cmocka_unit_test(test_moves_from_cache_still_gathered),
        cmocka_unit_test(test_moves_while_accumulating_gather),
        cmocka_unit_test(test_cache_follows_the_maps),
        cmocka_unit_test(test_twin_follows_cache),
        cmocka_unit_test(test_lookup_is_lattice_interpolation),
        cmocka_unit_test(test_candle_cache_vs_gather),
        cmocka_unit_test(test_lampshade_cache_vs_gather),
        cmocka_unit_test(test_votive_cache_vs_gather),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
