/* Physical reference, the plumbing around the estimators: determinism across threads and pass
 * sizes, the variance image against the spread of independent renders, colour band groups,
 * PFM files, the reference cache (keys and reuse) and reference scene files. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "tests/support/fs.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "render/reference/ref_priv.h"
#include "render/scene/scene.h"

/* A small lamp-like scene: a scattering sphere (n = 1.4) with an air cavity around a point
 * light, on a floor, with a wall, and a disk light; chromatic media so that colour groups are
 * exercised. */
static lr_ref_scene *lamp_scene(double sigma_a_red)
{
    lr_ref_scene *s;
    assert_int_equal(lr_ref_scene_create(NULL, &s, NULL), LR_OK);
    lr_ref_medium_desc md = {.sigma_s = {3, 3, 3}, .sigma_a = {sigma_a_red, 0.1, 0.1}, .g = 0.4,
                             .eta = 1.4};
    int m;
    assert_int_equal(lr_ref_scene_add_medium(s, &md, &m, NULL), LR_OK);
    lr_ref_shape *sh;
    assert_int_equal(lr_ref_sphere_create(lr_v3(0, 0, 1.2), 1.0, &sh, NULL), LR_OK);
    lr_ref_object_desc od = {.kind = LR_REF_BOUNDARY, .shape = sh, .inside = m};
    assert_int_equal(lr_ref_scene_add_object(s, &od, NULL), LR_OK);
    assert_int_equal(lr_ref_sphere_create(lr_v3(0, 0, 1.2), 0.6, &sh, NULL), LR_OK);
    od = (lr_ref_object_desc){.kind = LR_REF_BOUNDARY, .shape = sh, .inside = 0, .outside = m};
    assert_int_equal(lr_ref_scene_add_object(s, &od, NULL), LR_OK);
    assert_int_equal(lr_ref_quad_create(lr_v3(-5, -5, 0), lr_v3(10, 0, 0), lr_v3(0, 10, 0), &sh,
                                        NULL), LR_OK);
    od = (lr_ref_object_desc){.kind = LR_REF_RECEIVER, .shape = sh, .albedo = {0.7, 0.6, 0.5}};
    assert_int_equal(lr_ref_scene_add_object(s, &od, NULL), LR_OK);
    lr_ref_light_desc ld = {.kind = LR_REF_LIGHT_POINT, .position = lr_v3(0.1, 0, 1.2),
                            .emission = {1, 0.8, 0.6}};
    assert_int_equal(lr_ref_scene_add_light(s, &ld, NULL), LR_OK);
    ld = (lr_ref_light_desc){.kind = LR_REF_LIGHT_DISK, .position = lr_v3(2, 0, 3),
                             .direction = lr_v3(-0.5, 0, -1), .radius = 0.3,
                             .emission = {0.5, 0.5, 0.5}};
    assert_int_equal(lr_ref_scene_add_light(s, &ld, NULL), LR_OK);
    assert_int_equal(lr_ref_scene_finish(s, NULL), LR_OK);
    return s;
}

static const lr_ref_camera lamp_cam = {.position = {0, -5, 2}, .look_at = {0, 0, 1},
                                       .fov_y_deg = 40};

static void render(const lr_ref_scene *s, const lr_ref_render_desc *d, lr_ref_image *mean,
                   lr_ref_image *var)
{
    lr_ref_render *r;
    assert_int_equal(lr_ref_render_create(s, &lamp_cam, d, &r, NULL), LR_OK);
    assert_int_equal(lr_ref_render_run(r, NULL, NULL, NULL), LR_OK);
    assert_int_equal(lr_ref_render_mean(r, mean, NULL), LR_OK);
    if (var)
        assert_int_equal(lr_ref_render_variance(r, var, NULL), LR_OK);
    assert_int_equal(lr_ref_render_stats(r)->nonfinite, 0);
    lr_ref_render_destroy(r);
}

static size_t npix3(const lr_ref_image *a)
{
    return (size_t)a->width * (size_t)a->height * 3;
}

