/* The lamprig program's top level and the checks it makes before any work: `--version` prints
 * the VERSION file's line; `run --out-dir FILE` is refused at start (exit 2, one line) like a
 * folder that cannot be created; `calib check` names and skips JSON files that are not
 * calibration files (rig configs) with exit 0, still checks the calibration files among them
 * and still fails (exit 1) for one that does not load. Runs build/bin/lamprig (built by
 * `make test` before the tests). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <time.h>
#include <sys/wait.h>

#include "calib/colormatrix.h"
#include "tests/support/cli.h"
#include "tests/support/fs.h"

static char *dir;

static int setup(void **state)
{
    dir = lr_test_tmpdir();
    return 0;
}

static int teardown(void **state)
{
    lr_test_rmtree(dir);
    return 0;
}

/* The child runs with this file's scratch folder (tests/support/cli.h). */
#define run(...) lr_test_run_cli(dir, __VA_ARGS__)

static char *slurp(const char *name)
{
    char *path = lr_test_path(dir, name);
    size_t n;
    char *t = (char *)lr_test_read(path, &n);
    free(path);
    return t;
}

static int lines(const char *text)
{
    int n = 0;
    for (const char *c = text; *c; c++)
        n += *c == '\n';
    return n;
}

static void test_version_is_the_version_file(void **state)
{
    size_t n;
    char *want = (char *)lr_test_read("VERSION", &n);
    want[strcspn(want, "\n")] = '\0';
    assert_true(want[0] != '\0');
    char line[256];
    snprintf(line, sizeof line, "lamprig %s\n", want);
    const char *forms[] = {"--version", "version"};
    for (int k = 0; k < 2; k++) {
        assert_int_equal(run("./build/bin/lamprig %s", forms[k]), 0);
        char *out = slurp("out");
        assert_string_equal(out, line);
        free(out);
    }
    /* `lamprig help` says how to get it. */
    assert_int_equal(run("./build/bin/lamprig help"), 0);
    char *out = slurp("out");
    assert_non_null(strstr(out, "--version"));
    free(out);
    free(want);
}

/* A file where the frames' folder should be: one line naming the flag and the path, exit 2,
 * before the rig opens anything (no log line: the config line comes after set-up). */
static void test_run_out_dir_must_be_a_folder(void **state)
{
    char *file = lr_test_write(dir, "not-a-folder", "x", (size_t)-1);
    const char *bad[2] = {file, NULL};
    char *missing = lr_test_path(dir, "no/such/folder");
    bad[1] = missing;
    for (int k = 0; k < 2; k++) {
        int st = run("./build/bin/lamprig run --config configs/rig/sim.json --headless "
                     "--duration 0.2 --out-dir %s", bad[k]);
        char *err = slurp("err");
        if (st != 2 || !strstr(err, "--out-dir") || !strstr(err, bad[k]) || lines(err) != 1)
            fail_msg("--out-dir %s: exit %d, stderr '%s' (expected 2 and one line)", bad[k], st,
                     err);
        free(err);
    }
    struct stat sb;
    assert_int_equal(stat(file, &sb), 0);
    assert_true(S_ISREG(sb.st_mode)); /* left as it was */
    free(file);
    free(missing);
}

/* A full cache disk costs the shader cache, not the rig: with XDG_CACHE_HOME on a full tmpfs
 * Mesa's cache died with SIGBUS before the first frame (exit 135). Now the run finishes (0)
 * and says once which folder it runs without. Needs root to mount; skipped otherwise. */
static void test_run_on_a_full_cache_disk(void **state)
{
    char *mnt = lr_test_path(dir, "cache");
    assert_int_equal(mkdir(mnt, 0700), 0);
    if (lr_test_mount_tmpfs(mnt, 256, 0) != 0) {
        free(mnt);
        skip();
    }
    char *fill = lr_test_path(mnt, "fill");
    FILE *f = fopen(fill, "wb");
    assert_non_null(f);
    static const char block[4096];
    while (fwrite(block, 1, sizeof block, f) == sizeof block && fflush(f) == 0)
        ;
    fclose(f);
    int st = run("XDG_CACHE_HOME=%s ./build/bin/lamprig run --config configs/rig/sim.json "
                 "--headless --duration 0.5", mnt);
    char *err = slurp("err");
    lr_test_umount(mnt);
    if (st != 0)
        fail_msg("run on a full cache disk: exit %d, stderr '%s'", st, err);
    const char *w = strstr(err, "Mesa shader cache: ");
    assert_non_null(w);
    assert_non_null(strstr(w, mnt));
    assert_null(strstr(w + 1, "Mesa shader cache: ")); /* once */
    /* Our own caches cannot be stored either: said once, not never. */
    const char *c = strstr(err, "cache folder: ");
    assert_non_null(c);
    assert_non_null(strstr(c, mnt));
    assert_null(strstr(c + 1, "cache folder: "));
    free(err);
    free(fill);
    free(mnt);
}

