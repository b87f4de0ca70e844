/* The on-disk cache of translucent radiosity's F and S (render/transrad/cache.c):
 *  - a second create with the same scene and settings takes F and S from the file and solves
 *    to the same W bit for bit;
 *  - another setting (rays per patch) or another material is another key: a miss, a new file;
 *  - a file re-signed (a valid hash) with F x 1000 or S x 1000, finite but beyond energy
 *    conservation (F's row sum with the escape <= 1, S's column power <= the source's), is
 *    refused and rebuilt to the same W;
 *  - a corrupt cache (a flipped payload byte, a flipped key byte, a truncated file, garbage,
 *    an empty file) is never used: create rebuilds, solves to the same W, and rewrites it, so
 *    the next create hits again;
 *  - a folder that cannot be written costs only the cache (create succeeds, no hit); a
 *    read-only one (a tmpfs mounted ro) is said through the settings' warn sink, once over two
 *    creates sharing a lr_warn_once, and at each create without one;
 *  - the checked file under both caches (render/reference/cache_file.h): pieces read back as
 *    written, and a flipped magic, header or payload byte, a short file or an absent one read
 *    as absent. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <errno.h>
#include <sys/stat.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "render/base/paths.h"
#include "render/reference/cache_file.h"
#include "render/transrad/transrad.h"
#include "tests/support/fs.h"

static char dir[256];

static lr_scene *load(void)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/scenes/lampshade.json", lr_configs_dir());
    lr_scene *s;
    lr_err e = {0};
    if (lr_scene_load(path, NULL, &s, &e) ||
        lr_scene_set_assignment(s, "objects[0].model=translucent_radiosity", NULL, &e))
        fail_msg("%s", e.msg);
    return s;
}

static lr_tr *create(const lr_scene *s, const char *cache, int rays)
{
    lr_tr_settings set = {.patch_mm = 30, .receiver_mm = 150, .rays_per_patch = rays,
                          .seed = 9, .cache_dir = cache};
    lr_tr *t;
    lr_err e = {0};
    if (lr_tr_create_scene(s, &set, &t, &e))
        fail_msg("%s", e.msg);
    lr_tr_stats st;
    if (lr_tr_solve_light(t, lr_scene_light_at(s, 0), 0, &st, &e))
        fail_msg("%s", e.msg);
    return t;
}

/* Largest |W_a - W_b| over patches and bands. */
static double max_diff(const lr_tr *a, const lr_tr *b)
{
    double m = 0;
    for (size_t p = 0; p < lr_tr_patch_count(a); p++) {
        double wa[3], wb[3];
        lr_tr_radiosity(a, 0, p, wa);
        lr_tr_radiosity(b, 0, p, wb);
        for (int c = 0; c < 3; c++)
            m = fmax(m, fabs(wa[c] - wb[c]));
    }
    return m;
}

static int count_files(char *first, size_t cap)
{
    DIR *d = opendir(dir);
    int n = 0;
    struct dirent *ent;
    while (d && (ent = readdir(d)))
        if (!strncmp(ent->d_name, "transrad-", 9)) {
            if (n++ == 0 && first)
                snprintf(first, cap, "%s/%s", dir, ent->d_name);
        }
    if (d)
        closedir(d);
    return n;
}

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "/tmp/lamprig-test-transrad-cache-XXXXXX");
    return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    DIR *d = opendir(dir);
    struct dirent *ent;
    char path[600];
    while (d && (ent = readdir(d)))
        if (ent->d_name[0] != '.') {
            snprintf(path, sizeof path, "%s/%s", dir, ent->d_name);
            unlink(path);
        }
    if (d)
        closedir(d);
    rmdir(dir);
    return 0;
}

