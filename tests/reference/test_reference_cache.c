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
    assert_int_equal(lr_ref_render_cached(s, &lamp_cam, &d, sub, NULL, NULL, NULL, &m1, &v1,
                                          &hit, NULL), LR_OK);
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
    assert_int_equal(lr_ref_render_cached(s, &lamp_cam, &d, sub, NULL, NULL, NULL, &m2, &v2,
                                          &hit, NULL), LR_OK);
    assert_true(hit);
    snprintf(path, sizeof path, "%s/%s.pfm", sub, key);
    assert_int_equal(stat(path, &st2), 0);
    assert_int_equal(st1.st_mtime, st2.st_mtime);
    assert_memory_equal(m1.rgb, m2.rgb, npix3(&m1) * sizeof *m1.rgb);
    assert_memory_equal(v1.rgb, v2.rgb, npix3(&m1) * sizeof *m1.rgb);
    lr_ref_image_free(&m2);
    lr_ref_image_free(&v2);

    d.spp = 5; /* a changed input: a miss, a new entry */
    assert_int_equal(lr_ref_render_cached(s, &lamp_cam, &d, sub, NULL, NULL, NULL, &m2, &v2,
                                          &hit, NULL), LR_OK);
    assert_false(hit);
    lr_ref_image_free(&m1);
    lr_ref_image_free(&v1);
    lr_ref_image_free(&m2);
    lr_ref_image_free(&v2);
    lr_ref_scene_destroy(s);
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    assert_int_equal(system(cmd), 0);
}

/* ---- damaged entries: refused with a warning naming the file, rendered again ---------- */

typedef struct warns {
    int n;
    bool quiet;
    char last[LR_ERR_MSG_MAX];
} warns;

static void collect(void *user, const char *msg)
{
    warns *w = user;
    w->n++;
    snprintf(w->last, sizeof w->last, "%s", msg);
    if (!w->quiet)
        printf("  warning: %s\n", msg);
}

typedef struct entry_fx {
    char dir[64], sub[128], mean[256], var[256], meta[256];
    lr_ref_scene *s;
    lr_ref_render_desc d;
    lr_ref_image m0, v0; /* the images as first rendered */
    warns w;
} entry_fx;

/* The entry once more: whether it was served from the cache; the images are the first
 * render's bits either way (the renderer is deterministic, so a rebuild gives the same), so a
 * damaged value is never what comes back. */
static bool fetch(entry_fx *f)
{
    lr_ref_image m, v;
    bool hit = false;
    lr_err e = {0};
    assert_int_equal(lr_ref_render_cached(f->s, &lamp_cam, &f->d, f->sub, NULL, NULL,
                                          &(const lr_warn_sink){collect, &f->w}, &m, &v, &hit,
                                          &e), LR_OK);
    assert_int_equal(m.width, f->m0.width);
    assert_int_equal(m.height, f->m0.height);
    assert_memory_equal(m.rgb, f->m0.rgb, npix3(&m) * sizeof *m.rgb);
    assert_memory_equal(v.rgb, f->v0.rgb, npix3(&m) * sizeof *m.rgb);
    lr_ref_image_free(&m);
    lr_ref_image_free(&v);
    return hit;
}

static void fx_setup(entry_fx *f, int w, int h, int spp)
{
    memset(f, 0, sizeof *f);
    tmpdir(f->dir, sizeof f->dir);
    snprintf(f->sub, sizeof f->sub, "%s/refs", f->dir);
    f->s = lamp_scene(0.3);
    f->d = (lr_ref_render_desc){.width = w, .height = h, .spp = spp, .seed = 1};
    char key[17];
    lr_ref_cache_key(f->s, &lamp_cam, &f->d, key);
    snprintf(f->mean, sizeof f->mean, "%s/%s.pfm", f->sub, key);
    snprintf(f->var, sizeof f->var, "%s/%s.var.pfm", f->sub, key);
    snprintf(f->meta, sizeof f->meta, "%s/%s.json", f->sub, key);
    bool hit = true;
    assert_int_equal(lr_ref_render_cached(f->s, &lamp_cam, &f->d, f->sub, NULL, NULL, NULL,
                                          &f->m0, &f->v0, &hit, NULL), LR_OK);
    assert_false(hit);
    for (size_t i = 0; i < npix3(&f->m0); i++) /* what the loader demands of a good entry */
        assert_true(isfinite(f->m0.rgb[i]) && f->m0.rgb[i] >= 0 && isfinite(f->v0.rgb[i]) &&
                    f->v0.rgb[i] >= 0);
    assert_true(fetch(f));
    assert_int_equal(f->w.n, 0);
}

