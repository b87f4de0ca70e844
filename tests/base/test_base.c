/* Base utilities: error messages, atomic file replacement, data paths, the median and the
 * progress printer. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/time.h>

#include "firmware/cli.h"
#include "render/base/atomic_file.h"
#include "render/base/cache_dir.h"
#include "render/base/dir_check.h"
#include "render/base/err.h"
#include "render/base/file.h"
#include "render/base/median.h"
#include "render/base/paths.h"
#include "render/base/umask.h"
#include "render/gl/shader_cache.h"
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

/* Fills the file system under dir until a write fails (ENOSPC). */
static void fill_up(const char *dir)
{
    char *path = lr_test_path(dir, "fill");
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    assert_true(fd >= 0);
    static const char block[4096];
    while (write(fd, block, sizeof block) == (ssize_t)sizeof block)
        ;
    close(fd);
    free(path);
}

/* A folder that can take writes passes, a missing one is judged by the ancestor it would be
 * made in, a file where a folder should be and a free-space floor above what the disk has are
 * refused naming the folder; as root, a read-only and a full tmpfs are refused too (root
 * ignores permission bits, so only a mount shows them). */
static void test_dir_check_writable(void **state)
{
    (void)state;
    char *dir = lr_test_tmpdir();
    lr_err e = {0};
    assert_int_equal(lr_dir_check_writable(dir, 0, &e), LR_OK);
    char *deep = lr_test_path(dir, "a/b/c");
    assert_int_equal(lr_dir_check_writable(deep, 4096, &e), LR_OK);
    struct stat st;
    assert_int_equal(stat(deep, &st), -1); /* the check made nothing */
    char *file = lr_test_write(dir, "plain", "x", (size_t)-1);
    char *under = lr_test_path(file, "lamprig");
    assert_int_equal(lr_dir_check_writable(under, 0, &e), LR_EIO);
    assert_non_null(strstr(e.msg, file));
    assert_non_null(strstr(e.msg, "not a folder"));
    assert_int_equal(lr_dir_check_writable(dir, UINT64_MAX, &e), LR_EIO);
    assert_non_null(strstr(e.msg, dir));
    assert_non_null(strstr(e.msg, "kB free, under"));
    /* No probe file is left behind. */
    DIR *d = opendir(dir);
    int entries = 0;
    for (struct dirent *de; (de = readdir(d));)
        entries += de->d_name[0] != '.';
    closedir(d);
    assert_int_equal(entries, 1); /* "plain" */

    char *mnt = lr_test_path(dir, "mnt");
    assert_int_equal(mkdir(mnt, 0700), 0);
    if (lr_test_mount_tmpfs(mnt, 1024, 1) != 0) {
        fprintf(stderr, "skipping the tmpfs cases: mount: %s (needs root)\n", strerror(errno));
    } else {
        assert_int_equal(lr_dir_check_writable(mnt, 0, &e), LR_EIO);
        assert_non_null(strstr(e.msg, "read-only file system"));
        lr_test_umount(mnt);
        assert_int_equal(lr_test_mount_tmpfs(mnt, 256, 0), 0);
        assert_int_equal(lr_dir_check_writable(mnt, 0, &e), LR_OK);
        fill_up(mnt);
        /* No floor: the probe write itself finds the disk full. */
        assert_int_equal(lr_dir_check_writable(mnt, 0, &e), LR_EIO);
        assert_non_null(strstr(e.msg, mnt));
        assert_non_null(strstr(e.msg, "No space left"));
        lr_test_umount(mnt);
    }
    free(mnt);
    free(under);
    free(file);
    free(deep);
    lr_test_rmtree(dir);
}

/* Mesa 22.3's rules for its shader cache folder, and "disabled" when it is. */
static void set_env(const char *name, const char *value)
{
    if (value)
        setenv(name, value, 1);
    else
        unsetenv(name);
}

