/* Base utilities: error messages, atomic file replacement, data paths, the median and the
 * progress printer. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <sys/stat.h>

#include "firmware/cli.h"
#include "render/base/atomic_file.h"
#include "render/base/err.h"
#include "render/base/median.h"
#include "render/base/paths.h"
#include "render/base/progress.h"
#include "tests/support/fs.h"

static void test_err_prefix(void **state)
{
    (void)state;
    lr_err e = {0};
    assert_int_equal(lr_err_set(&e, LR_EINVAL, "field '%s' must be >= 0", "eta"), LR_EINVAL);
    assert_int_equal(lr_err_prefix(&e, "%s:%d", "wax.json", 7), LR_EINVAL);
    assert_string_equal(e.msg, "wax.json:7: field 'eta' must be >= 0");
    /* An overlong prefix truncates but keeps the string terminated and the code. */
    char big[2 * LR_ERR_MSG_MAX];
    memset(big, 'p', sizeof big - 1);
    big[sizeof big - 1] = '\0';
    assert_int_equal(lr_err_prefix(&e, "%s", big), LR_EINVAL);
    assert_int_equal(strlen(e.msg), LR_ERR_MSG_MAX - 1);
    assert_int_equal(lr_err_set(NULL, LR_EIO, "ignored"), LR_EIO);
    assert_string_equal(lr_status_str(LR_ENODEV), "no such device");
}

static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    char *buf = calloc(1, 4096);
    size_t n = fread(buf, 1, 4095, f);
    buf[n] = '\0';
    fclose(f);
    return buf;
}

static int count_entries(const char *dir)
{
    DIR *d = opendir(dir);
    int n = 0;
    struct dirent *de;
    while ((de = readdir(d)))
        if (de->d_name[0] != '.')
            n++;
    closedir(d);
    return n;
}

static void test_atomic_replace_and_failure_keeps_old(void **state)
{
    (void)state;
    char dir[] = "/tmp/lamprig-atomic-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[256];
    snprintf(path, sizeof path, "%s/calib.json", dir);
    lr_err e = {0};
    assert_int_equal(lr_atomic_write(path, "old", 3, &e), LR_OK);
    /* A writer that fails half-way (abort) leaves the old content and no temp file. */
    lr_atomic_file *f;
    assert_int_equal(lr_atomic_file_open(path, &f, &e), LR_OK);
    fputs("half-written new content", lr_atomic_file_stream(f));
    lr_atomic_file_abort(f);
    char *s = slurp(path);
    assert_string_equal(s, "old");
    free(s);
    assert_int_equal(count_entries(dir), 1);
    /* A committed writer replaces it whole. */
    assert_int_equal(lr_atomic_file_open(path, &f, &e), LR_OK);
    fputs("new", lr_atomic_file_stream(f));
    assert_int_equal(lr_atomic_file_commit(f, &e), LR_OK);
    s = slurp(path);
    assert_string_equal(s, "new");
    free(s);
    assert_int_equal(count_entries(dir), 1);
    /* Unwritable destination: a clear error naming the path. */
    char bad[300];
    snprintf(bad, sizeof bad, "%s/no-such-dir/x.json", dir);
    assert_int_equal(lr_atomic_write(bad, "x", 1, &e), LR_EIO);
    assert_non_null(strstr(e.msg, bad));
    unlink(path);
    rmdir(dir);
}

/* Data lookup (render/base/paths.h): the env overrides; shaders beside the source tree's
 * configs (render/shaders) or an installed prefix's (PREFIX/share/lamprig/shaders); the
 * global --configs/--shaders options set the env for the command; a missing DIR is a usage
 * error. The binary-relative installed lookup is tested on the package (tests/install.sh). */
