/* The passes' intermediate results through render/renderer_debug.h: the light G-buffer cube
 * map agrees with GL's cube-map lookup convention (what the radiosity shader's texture() on a
 * samplerCube reads is what the face draws put there), the radiosity maps' world -> texture
 * matrices P_k put each texel's x_o on that texel, and the VPLs sit on their fixed directions
 * and do not move when the material or the dimmer changes; new settings (a preview's and back)
 * keep the CPU solvers' keyed states. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/mat4.h"
#include "render/renderer.h"
#include "render/renderer_debug.h"
#include "tests/support/gl.h"
#include "tests/support/near.h"
#include "tests/support/render.h"

LR_TEST_GL_FIXTURE(gl) /* tests/support/gl.h: setup(), teardown() */

/* GL's cube-map face and (s, t) for direction v (OpenGL ES 3.1, "Cube Map Texture Selection"). */
static void cube_select(lr_vec3 v, int *face, double *s, double *t)
{
    double ax = fabs(v.x), ay = fabs(v.y), az = fabs(v.z), sc, tc, ma;
    if (ax >= ay && ax >= az) {
        *face = v.x > 0 ? 0 : 1;
        sc = v.x > 0 ? -v.z : v.z;
        tc = -v.y;
        ma = ax;
    } else if (ay >= az) {
        *face = v.y > 0 ? 2 : 3;
        sc = v.x;
        tc = v.y > 0 ? v.z : -v.z;
        ma = ay;
    } else {
        *face = v.z > 0 ? 4 : 5;
        sc = v.z > 0 ? v.x : -v.x;
        tc = -v.y;
        ma = az;
    }
    *s = 0.5 * (sc / ma + 1.0);
    *t = 0.5 * (tc / ma + 1.0);
}

static void test_gbuffer_cube_matches_gl_lookup(void **state)
{
    lr_scene *s = lr_test_scene("candle", lr_test_small_settings, NULL);
    lr_renderer *r = lr_test_renderer(gl, s, 16, 12, true, 1);
    lr_test_frame(r);
    lr_debug_gbuffer_info gi;
    lr_renderer_debug_gbuffer_info(r, &gi);
    assert_true(gi.cube); /* the flame is in the melt pool */
    int n = gi.size;
    float *pos = malloc((size_t)n * n * 3 * sizeof *pos), *nrm = malloc((size_t)n * n * 3 * sizeof *nrm);
    int *obj = malloc((size_t)n * n * sizeof *obj);
    lr_err e = {0};
    int filled = 0, exact = 0, facing = 0;
    for (int f = 0; f < 6; f++) {
        if (lr_renderer_debug_read_gbuffer(r, f, pos, nrm, obj, &e))
            fail_msg("%s", e.msg);
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++) {
                size_t k = (size_t)j * n + i;
                if (obj[k] < 0)
                    continue;
                assert_int_equal(obj[k], 0);
                filled++;
                lr_vec3 p = lr_v3(pos[3 * k], pos[3 * k + 1], pos[3 * k + 2]);
                lr_vec3 v = lr_v3_sub(p, gi.light_pos);
                int face;
                double ss, tt;
                cube_select(v, &face, &ss, &tt);
                int ii = (int)floor(ss * n), jj = (int)floor(tt * n);
                if (face == f && ii == i && jj == j)
                    exact++;
                else if (face == f && !(abs(ii - i) <= 1 && abs(jj - j) <= 1))
                    fail_msg("face %d texel (%d, %d) holds a point GL looks up at (%d, %d)", f, i, j, ii, jj);
                lr_vec3 nn = lr_v3(nrm[3 * k], nrm[3 * k + 1], nrm[3 * k + 2]);
                assert_near(lr_v3_len(nn), 1.0, 1e-5);
                facing += lr_v3_dot(nn, v) < 0.0;
            }
    }
    printf("G-buffer: %d texels filled, %d on the texel GL looks up, %d facing the light\n", filled,
           exact, facing);
    /* The flame sees wax below and around it, open sky above: about half the sphere. */
    assert_true(filled > 6 * n * n / 4);
    /* Texel centres can fall on the neighbour texel's edge in float: 99% exact. */
    assert_true(exact > 0.99 * filled);
    /* Seen from the light, the first surface faces it. */
    assert_true(facing > 0.99 * filled);
    free(pos);
    free(nrm);
    free(obj);
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
}