static void fx_teardown(entry_fx *f)
{
    lr_ref_image_free(&f->m0);
    lr_ref_image_free(&f->v0);
    lr_ref_scene_destroy(f->s);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", f->dir);
    assert_int_equal(system(cmd), 0);
}

/* After a damage: refused (not a hit) with exactly one warning that names the file and says
 * `why`; the rebuild rewrote the entry, so the next call is a quiet hit. */
static void expect_refused(entry_fx *f, const char *file, const char *why)
{
    int before = f->w.n;
    assert_false(fetch(f));
    assert_int_equal(f->w.n, before + 1);
    if (!strstr(f->w.last, file) || !strstr(f->w.last, why))
        fail_msg("warning '%s' lacks '%s' or '%s'", f->w.last, file, why);
    assert_true(fetch(f));
    assert_int_equal(f->w.n, before + 1);
}

static void flip_byte(const char *path, long from_end, unsigned char mask)
{
    size_t len = 0;
    unsigned char *b = lr_test_read(path, &len);
    assert_non_null(b);
    assert_true((size_t)from_end <= len);
    b[len - (size_t)from_end] ^= mask;
    lr_test_put(path, b, len);
    free(b);
}

/* Replaces the 16 hex digits after `"field": "` in the .json by hash. */
static void resign(const char *meta, const char *field, uint64_t hash)
{
    size_t len = 0;
    char *t = (char *)lr_test_read(meta, &len), pat[64], hex[17];
    assert_non_null(t);
    snprintf(pat, sizeof pat, "\"%s\": \"", field);
    char *p = strstr(t, pat);
    assert_non_null(p);
    snprintf(hex, sizeof hex, "%016llx", (unsigned long long)hash);
    memcpy(p + strlen(pat), hex, 16);
    lr_test_put(meta, t, len);
    free(t);
}

/* Sets one value of a PFM and, when field is given, re-signs the .json with the new image's
 * hash (a valid hash over implausible values: only the finite check can catch it). */
static void poke(const char *pfm, size_t i, float value, const char *meta, const char *field)
{
    lr_ref_image img;
    assert_int_equal(lr_image_read_pfm(pfm, &img, NULL), LR_OK);
    img.rgb[i] = value;
    assert_int_equal(lr_image_write_pfm(pfm, &img, NULL), LR_OK);
    if (field)
        resign(meta, field, lr_ref_image_hash(&img));
    lr_ref_image_free(&img);
}

/* What the cache without content hashes wrote (the .json's first lines, no hash fields). */
static void write_old_meta(const entry_fx *f)
{
    char key[17], text[512];
    lr_ref_cache_key(f->s, &lamp_cam, &f->d, key);
    snprintf(text, sizeof text,
             "{\n  \"key\": \"%s\",\n  \"version\": \"%s\",\n  \"spp\": 4,\n  \"paths\": 432,\n"
             "  \"nee\": 0,\n  \"nee_refracted\": 0,\n  \"nee_unsolved\": 0,\n"
             "  \"truncated\": 0,\n  \"medium_mismatch\": 0,\n  \"nonfinite\": 0\n}\n",
             key, LR_REF_VERSION);
    lr_test_put(f->meta, text, (size_t)-1);
}

/* The reference cache serves an entry only when both images match the content hashes in
 * its .json and every value is finite and non-negative: a flipped byte in either image, a
 * NaN or a negative variance under a valid (recomputed) hash, a NaN under an old-format .json
 * (no hashes: stale), a truncated image or .json, a .json naming another key: each refused
 * with a warning naming the file and rendered again, never served. */