static void test_hit_and_keys(void **state)
{
    (void)state;
    lr_scene *s = load();
    lr_tr *ref = create(s, NULL, 64);
    lr_tr *a = create(s, dir, 64);
    assert_false(lr_tr_cache_hit(ref));
    assert_false(lr_tr_cache_hit(a));
    assert_int_equal(count_files(NULL, 0), 1);
    lr_tr *b = create(s, dir, 64);
    assert_true(lr_tr_cache_hit(b));
    assert_true(max_diff(b, ref) == 0.0);
    assert_true(lr_tr_form_factor(b, 3, 7) == lr_tr_form_factor(ref, 3, 7));
    /* Another setting, another material: misses with their own files. */
    lr_tr *c = create(s, dir, 48);
    assert_false(lr_tr_cache_hit(c));
    assert_int_equal(count_files(NULL, 0), 2);
    lr_err e = {0};
    if (lr_scene_set_assignment(s, "receivers[0].albedo=0.5,0.5,0.5", NULL, &e))
        fail_msg("%s", e.msg);
    lr_tr *d = create(s, dir, 64);
    assert_false(lr_tr_cache_hit(d));
    assert_int_equal(count_files(NULL, 0), 3);
    print_message("%zu patches: hit solves to the same W; 3 keys, 3 files\n",
                  lr_tr_patch_count(a));
    lr_tr_destroy(ref);
    lr_tr_destroy(a);
    lr_tr_destroy(b);
    lr_tr_destroy(c);
    lr_tr_destroy(d);
    lr_scene_destroy(s);
}

/* Damages the single cache file, then create must miss, agree with ref, and repair it. */
static void damaged(const lr_scene *s, const lr_tr *ref, const char *what, long at, int len)
{
    char path[600];
    assert_int_equal(count_files(path, sizeof path), 1);
    FILE *f = fopen(path, "r+b");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    if (len < 0) { /* truncate to at */
        fclose(f);
        assert_int_equal(truncate(path, at), 0);
    } else {
        long pos = at >= 0 ? at : size + at;
        fseek(f, pos, SEEK_SET);
        int ch = fgetc(f);
        fseek(f, pos, SEEK_SET);
        fputc(ch ^ 0x5A, f);
        fclose(f);
    }
    lr_tr *t = create(s, dir, 64);
    print_message("%s: hit %d, W differs by %g\n", what, lr_tr_cache_hit(t), max_diff(t, ref));
    assert_false(lr_tr_cache_hit(t));
    assert_true(max_diff(t, ref) == 0.0);
    lr_tr_destroy(t);
    t = create(s, dir, 64); /* rewritten */
    assert_true(lr_tr_cache_hit(t));
    lr_tr_destroy(t);
}

static void test_corrupt(void **state)
{
    teardown(state);
    assert_int_equal(setup(state), 0);
    lr_scene *s = load();
    lr_tr *ref = create(s, dir, 64);
    damaged(s, ref, "payload byte", -5, 1);
    damaged(s, ref, "key byte", 9, 1);
    damaged(s, ref, "magic", 0, 1);
    damaged(s, ref, "truncated", 1000, -1);
    damaged(s, ref, "empty", 0, -1);
    /* Garbage of the right length: the payload hash refuses it. */
    char path[600];
    assert_int_equal(count_files(path, sizeof path), 1);
    FILE *f = fopen(path, "r+b");
    fseek(f, 200, SEEK_SET);
    for (int i = 0; i < 4096; i++)
        fputc(i * 37 & 255, f);
    fclose(f);
    lr_tr *t = create(s, dir, 64);
    assert_false(lr_tr_cache_hit(t));
    assert_true(max_diff(t, ref) == 0.0);
    lr_tr_destroy(t);
    lr_tr_destroy(ref);
    lr_scene_destroy(s);
}

/* Rewrites the cache file with piece `piece` (2 F values, 6 S values: float arrays) scaled by
 * k and a valid hash (as a foreign writer would). */