static void test_map_matrices_put_x_o_on_its_texel(void **state)
{
    lr_scene *s = lr_test_scene("lampshade", lr_test_small_settings, NULL);
    lr_renderer *r = lr_test_renderer(gl, s, 16, 12, true, 1);
    lr_test_frame(r);
    lr_debug_map_info mi;
    lr_renderer_debug_map_info(r, &mi);
    assert_int_equal(mi.K, 6);
    assert_int_equal(mi.frames, 1);
    int n = mi.size;
    float *pos = malloc((size_t)n * n * 3 * sizeof *pos), *nrm = malloc((size_t)n * n * 3 * sizeof *nrm);
    float *B = malloc((size_t)n * n * 3 * sizeof *B);
    int *obj = malloc((size_t)n * n * sizeof *obj);
    lr_err e = {0};
    for (int k = 0; k < mi.K; k++) {
        lr_vec3 d = lr_renderer_debug_map_dir(r, k), h = lr_halton_sphere((unsigned)k + 1);
        assert_near(d.x, h.x, 1e-12);
        assert_near(d.z, h.z, 1e-12);
        double P[16];
        lr_renderer_debug_map_matrix(r, k, P);
        if (lr_renderer_debug_read_map(r, k, B, pos, nrm, obj, &e))
            fail_msg("%s", e.msg);
        int covered = 0, facing = 0;
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++) {
                size_t t = (size_t)j * n + i;
                if (obj[t] < 0)
                    continue;
                covered++;
                lr_vec3 x = lr_v3(pos[3 * t], pos[3 * t + 1], pos[3 * t + 2]);
                lr_vec3 p = lr_mat4_point(P, x);
                /* The texel centre's surface point: within half a texel, plus float slack. */
                assert_near(p.x * n, i + 0.5, 0.51);
                assert_near(p.y * n, j + 0.5, 0.51);
                assert_true(p.z > 0.0 && p.z < 1.0);
                lr_vec3 no = lr_v3(nrm[3 * t], nrm[3 * t + 1], nrm[3 * t + 2]);
                facing += lr_v3_dot(no, d) >= -1e-6;
                for (int c = 0; c < 3; c++)
                    assert_true(isfinite(B[3 * t + c]) && B[3 * t + c] >= 0.0f);
            }
        /* The shade fills a good part of each view; visible normals face the map camera
         * (two-sided surfaces are turned toward it; closed ones face it by visibility). */
        assert_true(covered > n * n / 8);
        assert_true(facing > 0.97 * covered);
    }
    free(pos);
    free(nrm);
    free(B);
    free(obj);
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
}

static void read_vpls(lr_renderer *r, lr_debug_vpl *v)
{
    lr_err e = {0};
    if (lr_renderer_debug_read_vpls(r, v, &e))
        fail_msg("%s", e.msg);
}

static void test_vpls_are_stable(void **state)
{
    lr_scene *s = lr_test_scene("candle", lr_test_small_settings, NULL);
    lr_renderer *r = lr_test_renderer(gl, s, 16, 12, false, 1);
    lr_test_converge(r, 8);
    int n = lr_renderer_debug_vpl_count(r);
    assert_int_equal(n, 48);
    lr_debug_vpl *a = calloc((size_t)n, sizeof *a), *b = calloc((size_t)n, sizeof *b);
    read_vpls(r, a);
    lr_vec3 c = lr_renderer_debug_vpl_center(r);
    int valid = 0;
    double area = 0.0;
    for (int v = 0; v < n; v++) {
        if (!a[v].valid)
            continue;
        valid++;
        area += a[v].area;
        /* On its fixed direction from the centre, within the VPL cube's texel (16^2 faces:
         * ~0.09 rad at most). */
        lr_vec3 dir = lr_v3_normalize(lr_v3_sub(a[v].pos, c));
        assert_true(lr_v3_dot(dir, a[v].u) > cos(0.1));
        lr_vec3 h = lr_halton_sphere((unsigned)v + 1);
        assert_near(a[v].u.x, h.x, 1e-12);
    }
    /* A closed pillar: every direction meets it. The areas add up to roughly the surface
     * (2 pi r h + 2 pi r^2 = 34,080 mm^2 for r 35, h 120, plus the pool's wall): within 15%
     * with 48 directions and the 0.05 floor on |n . u|. */
    assert_int_equal(valid, n);
    double want = lr_scene_object_at(s, 0)->area;
    printf("VPL area sum %.0f mm^2, object area %.0f mm^2\n", area, want);
    assert_near_rel(area, want, 0.15);

    /* The dimmer and the material leave the positions exactly where they were. */
    lr_test_set(s, r, "light.intensity", "0.001");
    lr_test_frame(r);
    read_vpls(r, b);
    assert_memory_equal(a, b, (size_t)n * sizeof *a);
    lr_test_set(s, r, "objects[pillar].material.scale", "0.7");
    lr_test_converge(r, 8);
    read_vpls(r, b);
    int changed = 0;
    for (int v = 0; v < n; v++) {
        assert_true(a[v].pos.x == b[v].pos.x && a[v].pos.y == b[v].pos.y && a[v].pos.z == b[v].pos.z);
        assert_true(a[v].area == b[v].area);
        changed += a[v].B[0] != b[v].B[0];
    }
    assert_true(changed > n / 2); /* ... while their radiosity follows the material */
    free(a);
    free(b);
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
}