static void test_shader_cache_dir(void **state)
{
    (void)state;
    static const char *names[] = {"MESA_SHADER_CACHE_DISABLE", "MESA_GLSL_CACHE_DISABLE",
                                  "MESA_SHADER_CACHE_DIR", "MESA_GLSL_CACHE_DIR",
                                  "XDG_CACHE_HOME", "MESA_DISK_CACHE_SINGLE_FILE",
                                  "MESA_DISK_CACHE_DATABASE"};
    char *saved[7];
    for (int i = 0; i < 7; i++) {
        saved[i] = getenv(names[i]) ? strdup(getenv(names[i])) : NULL;
        unsetenv(names[i]);
    }
    char buf[512];
    setenv("XDG_CACHE_HOME", "/x/cache", 1);
    assert_string_equal(lr_gl_shader_cache_dir(buf, sizeof buf), "/x/cache/mesa_shader_cache");
    setenv("MESA_GLSL_CACHE_DIR", "/old", 1);
    assert_string_equal(lr_gl_shader_cache_dir(buf, sizeof buf), "/old/mesa_shader_cache");
    setenv("MESA_SHADER_CACHE_DIR", "/new", 1);
    setenv("MESA_DISK_CACHE_SINGLE_FILE", "1", 1);
    assert_string_equal(lr_gl_shader_cache_dir(buf, sizeof buf), "/new/mesa_shader_cache_sf");
    setenv("MESA_GLSL_CACHE_DISABLE", "yes", 1);
    assert_null(lr_gl_shader_cache_dir(buf, sizeof buf));
    /* The new name, when present, decides alone. */
    setenv("MESA_SHADER_CACHE_DISABLE", "false", 1);
    assert_non_null(lr_gl_shader_cache_dir(buf, sizeof buf));
    setenv("MESA_SHADER_CACHE_DISABLE", "TRUE", 1);
    assert_null(lr_gl_shader_cache_dir(buf, sizeof buf));
    lr_err e = {0};
    assert_int_equal(lr_gl_shader_cache_check(&e), LR_OK); /* disabled: nothing to check */
    unsetenv("MESA_SHADER_CACHE_DISABLE");
    unsetenv("MESA_GLSL_CACHE_DISABLE");
    /* A file where the cache's parent should be: refused, named. */
    char *dir = lr_test_tmpdir();
    char *file = lr_test_write(dir, "f", "x", (size_t)-1);
    setenv("MESA_SHADER_CACHE_DIR", file, 1);
    assert_int_equal(lr_gl_shader_cache_check(&e), LR_EIO);
    assert_non_null(strstr(e.msg, "Mesa shader cache"));
    assert_non_null(strstr(e.msg, file));
    setenv("MESA_SHADER_CACHE_DIR", dir, 1);
    assert_int_equal(lr_gl_shader_cache_check(&e), lr_dir_check_writable(dir, LR_GL_SHADER_CACHE_MIN_FREE, NULL));
    free(file);
    lr_test_rmtree(dir);
    for (int i = 0; i < 7; i++) {
        set_env(names[i], saved[i]);
        free(saved[i]);
    }
}

/* Whole-file reads take regular files only, up to the caller's cap: a FIFO is refused at once
 * (it blocked the open for ever), a symlink to /dev/zero is refused as a device (it was read
 * until memory ran out), a file one byte over the cap is refused, one at the cap is read. */