/* The image is a function of (scene, camera, size, spp, seed): one thread or two, one
 * sample per pass or four, give the same bits; another seed gives other bits. */
static void test_render_deterministic(void **state)
{
    (void)state;
    lr_ref_scene *s = lamp_scene(0.3);
    assert_int_equal(s->n_groups, 2); /* red differs; green and blue share a path */
    lr_ref_render_desc d = {.width = 20, .height = 14, .spp = 8, .spp_per_pass = 4,
                            .threads = 2, .seed = 3};
    lr_ref_image a, b, va, vb;
    render(s, &d, &a, &va);
    d.threads = 1;
    d.spp_per_pass = 1;
    render(s, &d, &b, &vb);
    assert_memory_equal(a.rgb, b.rgb, npix3(&a) * sizeof *a.rgb);
    assert_memory_equal(va.rgb, vb.rgb, npix3(&a) * sizeof *a.rgb);
    lr_ref_image_free(&b);
    d.seed = 4;
    render(s, &d, &b, NULL);
    assert_true(memcmp(a.rgb, b.rgb, npix3(&a) * sizeof *a.rgb) != 0);
    lr_ref_image_free(&a);
    lr_ref_image_free(&b);
    lr_ref_image_free(&va);
    lr_ref_image_free(&vb);
    lr_ref_scene_destroy(s);
}

/* The variance image predicts the spread between independent renders: for two seeds,
 * (m1 - m2)^2 has expectation v1 + v2 per pixel. Averaged over the pixels that are lit
 * (green band), the ratio must be near 1. Per-pixel ratios follow roughly a chi-square with
 * one degree of freedom (variance 2), so the mean over n pixels has SD about sqrt(2 / n);
 * with n > 400 that is < 0.071, and the test allows 0.75..1.3 (more than 4 SD, plus room for
 * the heavy tail of light-traced splats). A variance image off by a factor (e.g. forgetting
 * the division by N) fails by far. */
static void test_variance_predicts_spread(void **state)
{
    (void)state;
    lr_ref_scene *s = lamp_scene(0.1);
    assert_int_equal(s->n_groups, 1); /* grey: one path for all three bands */
    lr_ref_render_desc d = {.width = 32, .height = 24, .spp = 32, .spp_per_pass = 8, .seed = 5};
    lr_ref_image m1, m2, v1, v2;
    render(s, &d, &m1, &v1);
    d.seed = 6;
    render(s, &d, &m2, &v2);
    double ratio = 0.0;
    int n = 0;
    for (size_t i = 1; i < npix3(&m1); i += 3) {
        double v = (double)v1.rgb[i] + (double)v2.rgb[i];
        if (!(v > 0.0))
            continue;
        double dm = (double)m1.rgb[i] - (double)m2.rgb[i];
        ratio += dm * dm / v;
        n++;
    }
    ratio /= n;
    printf("  %d lit pixels: mean (m1 - m2)^2 / (v1 + v2) = %.3f\n", n, ratio);
    assert_true(n > 400);
    assert_true(ratio > 0.75 && ratio < 1.3);
    lr_ref_image_free(&m1);
    lr_ref_image_free(&m2);
    lr_ref_image_free(&v1);
    lr_ref_image_free(&v2);
    lr_ref_scene_destroy(s);
}

static void tmpdir(char *buf, size_t n)
{
    snprintf(buf, n, "/tmp/lamprig-ref-XXXXXX");
    assert_non_null(mkdtemp(buf));
}

/* PFM: bits survive a round trip (NaN and Inf included), rows keep their order, and broken
 * files are rejected. */