static void resign_scaled(const char *path, int piece, float k)
{
    uint64_t w[4];
    char *data = NULL;
    const unsigned char *payload;
    size_t len;
    assert_true(lr_cache_file_read(path, "LRTRC002", w, 4, &data, &payload, &len));
    size_t n = (size_t)w[1], nf = (size_t)w[2], ns = (size_t)w[3];
    size_t b[7] = {(n + 1) * sizeof(size_t), nf * 4, nf * 4, n * sizeof(double),
                   (n + 1) * sizeof(size_t), ns * 4, 3 * ns * 4};
    size_t want = 0, off = 0;
    for (int i = 0; i < 7; i++)
        want += b[i];
    assert_int_equal(len, want);
    unsigned char *copy = malloc(len);
    assert_non_null(copy);
    memcpy(copy, payload, len);
    lr_cache_piece pc[7];
    for (int i = 0; i < 7; i++) {
        if (i == piece)
            for (size_t j = 0; j < b[i] / 4; j++) {
                float v;
                memcpy(&v, copy + off + 4 * j, 4);
                v *= k;
                memcpy(copy + off + 4 * j, &v, 4);
            }
        pc[i] = (lr_cache_piece){copy + off, b[i]};
        off += b[i];
    }
    lr_err e = {0};
    assert_int_equal(lr_cache_file_write(path, "LRTRC002", w, 4, pc, 7, "test", &e), LR_OK);
    free(copy);
    free(data);
}

static void test_implausible_physics(void **state)
{
    teardown(state);
    assert_int_equal(setup(state), 0);
    lr_scene *s = load();
    lr_tr *ref = create(s, dir, 64);
    char path[600];
    assert_int_equal(count_files(path, sizeof path), 1);
    const int pieces[2] = {2, 6};
    for (int i = 0; i < 2; i++) {
        resign_scaled(path, pieces[i], 1000.0f);
        lr_tr *t = create(s, dir, 64);
        if (lr_tr_cache_hit(t))
            fail_msg("%s x 1000 with a valid hash was used", i ? "S" : "F");
        assert_true(max_diff(t, ref) == 0.0);
        lr_tr_destroy(t);
        t = create(s, dir, 64); /* rebuilt and rewritten */
        assert_true(lr_tr_cache_hit(t));
        lr_tr_destroy(t);
    }
    /* A scale within the tolerance's reach is not a change of physics: kept. */
    resign_scaled(path, 2, 1.0f);
    lr_tr *t = create(s, dir, 64);
    assert_true(lr_tr_cache_hit(t));
    lr_tr_destroy(t);
    lr_tr_destroy(ref);
    lr_scene_destroy(s);
}

/* Flips byte `at` of path (or truncates it to `at` bytes) and expects the read to fail. */
static void cache_file_refused(const char *path, const unsigned char *good, size_t len, long at,
                               bool truncate)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    unsigned char *copy = malloc(len);
    assert_non_null(copy);
    memcpy(copy, good, len);
    if (!truncate)
        copy[at] ^= 0x10;
    assert_int_equal(fwrite(copy, 1, truncate ? (size_t)at : len, f), truncate ? (size_t)at : len);
    fclose(f);
    free(copy);
    uint64_t w[2];
    char *data = NULL;
    const unsigned char *payload;
    size_t n;
    assert_false(lr_cache_file_read(path, "LRTEST01", w, 2, &data, &payload, &n));
    assert_null(data);
}