static void test_cache_refuses_bad_entries(void **state)
{
    (void)state;
    entry_fx f;
    fx_setup(&f, 12, 9, 4);
    flip_byte(f.mean, 40, 0x01); /* the low bit of a value: a silently wrong pixel */
    expect_refused(&f, f.mean, "content hash");
    flip_byte(f.var, 100, 0x40);
    expect_refused(&f, f.var, "content hash");
    poke(f.mean, 7, NAN, f.meta, "mean_hash");
    expect_refused(&f, f.mean, "not finite and non-negative");
    poke(f.mean, 0, INFINITY, f.meta, "mean_hash");
    expect_refused(&f, f.mean, "not finite and non-negative");
    poke(f.var, 11, -1e-3f, f.meta, "var_hash");
    expect_refused(&f, f.var, "not finite and non-negative");
    /* The old format: the same NaN, the .json as the cache without hashes wrote it. */
    poke(f.mean, 7, NAN, NULL, NULL);
    write_old_meta(&f);
    expect_refused(&f, f.meta, "no content hash");
    /* A truncated image, a truncated .json. */
    assert_int_equal(truncate(f.mean, 100), 0);
    expect_refused(&f, f.mean, "truncated");
    assert_int_equal(truncate(f.meta, 30), 0);
    expect_refused(&f, f.meta, ".json");
    /* A .json of another entry under this one's name. */
    resign(f.meta, "key", 0x0123456789abcdefULL);
    expect_refused(&f, f.meta, "0123456789abcdef");
    fx_teardown(&f);
}

/* Random damage (120 single-byte changes, a third in each of the three files, fixed seed;
 * a 6x4 image at 1 sample so that each of the rebuilds costs little): every call returns the
 * first render's bits (asserted in fetch), each either a hit with no warning (a change the
 * checks need not see: a PFM header's whitespace or scale digits, a counter in the .json) or
 * a miss with exactly one warning. Of an image's 300 bytes only the 12 of its header can be
 * harmless (4 %), so of the 80 image changes at least 68 are refused (expected harmless
 * under 3.2; more than 12 has a Poisson probability below 1e-5). */
static void test_cache_random_damage(void **state)
{
    (void)state;
    enum { ROUNDS = 120 };
    entry_fx f;
    fx_setup(&f, 6, 4, 1);
    lr_ref_rng rng;
    lr_ref_rng_seed(&rng, 7, 0);
    f.w.quiet = true; /* a warning each, like those of the test above */
    int refused[3] = {0};
    for (int round = 0; round < ROUNDS; round++) {
        const char *path = round % 3 == 0 ? f.mean : round % 3 == 1 ? f.var : f.meta;
        size_t len = 0;
        unsigned char *b = lr_test_read(path, &len);
        assert_non_null(b);
        size_t at = (size_t)(lr_ref_rng_uniform(&rng) * (double)len) % len;
        b[at] ^= (unsigned char)(1 + (int)(lr_ref_rng_uniform(&rng) * 255) % 255);
        lr_test_put(path, b, len);
        free(b);
        int before = f.w.n;
        bool hit = fetch(&f);
        assert_int_equal(f.w.n, before + !hit);
        refused[round % 3] += !hit;
    }
    printf("  refused of %d changes each: mean %d, variance %d, .json %d\n", ROUNDS / 3,
           refused[0], refused[1], refused[2]);
    assert_true(refused[0] + refused[1] >= 68);
    fx_teardown(&f);
}

/* The loader's fuzz harness (every parser and cache loader has one): 3000 mutations of a good
 * entry, a fixed seed, a third in each of its three files, the file put back after each:
 * 1 to 4 bytes changed at random places, a truncation at a random length (0 included), or 1
 * to 64 random bytes appended. Each lr_ref_cache_load (the loader alone: no rebuild, so the
 * loop is cheap; ASan and UBSan watch every read) either serves images with the first
 * render's bits, hence its hashes, finite and non-negative, and says nothing, or refuses
 * with exactly one warning naming one of the entry's files (its key is in the name). A
 * truncated image always loses pixel bytes, so each of those must be refused; at most the
 * .json's trailing newline and appended bytes after a valid entry can be harmless. */