static void test_pfm_roundtrip(void **state)
{
    (void)state;
    char dir[64], path[128];
    tmpdir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/a.pfm", dir);
    float px[2 * 3 * 3] = {0.0f, 1.5f, -2.0f, 1e-30f, 3e30f, (float)NAN, INFINITY, 7, 8,
                           9, 10, 11, 12, 13, 14, 15, 16, 17};
    lr_ref_image img = {.width = 3, .height = 2, .rgb = px}, back;
    assert_int_equal(lr_image_write_pfm(path, &img, NULL), LR_OK);
    assert_int_equal(lr_image_read_pfm(path, &back, NULL), LR_OK);
    assert_int_equal(back.width, 3);
    assert_int_equal(back.height, 2);
    assert_memory_equal(back.rgb, px, sizeof px);
    lr_ref_image_free(&back);
    /* Truncate: an error naming the file, no image. */
    FILE *f = fopen(path, "r+b");
    assert_non_null(f);
    assert_int_equal(ftruncate(fileno(f), 20), 0);
    fclose(f);
    lr_err e = {0};
    assert_int_equal(lr_image_read_pfm(path, &back, &e), LR_EPARSE);
    assert_non_null(strstr(e.msg, "a.pfm"));
    assert_null(back.rgb);
    unlink(path);
    rmdir(dir);
}

/* Cache keys: every input that changes the pixels changes the key; what does not (thread
 * count, pass size, zero-for-default vs the explicit default) keeps it. */
static void test_cache_key(void **state)
{
    (void)state;
    lr_ref_scene *s = lamp_scene(0.3), *s2 = lamp_scene(0.3), *s3 = lamp_scene(0.31);
    lr_ref_render_desc d = {.width = 20, .height = 14, .spp = 8, .seed = 1};
    char k0[17], k[17];
    lr_ref_cache_key(s, &lamp_cam, &d, k0);
    assert_int_equal(strlen(k0), 16);
    lr_ref_cache_key(s2, &lamp_cam, &d, k); /* the same content built again */
    assert_string_equal(k, k0);
    lr_ref_render_desc d2 = d;
    d2.threads = 7;
    d2.spp_per_pass = 2;
    lr_ref_cache_key(s, &lamp_cam, &d2, k);
    assert_string_equal(k, k0);
    lr_ref_camera c2 = lamp_cam;
    c2.up = lr_v3(0, 0, 1);  /* the default made explicit */
    c2.fov_y_deg = 40;
    lr_ref_cache_key(s, &c2, &d, k);
    assert_string_equal(k, k0);
    lr_ref_cache_key(s3, &lamp_cam, &d, k); /* a medium coefficient */
    assert_string_not_equal(k, k0);
    c2.position.x += 1e-9; /* the camera */
    lr_ref_cache_key(s, &c2, &d, k);
    assert_string_not_equal(k, k0);
    d2 = d;
    d2.spp = 16;
    lr_ref_cache_key(s, &lamp_cam, &d2, k);
    assert_string_not_equal(k, k0);
    d2 = d;
    d2.width = 21;
    lr_ref_cache_key(s, &lamp_cam, &d2, k);
    assert_string_not_equal(k, k0);
    d2 = d;
    d2.seed = 2;
    lr_ref_cache_key(s, &lamp_cam, &d2, k);
    assert_string_not_equal(k, k0);
    lr_ref_scene_destroy(s);
    lr_ref_scene_destroy(s2);
    lr_ref_scene_destroy(s3);
}

/* The cache renders once and reuses: a miss writes <key>.pfm, .var.pfm and .json (no stray
 * temporary files), a second call hits and returns the same pixels without rewriting the
 * files, and a changed input misses again. */