static void test_data_paths(void **state)
{
    (void)state;
    char buf[1024];
    unsetenv("LAMPRIG_CONFIGS");
    unsetenv("LAMPRIG_SHADERS");
    /* The test runs from the source tree (or finds it compiled in): its own layout. */
    assert_int_equal(lr_shaders_dir(buf, sizeof buf), 0);
    char want[1024];
    snprintf(want, sizeof want, "%s/../render/shaders", lr_configs_dir());
    assert_string_equal(buf, want);
    /* An installed layout named by LAMPRIG_CONFIGS: shaders are its sibling. */
    char *dir = lr_test_tmpdir();
    char *cfg = lr_test_path(dir, "configs");
    assert_int_equal(mkdir(cfg, 0755), 0);
    setenv("LAMPRIG_CONFIGS", cfg, 1);
    assert_string_equal(lr_configs_dir(), cfg);
    assert_int_equal(lr_shaders_dir(buf, sizeof buf), 0);
    snprintf(want, sizeof want, "%s/../shaders", cfg);
    assert_string_equal(buf, want);
    setenv("LAMPRIG_SHADERS", "/opt/glsl", 1);
    assert_int_equal(lr_shaders_dir(buf, sizeof buf), 0);
    assert_string_equal(buf, "/opt/glsl");
    assert_int_equal(lr_shaders_dir(buf, 5), -1); /* does not fit */
    /* lamprig --configs DIR --shaders DIR help */
    char *argv[] = {"lamprig", "--configs", "/a/configs", "--shaders", "/b/shaders", "help", NULL};
    assert_int_equal(lr_cli_main(6, argv), LR_EXIT_OK);
    assert_string_equal(getenv("LAMPRIG_CONFIGS"), "/a/configs");
    assert_string_equal(getenv("LAMPRIG_SHADERS"), "/b/shaders");
    char *bad[] = {"lamprig", "--configs", NULL};
    assert_int_equal(lr_cli_main(2, bad), LR_EXIT_USAGE);
    char *empty[] = {"lamprig", "--shaders", "", "help", NULL};
    assert_int_equal(lr_cli_main(4, empty), LR_EXIT_USAGE);
    unsetenv("LAMPRIG_CONFIGS");
    unsetenv("LAMPRIG_SHADERS");
    rmdir(cfg);
    free(cfg);
    lr_test_rmtree(dir);
}

/* The median skips failed measurements (NaN, Inf) and leaves its input as it was. */
static void test_median_finite(void **state)
{
    (void)state;
    double odd[] = {5, NAN, 1, INFINITY, 3};
    assert_true(lr_median_finite(odd, 5) == 3.0);
    assert_true(isnan(odd[1]) && odd[0] == 5 && odd[2] == 1); /* unchanged */
    double even[] = {4, 1, -INFINITY, 2, 3};
    assert_true(lr_median_finite(even, 5) == 2.5);
    double none[] = {NAN, INFINITY};
    assert_true(isnan(lr_median_finite(none, 2)));
    assert_true(isnan(lr_median_finite(NULL, 0)));
}

/* ---- progress (render/base/progress.h) ---------------------------------------------------- */

static double fake_clock(void *ctx)
{
    return *(const double *)ctx;
}

/* A meter writing into a memory stream at a clock the test sets. */
typedef struct meter_case {
    double t;
    char *buf;
    size_t len;
    FILE *f;
    lr_progress_meter *m;
} meter_case;

static void meter_open(meter_case *c, lr_progress_style style)
{
    memset(c, 0, sizeof *c);
    assert_non_null(c->f = open_memstream(&c->buf, &c->len));
    lr_progress_meter_desc d = {.prefix = "lamprig x", .style = style, .out = c->f,
                                .clock = fake_clock, .clock_ctx = &c->t};
    assert_int_equal(lr_progress_meter_create(&d, &c->m, NULL), LR_OK);
}

static void meter_close(meter_case *c)
{
    lr_progress_meter_destroy(c->m);
    fclose(c->f);
}

/* Plain lines: the first report at once, then at most one a second, plus the line that closes
 * a stage already shown; stage, n/N, percentage, elapsed and the straight-line estimate of the
 * time left (10 s for 25 of 100 -> 30 s left). */