/* lr_async's preview stage sets render.K, the map sizes and receiver_bounce=false for one frame
 * and restores them: each re-allocates the renderer's GPU resources. The receiver bounce's F and
 * object rows depend on the geometry alone (keyed, render/bounce/rbounce.c): the settings'
 * re-allocation must not throw them away, or the full frame after every preview rebuilt them
 * (about 0.9 s on the sim rig's candle, not cut by a newer batch). */
static void test_new_settings_keep_the_bounce(void **state)
{
    (void)state;
    lr_scene *s = lr_test_scene("candle", lr_test_small_settings, NULL);
    lr_renderer *r = lr_test_renderer(gl, s, 64, 48, false, 3);
    lr_test_frame(r);
    double build_s;
    assert_true(lr_renderer_debug_bounce_build(r, &build_s));
    assert_true(build_s > 0); /* built by the first frame */
    lr_test_converge(r, 4);
    const char *preview[][2] = {{"render.K", "1"}, {"render.map_size", "32"},
                                {"render.receiver_bounce", "false"}};
    const char *back[][2] = {{"render.receiver_bounce", "true"}, {"render.map_size", "48"},
                             {"render.K", "6"}};
    for (int i = 0; i < 3; i++)
        lr_test_set(s, r, preview[i][0], preview[i][1]);
    lr_test_frame(r);
    assert_false(lr_renderer_debug_bounce_build(r, &build_s)); /* parked */
    for (int i = 0; i < 3; i++)
        lr_test_set(s, r, back[i][0], back[i][1]);
    lr_test_frame(r);
    assert_true(lr_renderer_debug_bounce_build(r, &build_s));
    printf("bounce rebuild after the settings and back: %.3f s\n", build_s);
    assert_true(build_s == 0); /* kept: nothing in its key changed */
    /* A material change keeps F too (the objects' albedo is set at each update). */
    lr_test_set(s, r, "objects[pillar].material.scale", "0.7");
    lr_test_frame(r);
    assert_true(lr_renderer_debug_bounce_build(r, &build_s) && build_s == 0);
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
}

/* images_only (render/async's renderer): no frame runs the blend pass, the per-light images
 * are the same numbers as a plain renderer's (same scene, size and seed: the passes before
 * the blend are the same code; compared bit for bit), and the output readers refuse. */
static void test_images_only_skips_the_blend(void **state)
{
    (void)state;
    lr_scene *s = lr_test_scene("candle", lr_test_small_settings, NULL);
    enum { W = 32, H = 24 };
    lr_renderer_desc d = {.gl = gl, .scene = s, .width = W, .height = H, .seed = 5};
    lr_renderer *plain = lr_test_renderer_desc(&d);
    d.images_only = true;
    lr_renderer *only = lr_test_renderer_desc(&d);
    /* The tests' small settings converge in two frames (a restart, one accumulation). */
    for (int f = 0; f < 2; f++) {
        lr_frame_stats a = lr_test_frame(plain), b = lr_test_frame(only);
        assert_true(a.passes & LR_PASS_BLEND);
        assert_false(b.passes & LR_PASS_BLEND);
        assert_int_equal(a.passes & ~(unsigned)LR_PASS_BLEND, b.passes);
    }
    /* A dimmer change is the caller's blend: nothing left for the renderer to do. */
    lr_test_set(s, only, "light.intensity_cd", "1.5");
    lr_test_set(s, plain, "light.intensity_cd", "1.5");
    assert_true(lr_renderer_needs_frame(plain));
    assert_false(lr_renderer_needs_frame(only));
    float sc_a[LR_SCENE_MAX_LIGHTS], sc_b[LR_SCENE_MAX_LIGHTS];
    int na = 0, nb = 0;
    const lr_tex *ia = lr_renderer_images(plain, &na, sc_a);
    const lr_tex *ib = lr_renderer_images(only, &nb, sc_b);
    assert_non_null(ia);
    assert_non_null(ib);
    assert_int_equal(na, nb);
    float *pa = malloc(sizeof(float) * 4 * W * H), *pb = malloc(sizeof(float) * 4 * W * H);
    assert_non_null(pa);
    assert_non_null(pb);
    lr_err e = {0};
    for (int l = 0; l < na; l++) {
        assert_true(sc_a[l] == sc_b[l]);
        lr_fb *fa, *fb;
        lr_fb_desc da = {.color = {{(lr_tex *)ia, l}}}, db = {.color = {{(lr_tex *)ib, l}}};
        assert_int_equal(lr_fb_create(gl, &da, &fa, &e), LR_OK);
        assert_int_equal(lr_fb_create(gl, &db, &fb, &e), LR_OK);
        assert_int_equal(lr_fb_read(fa, 0, 0, 0, W, H, pa, &e), LR_OK);
        assert_int_equal(lr_fb_read(fb, 0, 0, 0, W, H, pb, &e), LR_OK);
        double sum = 0.0;
        for (int i = 0; i < 4 * W * H; i++) {
            assert_true(pa[i] == pb[i]);
            sum += pa[i];
        }
        assert_true(sum > 0.0);
        lr_fb_destroy(fa);
        lr_fb_destroy(fb);
    }
    free(pa);
    free(pb);
    float rgb[3 * W * H];
    assert_int_equal(lr_renderer_read_hdr(only, rgb, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "images_only"));
    lr_renderer_destroy(plain);
    lr_renderer_destroy(only);
    lr_scene_destroy(s);
}