static void test_file_read_regular_only(void **state)
{
    (void)state;
    char *dir = lr_test_tmpdir();
    char *fifo = lr_test_path(dir, "fifo.json");
    assert_int_equal(mkfifo(fifo, 0600), 0);
    char *zero = lr_test_path(dir, "zero.json");
    assert_int_equal(symlink("/dev/zero", zero), 0);
    char *data = NULL;
    size_t len = 99;
    lr_err e = {0};
    alarm(10); /* a regression would block here: fail, do not hang */
    assert_int_equal(lr_file_read(fifo, LR_FILE_MAX_TEXT, &data, &len, &e), LR_EIO);
    alarm(0);
    assert_null(data);
    assert_int_equal(len, 0);
    assert_non_null(strstr(e.msg, fifo));
    assert_non_null(strstr(e.msg, "a FIFO, not a regular file"));
    assert_int_equal(lr_file_read(zero, LR_FILE_MAX_TEXT, &data, &len, &e), LR_EIO);
    assert_non_null(strstr(e.msg, zero));
    assert_non_null(strstr(e.msg, "a character device"));
    assert_int_equal(lr_file_read(dir, LR_FILE_MAX_TEXT, &data, &len, &e), LR_EIO);
    assert_non_null(strstr(e.msg, "a directory"));
    char body[100];
    memset(body, 'a', sizeof body);
    char *file = lr_test_write(dir, "f.json", body, sizeof body);
    assert_int_equal(lr_file_read(file, 99, &data, &len, &e), LR_EIO);
    assert_non_null(strstr(e.msg, file));
    assert_non_null(strstr(e.msg, "larger than 99 bytes"));
    assert_null(data);
    assert_int_equal(lr_file_read(file, 100, &data, &len, &e), LR_OK);
    assert_int_equal(len, 100);
    assert_int_equal(data[100], '\0');
    assert_memory_equal(data, body, 100);
    free(data);
    /* A symlink to a regular file is fine. */
    char *link = lr_test_path(dir, "link.json");
    assert_int_equal(symlink(file, link), 0);
    assert_int_equal(lr_file_read(link, 100, &data, &len, &e), LR_OK);
    assert_int_equal(len, 100);
    free(data);
    free(link);
    free(file);
    free(zero);
    free(fifo);
    lr_test_rmtree(dir);
}

static unsigned mode_of(const char *path)
{
    struct stat st;
    assert_int_equal(stat(path, &st), 0);
    return (unsigned)(st.st_mode & 07777);
}

/* Written files get the mode asked for less the umask, as open(2) gives (it was 0644 whatever
 * the umask); the umask is read without changing it (lr_umask_get). Private files (calibrations,
 * the rig's state) are 0640 at most. */
static void test_atomic_file_mode_follows_umask(void **state)
{
    (void)state;
    char *dir = lr_test_tmpdir();
    char *path = lr_test_path(dir, "f.bin");
    lr_err e = {0};
    static const struct {
        mode_t mask;
        unsigned data, priv;
    } cases[] = {{022, 0644, 0640}, {027, 0640, 0640}, {077, 0600, 0600}, {002, 0664, 0640}};
    mode_t old = umask(022);
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        umask(cases[i].mask);
        assert_int_equal(lr_umask_get(), cases[i].mask);
        assert_int_equal(lr_atomic_write(path, "x", 1, &e), LR_OK);
        if (mode_of(path) != cases[i].data)
            fail_msg("umask %03o: data file %03o, expected %03o", (unsigned)cases[i].mask,
                     mode_of(path), cases[i].data);
        assert_int_equal(lr_atomic_write_mode(path, "y", 1, LR_FILE_MODE_PRIVATE, &e), LR_OK);
        if (mode_of(path) != cases[i].priv)
            fail_msg("umask %03o: private file %03o, expected %03o", (unsigned)cases[i].mask,
                     mode_of(path), cases[i].priv);
    }
    umask(old);
    free(path);
    lr_test_rmtree(dir);
}

/* Sets a file's access and modification times to now - age_s. */
static void age(const char *dir, const char *name, time_t now, long age_s, size_t bytes)
{
    char *path = lr_test_path(dir, name);
    char *body = calloc(1, bytes + 1);
    memset(body, 'c', bytes);
    lr_test_put(path, body, bytes);
    struct timeval tv[2] = {{now - age_s, 0}, {now - age_s, 0}};
    assert_int_equal(utimes(path, tv), 0);
    free(body);
    free(path);
}

static int exists(const char *dir, const char *name)
{
    char *path = lr_test_path(dir, name);
    struct stat st;
    int ok = stat(path, &st) == 0;
    free(path);
    return ok;
}

/* Stale temps of our exact pattern are swept (a kill between mkstemp and rename left them for
 * ever), fresh ones and other people's files are kept; over the cap the least recently used
 * cache files go first until the rest fit. */