/* A FIFO given as the scene or the rig config is refused at once, naming it (the open used to
 * wait for a writer for ever: `timeout` turns that into exit 124). */
static void test_fifo_input_is_refused(void **state)
{
    char *fifo = lr_test_path(dir, "scene.json");
    assert_int_equal(mkfifo(fifo, 0600), 0);
    const char *cmd[2] = {"render --scene %s --out x.png", "run --config %s --headless --duration 0.2"};
    for (int k = 0; k < 2; k++) {
        char line[512];
        snprintf(line, sizeof line, cmd[k], fifo);
        int st = run("timeout 20 ./build/bin/lamprig %s", line);
        char *err = slurp("err");
        if (st != 1 || !strstr(err, fifo) || !strstr(err, "a FIFO, not a regular file"))
            fail_msg("%s: exit %d, stderr '%s' (expected 1 naming the FIFO)", line, st, err);
        free(err);
    }
    free(fifo);
}

/* A command's start sweeps the cache folder: a temp of ours two minutes old (a writer killed
 * between mkstemp and rename) is removed, a fresh one and a file not of our naming stay. */
static void test_start_sweeps_stale_cache_temps(void **state)
{
    char *cache = lr_test_path(dir, "xdg");
    char *stale = lr_test_write(dir, "xdg/lamprig/transrad-00000000000000aa.bin.tmpAb12Zx", "x", 1);
    char *fresh = lr_test_write(dir, "xdg/lamprig/transrad-00000000000000bb.bin.tmpCd34Wv", "x", 1);
    char *other = lr_test_write(dir, "xdg/lamprig/mine.txt.tmpAb12Zx", "x", 1);
    struct timeval tv[2] = {{time(NULL) - 120, 0}, {time(NULL) - 120, 0}};
    assert_int_equal(utimes(stale, tv), 0);
    assert_int_equal(utimes(other, tv), 0);
    int st = run("XDG_CACHE_HOME=%s ./build/bin/lamprig render --scene %s/none.json --out x.png",
                 cache, dir);
    assert_int_equal(st, 1); /* no such scene: the sweep ran before the work */
    struct stat sb;
    assert_int_equal(stat(stale, &sb), -1);
    assert_int_equal(stat(fresh, &sb), 0);
    assert_int_equal(stat(other, &sb), 0);
    free(stale);
    free(fresh);
    free(other);
    free(cache);
}

static void test_calib_check_skips_rig_configs(void **state)
{
    /* A valid colour matrix, an invalid one (a required field missing) and the rig configs. */
    lr_colormatrix m = {.m = {1, 0, 0, 0, 1, 0, 0, 0, 1}, .rms = 0.01, .max_err = 0.02,
                        .patches = 24};
    char *good = lr_test_path(dir, "color.json");
    lr_err e = {0};
    if (lr_colormatrix_save(good, &m, &e))
        fail_msg("%s", e.msg);
    char *broken = lr_test_write(dir, "broken.json",
                                 "{\"version\": 1, \"kind\": \"color_matrix\"}\n", (size_t)-1);

    assert_int_equal(run("./build/bin/lamprig calib check configs/rig/sim.json "
                         "configs/rig/modbus-demo.json %s", good), 0);
    char *out = slurp("out");
    assert_non_null(strstr(out, "configs/rig/sim.json: not a calibration file"));
    assert_non_null(strstr(out, "configs/rig/modbus-demo.json: not a calibration file"));
    assert_non_null(strstr(out, "colour matrix from 24 patches"));
    assert_non_null(strstr(out, "1 valid, 0 invalid, 2 not calibration files"));
    free(out);

    /* A calibration file that does not load still fails the run, with the rig configs beside it. */
    assert_int_equal(run("./build/bin/lamprig calib check configs/rig/sim.json %s", broken), 1);
    char *err = slurp("err");
    assert_non_null(strstr(err, "broken.json"));
    free(err);
    out = slurp("out");
    assert_non_null(strstr(out, "0 valid, 1 invalid, 1 not calibration files"));
    free(out);

    /* Not JSON at all: it cannot be told apart from a damaged calibration file, so it fails. */
    char *text = lr_test_write(dir, "notes.txt", "hello\n", (size_t)-1);
    assert_int_equal(run("./build/bin/lamprig calib check %s", text), 1);
    free(text);
    free(good);
    free(broken);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_version_is_the_version_file),
        cmocka_unit_test(test_run_out_dir_must_be_a_folder),
        cmocka_unit_test(test_calib_check_skips_rig_configs),
        cmocka_unit_test(test_run_on_a_full_cache_disk),
        cmocka_unit_test(test_fifo_input_is_refused),
        cmocka_unit_test(test_start_sweeps_stale_cache_temps),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