/* GPU memory (lr_renderer_gpu_bytes, lr_gl_memory; the renderer's budget): what the renderer
 * holds is what its context's count gained, at least the light G-buffer's storage (per
 * light: two RGBA32F cube maps and two 2D maps of gbuffer_size^2, and seven 4-byte depth
 * renderbuffers), and all of it is given back at destroy (the count returns exactly). A
 * budget under the need refuses the renderer naming the need and gpu_memory_mb; a budget
 * above it lets it run, and a settings change that passes it fails the frame that applies it. */
static void test_gpu_memory_budget(void **state)
{
    (void)state;
    lr_scene *s = lr_test_scene("candle", lr_test_small_settings, NULL);
    size_t before, after, peak;
    lr_gl_memory(gl, &before, NULL);
    lr_renderer_desc d = {.gl = gl, .scene = s, .width = 32, .height = 24};
    lr_renderer *r = lr_test_renderer_desc(&d);
    lr_frame_stats st = lr_test_frame(r);
    size_t need = lr_renderer_gpu_bytes(r), n = 64;
    lr_gl_memory(gl, &after, &peak);
    assert_int_equal(need, after - before);
    assert_int_equal(st.gpu_bytes, need);
    size_t gbuffer = 2 * 6 * n * n * 16 + 2 * n * n * 16 + 7 * n * n * 4;
    assert_true(need >= gbuffer);
    printf("candle at the tests' settings: %.2f MB (G-buffer %.2f MB), context peak %.2f MB\n",
           need / 1048576.0, gbuffer / 1048576.0, peak / 1048576.0);
    lr_renderer_destroy(r);
    lr_gl_memory(gl, &after, NULL);
    assert_int_equal(after, before);

    lr_renderer *no = NULL;
    lr_err e = {0};
    /* Under what create itself allocates (the G-buffer; grids come at the first frame). */
    d.gpu_budget_mb = gbuffer / 1048576.0 * 0.5;
    assert_int_equal(lr_renderer_create(&d, &no, &e), LR_ENOMEM);
    assert_null(no);
    assert_non_null(strstr(e.msg, "gpu_memory_mb"));
    assert_non_null(strstr(e.msg, "MB of GPU memory"));
    lr_gl_memory(gl, &after, NULL);
    assert_int_equal(after, before);

    d.gpu_budget_mb = need / 1048576.0 * 1.5;
    r = lr_test_renderer_desc(&d);
    lr_test_frame(r);
    lr_test_set(s, r, "render.gbuffer_size", "256"); /* 16 x the G-buffer: over 1.5 x */
    e = (lr_err){0};
    assert_int_equal(lr_renderer_frame(r, NULL, &e), LR_ENOMEM);
    assert_non_null(strstr(e.msg, "G-buffers 256^2"));
    lr_renderer_destroy(r);
    lr_gl_memory(gl, &after, NULL);
    assert_int_equal(after, before);
    lr_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gbuffer_cube_matches_gl_lookup),
        cmocka_unit_test(test_map_matrices_put_x_o_on_its_texel),
        cmocka_unit_test(test_vpls_are_stable),
        cmocka_unit_test(test_new_settings_keep_the_bounce),
        cmocka_unit_test(test_images_only_skips_the_blend),
        cmocka_unit_test(test_gpu_memory_budget),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