static void test_cache_reuse(void **state)
{
    (void)state;
    char dir[64], sub[128], path[256];
    tmpdir(dir, sizeof dir);
    snprintf(sub, sizeof sub, "%s/cache/refs", dir); /* created on demand */
    lr_ref_scene *s = lamp_scene(0.3);
    lr_ref_render_desc d = {.width = 12, .height = 9, .spp = 4, .seed = 1};
    lr_ref_image m1, v1, m2, v2;
    bool hit = true;
    assert_int_equal(lr_ref_render_cached(s, &lamp_cam, &d, sub, NULL, NULL, &m1, &v1, &hit,
                                          NULL), LR_OK);
    assert_false(hit);
    char key[17];
    lr_ref_cache_key(s, &lamp_cam, &d, key);
    struct stat st1, st2;
    snprintf(path, sizeof path, "%s/%s.pfm", sub, key);
    assert_int_equal(stat(path, &st1), 0);
    snprintf(path, sizeof path, "%s/%s.json", sub, key);
    assert_int_equal(access(path, R_OK), 0);
    snprintf(path, sizeof path, "%s/%s.var.pfm", sub, key);
    assert_int_equal(access(path, R_OK), 0);
    /* Exactly the three files: the atomic writes left no temporaries. */
    int files = 0;
    FILE *ls;
    char cmd[300];
    snprintf(cmd, sizeof cmd, "ls -A %s", sub);
    assert_non_null(ls = popen(cmd, "r"));
    char line[256];
    while (fgets(line, sizeof line, ls))
        files++;
    pclose(ls);
    assert_int_equal(files, 3);

    sleep(1); /* so that a rewrite would show in the modification time */
    assert_int_equal(lr_ref_render_cached(s, &lamp_cam, &d, sub, NULL, NULL, &m2, &v2, &hit,
                                          NULL), LR_OK);
    assert_true(hit);
    snprintf(path, sizeof path, "%s/%s.pfm", sub, key);
    assert_int_equal(stat(path, &st2), 0);
    assert_int_equal(st1.st_mtime, st2.st_mtime);
    assert_memory_equal(m1.rgb, m2.rgb, npix3(&m1) * sizeof *m1.rgb);
    assert_memory_equal(v1.rgb, v2.rgb, npix3(&m1) * sizeof *m1.rgb);
    lr_ref_image_free(&m2);
    lr_ref_image_free(&v2);

    d.spp = 5; /* a changed input: a miss, a new entry */
    assert_int_equal(lr_ref_render_cached(s, &lamp_cam, &d, sub, NULL, NULL, &m2, &v2, &hit,
                                          NULL), LR_OK);
    assert_false(hit);
    lr_ref_image_free(&m1);
    lr_ref_image_free(&v1);
    lr_ref_image_free(&m2);
    lr_ref_image_free(&v2);
    lr_ref_scene_destroy(s);
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    assert_int_equal(system(cmd), 0);
}

/* Scene files: a full file loads into the same scene (same hash) as the equivalent calls, and
 * mistakes are reported with file:line and the field. */