static void test_progress_lines(void **state)
{
    (void)state;
    meter_case c;
    meter_open(&c, LR_PROGRESS_LINES);
    const lr_progress *p = lr_progress_meter_sink(c.m);
    for (int i = 0; i <= 100; i++) { /* 100 steps over 40 s: 0.4 s each */
        c.t = 0.4 * i;
        lr_progress_report(p, "render frame", i, 100);
    }
    /* a stage done within the interval after the last line: never shown */
    lr_progress_report(p, "quick", 0, 2);
    lr_progress_report(p, "quick", 2, 2);
    int lines = lr_progress_meter_lines(c.m);
    meter_close(&c);
    /* lines at t = 0, 1.2, 2.4, ... (every third step, 1.2 s >= 1 s apart): 0, 3, ..., 99,
     * then 100 closing the stage */
    assert_int_equal(lines, 35);
    assert_non_null(strstr(c.buf, "lamprig x: render frame 0/100 (0 %), 0 s elapsed\n"));
    assert_non_null(strstr(c.buf, "lamprig x: render frame 3/100 (3 %), 1 s elapsed, ~39 s left\n"));
    /* at step 75, 30 s: 30 x 25 / 75 = 10 s left */
    assert_non_null(strstr(c.buf, "render frame 75/100 (75 %), 30 s elapsed, ~10 s left\n"));
    assert_non_null(strstr(c.buf, "render frame 100/100 (100 %), 40 s elapsed\n"));
    assert_null(strstr(c.buf, "quick"));
    assert_null(strchr(c.buf, '\r'));
    free(c.buf);
}

/* A terminal: one line rewritten in place (\r ... ESC[K), ended by a newline when the stage
 * ends or the meter is destroyed; quiet: nothing at all. */
static void test_progress_tty_and_quiet(void **state)
{
    (void)state;
    meter_case c;
    meter_open(&c, LR_PROGRESS_TTY);
    const lr_progress *p = lr_progress_meter_sink(c.m);
    lr_progress_report(p, "decode", 0, 4);
    c.t = 0.3;
    lr_progress_report(p, "decode", 1, 4);
    c.t = 0.4; /* 0.1 s after the last update: skipped */
    lr_progress_report(p, "decode", 2, 4);
    c.t = 0.7;
    lr_progress_report(p, "decode", 4, 4);
    c.t = 1.0;
    lr_progress_report(p, "evaluations", 5, 0); /* total unknown */
    meter_close(&c);
    assert_string_equal(c.buf, "\rlamprig x: decode 0/4 (0 %), 0 s elapsed\033[K"
                               "\rlamprig x: decode 1/4 (25 %), 0 s elapsed, ~1 s left\033[K"
                               "\rlamprig x: decode 4/4 (100 %), 1 s elapsed\033[K\n"
                               "\rlamprig x: evaluations 5, 0 s elapsed\033[K\n");
    free(c.buf);
    meter_open(&c, LR_PROGRESS_QUIET);
    p = lr_progress_meter_sink(c.m);
    for (int i = 0; i < 5; i++) {
        c.t = 10.0 * i;
        lr_progress_report(p, "render frame", i, 4);
    }
    assert_int_equal(lr_progress_meter_lines(c.m), 0);
    meter_close(&c);
    assert_int_equal(c.len, 0);
    free(c.buf);
    /* nobody listening */
    lr_progress_report(lr_progress_meter_sink(NULL), "x", 1, 2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_err_prefix),
        cmocka_unit_test(test_atomic_replace_and_failure_keeps_old),
        cmocka_unit_test(test_data_paths),
        cmocka_unit_test(test_median_finite),
        cmocka_unit_test(test_progress_lines),
        cmocka_unit_test(test_progress_tty_and_quiet),
    };
    return cmocka_run_group_tests_name("base", tests, NULL, NULL);
}