static void test_cache_file(void **state)
{
    (void)state;
    char path[512];
    snprintf(path, sizeof path, "%s/blob.bin", dir);
    const uint64_t words[2] = {0x1122334455667788ull, 3};
    const float a[3] = {1.0f, 2.5f, -4.0f};
    const uint32_t b[2] = {7, 9};
    lr_cache_piece pc[3] = {{a, sizeof a}, {NULL, 0}, {b, sizeof b}};
    lr_err e = {0};
    assert_int_equal(lr_cache_file_write(path, "LRTEST01", words, 2, pc, 3, "test", &e), LR_OK);
    uint64_t w[2];
    char *data = NULL;
    const unsigned char *payload;
    size_t n;
    assert_true(lr_cache_file_read(path, "LRTEST01", w, 2, &data, &payload, &n));
    assert_int_equal(w[0], words[0]);
    assert_int_equal(w[1], words[1]);
    assert_int_equal(n, sizeof a + sizeof b);
    assert_memory_equal(payload, a, sizeof a);
    assert_memory_equal(payload + sizeof a, b, sizeof b);
    /* The header is 8 + 3 x 8 bytes: magic, two words, the hash. */
    size_t len = 8 + 3 * 8 + n;
    unsigned char *good = malloc(len);
    assert_non_null(good);
    memcpy(good, data, len);
    free(data);
    char *other = NULL;
    assert_false(lr_cache_file_read(path, "LRTEST02", w, 2, &other, &payload, &n));
    const long flips[] = {0, 9, 24, 32, (long)len - 1};
    for (size_t k = 0; k < sizeof flips / sizeof flips[0]; k++)
        cache_file_refused(path, good, len, flips[k], false);
    cache_file_refused(path, good, len, (long)len - 1, true);
    cache_file_refused(path, good, len, 20, true);
    unlink(path);
    assert_false(lr_cache_file_read(path, "LRTEST01", w, 2, &other, &payload, &n));
    free(good);
}

static void test_unwritable_folder(void **state)
{
    (void)state;
    lr_scene *s = load();
    lr_tr *t = create(s, "/proc/lamprig-no-such-folder", 64);
    assert_false(lr_tr_cache_hit(t));
    lr_tr_destroy(t);
    lr_scene_destroy(s);
}

typedef struct said {
    int n;
    char last[LR_ERR_MSG_MAX];
} said;

static void count_warning(void *user, const char *msg)
{
    said *w = user;
    w->n++;
    snprintf(w->last, sizeof w->last, "%s", msg);
}

static void create_warned(const lr_scene *s, const char *cache, said *w, lr_warn_once *once)
{
    lr_tr_settings set = {.patch_mm = 30, .receiver_mm = 150, .rays_per_patch = 64, .seed = 9,
                          .cache_dir = cache, .warn = {count_warning, w}, .warned = once};
    lr_tr *t;
    lr_err e = {0};
    if (lr_tr_create_scene(s, &set, &t, &e))
        fail_msg("%s", e.msg);
    assert_false(lr_tr_cache_hit(t));
    lr_tr_destroy(t);
}

/* A read-only cache folder: every store fails; said once per folder over two creates with
 * the caller's lr_warn_once (the message names the folder and the reason), at every create
 * without one. A writable folder says nothing. */
static void test_store_failure_said_once(void **state)
{
    (void)state;
    char *root = lr_test_tmpdir();
    char *ro = lr_test_path(root, "ro");
    assert_int_equal(mkdir(ro, 0700), 0);
    if (lr_test_mount_tmpfs(ro, 256, 1) != 0) {
        print_message("skipped: mount: %s (needs root)\n", strerror(errno));
        free(ro);
        lr_test_rmtree(root);
        skip();
    }
    lr_scene *s = load();
    said w = {0};
    lr_warn_once once = {0};
    create_warned(s, ro, &w, &once);
    create_warned(s, ro, &w, &once);
    assert_int_equal(w.n, 1);
    print_message("said: %s\n", w.last);
    assert_non_null(strstr(w.last, ro));
    assert_non_null(strstr(w.last, "Read-only file system"));
    assert_non_null(strstr(w.last, "rebuilt at every start"));
    said w2 = {0};
    create_warned(s, ro, &w2, NULL);
    create_warned(s, ro, &w2, NULL);
    assert_int_equal(w2.n, 2);
    said w3 = {0};
    lr_warn_once once3 = {0};
    char *rw = lr_test_path(root, "rw");
    create_warned(s, rw, &w3, &once3);
    assert_int_equal(w3.n, 0);
    lr_scene_destroy(s);
    lr_test_umount(ro);
    free(ro);
    free(rw);
    lr_test_rmtree(root);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hit_and_keys),
        cmocka_unit_test(test_corrupt),
        cmocka_unit_test(test_implausible_physics),
        cmocka_unit_test(test_unwritable_folder),
        cmocka_unit_test(test_store_failure_said_once),
        cmocka_unit_test(test_cache_file),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