static void test_scene_file(void **state)
{
    (void)state;
    char dir[64], path[128];
    tmpdir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/s.json", dir);
    lr_test_put(path,
               "{\n"
               "  \"media\": [{\"name\": \"wax\", \"sigma_a\": [0.3, 0.1, 0.1],\n"
               "              \"sigma_s\": [3, 3, 3], \"g\": 0.4, \"eta\": 1.4}],\n"
               "  \"objects\": [\n"
               "    {\"shape\": \"sphere\", \"center\": [0, 0, 1.2], \"radius\": 1.0,\n"
               "     \"inside\": \"wax\"},\n"
               "    {\"shape\": \"sphere\", \"center\": [0, 0, 1.2], \"radius\": 0.6,\n"
               "     \"inside\": \"ambient\", \"outside\": \"wax\"},\n"
               "    {\"shape\": \"quad\", \"corner\": [-5, -5, 0], \"edge1\": [10, 0, 0],\n"
               "     \"edge2\": [0, 10, 0], \"albedo\": [0.7, 0.6, 0.5]}],\n"
               "  \"lights\": [\n"
               "    {\"type\": \"point\", \"position\": [0.1, 0, 1.2], \"intensity\": [1, 0.8, 0.6]},\n"
               "    {\"type\": \"disk\", \"center\": [2, 0, 3], \"normal\": [-0.5, 0, -1],\n"
               "     \"radius\": 0.3, \"radiance\": [0.5, 0.5, 0.5]}],\n"
               "  \"camera\": {\"position\": [0, -5, 2], \"look_at\": [0, 0, 1], \"fov_deg\": 40},\n"
               "  \"render\": {\"width\": 20, \"height\": 14, \"spp\": 8, \"seed\": 1}\n"
               "}\n", (size_t)-1);
    lr_ref_scene *s, *ref = lamp_scene(0.3);
    lr_ref_camera cam = {0};
    lr_ref_render_desc d = {0};
    lr_err e = {0};
    assert_int_equal(lr_ref_scene_load(path, &s, &cam, &d, &e), LR_OK);
    assert_true(lr_ref_scene_hash(s) == lr_ref_scene_hash(ref));
    assert_int_equal(d.width, 20);
    assert_int_equal(d.spp, 8);
    assert_true(cam.fov_y_deg == 40 && cam.position.y == -5);
    char k1[17], k2[17];
    lr_ref_cache_key(s, &cam, &d, k1);
    lr_ref_cache_key(ref, &lamp_cam, &d, k2);
    assert_string_equal(k1, k2);
    lr_ref_scene_destroy(s);
    lr_ref_scene_destroy(ref);

    /* A typo in a key, an unknown medium, a bad value: each names the file and line. */
    struct {
        const char *text, *want;
    } bad[] = {
        {"{\n \"media\": [{\"name\": \"w\", \"sigma_a\": [0,0,0], \"sigma_s\": [1,1,1],\n"
         " \"gg\": 0.2}]\n}\n", ":3:"},
        {"{\n \"objects\": [\n  {\"shape\": \"sphere\", \"center\": [0,0,0], \"radius\": 1,\n"
         "   \"inside\": \"milk\"}]\n}\n", "milk"},
        {"{\n \"media\": [{\"name\": \"w\", \"sigma_a\": [0,0,0], \"sigma_s\": [1,1,1],\n"
         "   \"g\": 1.5}]\n}\n", ":2"},
        {"{\n \"lights\": [{\"type\": \"laser\"}]\n}\n", "laser"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        lr_test_put(path, bad[i].text, (size_t)-1);
        e = (lr_err){0};
        assert_int_not_equal(lr_ref_scene_load(path, &s, &cam, &d, &e), LR_OK);
        assert_null(s);
        printf("  %s\n", e.msg);
        assert_non_null(strstr(e.msg, "s.json"));
        assert_non_null(strstr(e.msg, bad[i].want));
    }
    unlink(path);
    rmdir(dir);
}

/* Scene validation: what would make transport meaningless is refused with a message. */
static void test_scene_validation(void **state)
{
    (void)state;
    lr_ref_scene *s;
    lr_err e = {0};
    assert_int_equal(lr_ref_scene_create(NULL, &s, NULL), LR_OK);
    lr_ref_medium_desc md = {.sigma_s = {1, NAN, 1}};
    int id;
    assert_int_equal(lr_ref_scene_add_medium(s, &md, &id, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "sigma_s[1]"));
    md = (lr_ref_medium_desc){.sigma_s = {1, 1, 1}, .g = 1.0};
    assert_int_equal(lr_ref_scene_add_medium(s, &md, &id, &e), LR_EINVAL);
    md.g = 0.0;
    assert_int_equal(lr_ref_scene_add_medium(s, &md, &id, &e), LR_OK);
    /* An open quad cannot bound a medium (and is freed by the scene). */
    lr_ref_shape *sh;
    assert_int_equal(lr_ref_quad_create(lr_v3(0, 0, 0), lr_v3(1, 0, 0), lr_v3(0, 1, 0), &sh,
                                        NULL), LR_OK);
    lr_ref_object_desc od = {.kind = LR_REF_BOUNDARY, .shape = sh, .inside = id};
    assert_int_equal(lr_ref_scene_add_object(s, &od, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "not closed"));
    lr_ref_light_desc ld = {.kind = LR_REF_LIGHT_SPOT, .position = lr_v3(0, 0, 1),
                            .direction = lr_v3(0, 0, -1), .inner_deg = 40, .outer_deg = 30};
    assert_int_equal(lr_ref_scene_add_light(s, &ld, &e), LR_EINVAL);
    assert_int_equal(lr_ref_scene_finish(s, &e), LR_OK);
    assert_int_equal(lr_ref_scene_add_medium(s, &md, &id, &e), LR_EINVAL); /* after finish */
    lr_ref_scene_destroy(s);
}

/* Project scenes (configs/scenes) become reference scenes: the shipped candle keeps its
 * object (a wax boundary), its two receivers and its flame (in the air of the melt pool, at
 * intensity times colour), and renders finite, non-negative radiance with light on it; what
 * the reference cannot represent is refused by name. */
static void test_from_project_scene(void **state)
{
    (void)state;
    lr_scene *sc;
    lr_err e = {0};
    assert_int_equal(lr_scene_load(LR_SOURCE_CONFIGS "/scenes/candle.json", NULL, &sc, &e),
                     LR_OK);
    lr_ref_scene *s;
    lr_ref_camera cam;
    assert_int_equal(lr_ref_scene_from_scene(sc, &s, &cam, &e), LR_OK);
    assert_int_equal(s->n_objects, 3);
    assert_int_equal(s->objects[0].kind, LR_REF_SURF_BOUNDARY);
    assert_int_equal(s->objects[1].kind, LR_REF_SURF_RECEIVER);
    assert_int_equal(s->n_lights, 1);
    assert_int_equal(s->lights[0].medium, 0); /* the flame burns in air */
    double rgb[3];
    lr_light_rgb(lr_scene_light_at(sc, 0), rgb);
    assert_true(s->lights[0].d.emission[0] == rgb[0] && s->lights[0].d.emission[2] == rgb[2]);
    assert_true(s->media[1].eta > 1.4 && s->media[1].sigma_s[0] > 0.0);
    assert_true(cam.fov_y_deg == lr_scene_camera(sc)->fov_deg);
    lr_ref_render_desc d = {.width = 16, .height = 12, .spp = 2, .seed = 1};
    lr_ref_render *r;
    assert_int_equal(lr_ref_render_create(s, &cam, &d, &r, NULL), LR_OK);
    assert_int_equal(lr_ref_render_run(r, NULL, NULL, NULL), LR_OK);
    lr_ref_image m;
    assert_int_equal(lr_ref_render_mean(r, &m, NULL), LR_OK);
    int lit = 0;
    for (size_t i = 0; i < npix3(&m); i++) {
        assert_true(isfinite(m.rgb[i]) && m.rgb[i] >= 0.0f);
        lit += m.rgb[i] > 0.0f;
    }
    assert_true(lit > 16);
    assert_int_equal(lr_ref_render_stats(r)->medium_mismatch, 0);
    lr_ref_image_free(&m);
    lr_ref_render_destroy(r);
    lr_ref_scene_destroy(s);
    lr_scene_destroy(sc);

    static const char directional[] =
        "{\"objects\": [{\"material\": \"marble\", \"mesh\": {\"type\": \"sphere\"}}],\n"
        " \"lights\": [{\"type\": \"directional\", \"name\": \"sun\",\n"
        "   \"direction\": [0, 0, -1], \"radiance\": 1}],\n"
        " \"camera\": {\"position\": [0, -300, 0], \"target\": [0, 0, 0]}}\n";
    assert_int_equal(lr_scene_parse(directional, sizeof directional - 1, "sun.json", NULL, &sc,
                                    &e), LR_OK);
    assert_int_equal(lr_ref_scene_from_scene(sc, &s, &cam, &e), LR_EUNSUPPORTED);
    assert_null(s);
    assert_non_null(strstr(e.msg, "sun"));
    lr_scene_destroy(sc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_render_deterministic),
        cmocka_unit_test(test_variance_predicts_spread),
        cmocka_unit_test(test_pfm_roundtrip),
        cmocka_unit_test(test_cache_key),
        cmocka_unit_test(test_cache_reuse),
        cmocka_unit_test(test_scene_file),
        cmocka_unit_test(test_scene_validation),
        cmocka_unit_test(test_from_project_scene),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