static void test_cache_loader_mutations(void **state)
{
    (void)state;
    enum { ROUNDS = 3000 };
    entry_fx f;
    fx_setup(&f, 6, 4, 1);
    char key[17];
    lr_ref_cache_key(f.s, &lamp_cam, &f.d, key);
    const char *paths[3] = {f.mean, f.var, f.meta};
    unsigned char *good[3];
    size_t glen[3];
    for (int k = 0; k < 3; k++)
        good[k] = lr_test_read(paths[k], &glen[k]);
    const uint64_t hm = lr_ref_image_hash(&f.m0), hv = lr_ref_image_hash(&f.v0);
    lr_ref_rng rng;
    lr_ref_rng_seed(&rng, 11, 0);
    f.w.quiet = true;
    int served[3][3] = {{0}}, refused[3][3] = {{0}}; /* [file][kind] */
    unsigned char *buf = malloc(glen[0] + glen[1] + glen[2] + 64);
    assert_non_null(buf);
    for (int round = 0; round < ROUNDS; round++) {
        int k = round % 3, kind = (int)(lr_ref_rng_uniform(&rng) * 3.0) % 3;
        size_t len = glen[k];
        memcpy(buf, good[k], len);
        if (kind == 0) {
            int n = 1 + (int)(lr_ref_rng_uniform(&rng) * 4.0) % 4;
            for (int i = 0; i < n; i++) {
                size_t at = (size_t)(lr_ref_rng_uniform(&rng) * (double)len) % len;
                buf[at] ^= (unsigned char)(1 + (int)(lr_ref_rng_uniform(&rng) * 255) % 255);
            }
        } else if (kind == 1) {
            len = (size_t)(lr_ref_rng_uniform(&rng) * (double)len) % len;
        } else {
            int n = 1 + (int)(lr_ref_rng_uniform(&rng) * 64.0) % 64;
            for (int i = 0; i < n; i++)
                buf[len++] = (unsigned char)((int)(lr_ref_rng_uniform(&rng) * 256.0) & 255);
        }
        lr_test_put(paths[k], buf, len);
        lr_ref_image m, v;
        int before = f.w.n;
        bool hit = lr_ref_cache_load(f.sub, key, 6, 4, &(const lr_warn_sink){collect, &f.w},
                                     &m, &v);
        if (hit) {
            assert_int_equal(f.w.n, before);
            assert_true(lr_ref_image_hash(&m) == hm && lr_ref_image_hash(&v) == hv);
            assert_int_equal(m.width * m.height, 24);
            assert_memory_equal(m.rgb, f.m0.rgb, npix3(&m) * sizeof *m.rgb);
            assert_memory_equal(v.rgb, f.v0.rgb, npix3(&v) * sizeof *v.rgb);
            lr_ref_image_free(&m);
            lr_ref_image_free(&v);
            served[k][kind]++;
        } else {
            assert_int_equal(f.w.n, before + 1);
            if (!strstr(f.w.last, key))
                fail_msg("round %d: warning names none of the entry's files: %s", round,
                         f.w.last);
            assert_null(m.rgb);
            assert_null(v.rgb);
            refused[k][kind]++;
        }
        lr_test_put(paths[k], good[k], glen[k]);
    }
    static const char *const file[3] = {"mean", "variance", ".json"};
    for (int k = 0; k < 3; k++)
        printf("  %s: bytes changed %d served / %d refused, truncated %d / %d, extended "
               "%d / %d\n", file[k], served[k][0], refused[k][0], served[k][1], refused[k][1],
               served[k][2], refused[k][2]);
    assert_int_equal(served[0][1] + served[1][1], 0);
    /* every kind of mutation was tried on every file */
    for (int k = 0; k < 3; k++)
        for (int kind = 0; kind < 3; kind++)
            assert_true(served[k][kind] + refused[k][kind] > 0);
    /* the good entry is still served, quietly */
    lr_ref_image m, v;
    int before = f.w.n;
    assert_true(lr_ref_cache_load(f.sub, key, 6, 4, &(const lr_warn_sink){collect, &f.w}, &m,
                                  &v));
    assert_int_equal(f.w.n, before);
    lr_ref_image_free(&m);
    lr_ref_image_free(&v);
    free(buf);
    for (int k = 0; k < 3; k++)
        free(good[k]);
    fx_teardown(&f);
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
        cmocka_unit_test(test_cache_refuses_bad_entries),
        cmocka_unit_test(test_cache_random_damage),
        cmocka_unit_test(test_cache_loader_mutations),
        cmocka_unit_test(test_scene_file),
        cmocka_unit_test(test_scene_validation),
        cmocka_unit_test(test_from_project_scene),
    };
    if (getenv("LR_TEST_FILTER")) /* e.g. LR_TEST_FILTER='test_cache*' to run some tests */
        cmocka_set_test_filter(getenv("LR_TEST_FILTER"));
    return cmocka_run_group_tests(tests, NULL, NULL);
}