static void test_cache_dir_tidy(void **state)
{
    (void)state;
    int temp;
    assert_true(lr_cache_dir_ours("transrad-0123456789abcdef.bin", &temp) && !temp);
    assert_true(lr_cache_dir_ours("objlight-0123456789abcdef.bin.tmpAb3xYz", &temp) && temp);
    assert_false(lr_cache_dir_ours("transrad-0123456789ABCDEF.bin", &temp));
    assert_false(lr_cache_dir_ours("transrad-0123456789abcde.bin", &temp));
    assert_false(lr_cache_dir_ours("transrad-0123456789abcdef.bin.tmpAb3xY", &temp));
    assert_false(lr_cache_dir_ours("transrad-0123456789abcdef.bin.tmpAb3xYzz", &temp));
    assert_false(lr_cache_dir_ours("notes.txt.tmpAb3xYz", &temp));
    assert_false(lr_cache_dir_ours("mesa_shader_cache", &temp));

    char *dir = lr_test_tmpdir();
    time_t now = time(NULL);
    const char *a = "transrad-000000000000000a.bin", *b = "objlight-000000000000000b.bin",
               *c = "transrad-000000000000000c.bin";
    age(dir, a, now, 3000, 4000); /* least recently used */
    age(dir, b, now, 2000, 3000);
    age(dir, c, now, 1000, 2000);
    age(dir, "transrad-000000000000000a.bin.tmpQw3rTy", now, 120, 100); /* stale */
    age(dir, "transrad-000000000000000c.bin.tmpFr35hh", now, 5, 100);   /* a writer's */
    age(dir, "keep.bin.tmpQw3rTy", now, 5000, 100);                     /* not ours */
    lr_cache_tidy t;
    lr_err e = {0};
    assert_int_equal(lr_cache_dir_tidy(dir, 9000, now, &t, &e), LR_OK);
    assert_int_equal(t.temps_removed, 1);
    assert_int_equal(t.files_removed, 0);
    assert_int_equal(t.bytes_before, 9000);
    assert_false(exists(dir, "transrad-000000000000000a.bin.tmpQw3rTy"));
    assert_true(exists(dir, "transrad-000000000000000c.bin.tmpFr35hh"));
    assert_true(exists(dir, "keep.bin.tmpQw3rTy"));
    /* Cap 4999: a (4000) goes first (5000 left, still over), then b (3000): 2000 left. */
    assert_int_equal(lr_cache_dir_tidy(dir, 4999, now, &t, &e), LR_OK);
    assert_int_equal(t.files_removed, 2);
    assert_int_equal(t.bytes_after, 2000);
    assert_false(exists(dir, a));
    assert_false(exists(dir, b));
    assert_true(exists(dir, c));
    /* A missing folder: nothing to do. */
    char *none = lr_test_path(dir, "none");
    assert_int_equal(lr_cache_dir_tidy(none, 0, now, &t, &e), LR_OK);
    free(none);
    uint64_t cap;
    setenv("LAMPRIG_CACHE_MAX_MB", "12", 1);
    assert_int_equal(lr_cache_max_bytes(&cap, &e), LR_OK);
    assert_true(cap == (uint64_t)12 << 20);
    setenv("LAMPRIG_CACHE_MAX_MB", "-3", 1);
    assert_int_equal(lr_cache_max_bytes(&cap, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "LAMPRIG_CACHE_MAX_MB"));
    assert_true(cap == LR_CACHE_MAX_BYTES_DEFAULT);
    unsetenv("LAMPRIG_CACHE_MAX_MB");
    lr_test_rmtree(dir);
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
        cmocka_unit_test(test_dir_check_writable),
        cmocka_unit_test(test_cache_dir_tidy),
        cmocka_unit_test(test_atomic_file_mode_follows_umask),
        cmocka_unit_test(test_file_read_regular_only),
        cmocka_unit_test(test_shader_cache_dir),
        cmocka_unit_test(test_progress_lines),
        cmocka_unit_test(test_progress_tty_and_quiet),
    };
    return cmocka_run_group_tests_name("base", tests, NULL, NULL);
}
