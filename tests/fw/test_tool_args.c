/* The tools' command lines (build/bin/lamprig-NAME, firmware/tool.h): each one's --help lists
 * every option it has always taken (the spellings scripts, the bench, READMEs and the man page
 * use), an unknown flag and an out-of-range value are one line on stderr naming the flag with
 * exit status 2, and one ordinary invocation still does its work. The release binaries are
 * run as a user runs them (built by `make test` before the tests); every case takes well
 * under a second (no bench section, no GPU render). lamprig-modbus-sim's serving with
 * --port/--panel/--trace is test_modbus_sim's, lamprig-capsim's full capture
 * test_calib_compare's. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tests/support/cli.h"
#include "tests/support/fs.h"

#define BIN "build/bin/"

/* Whether text has the line "  FLAG" followed by a space or the end of the line: the option
 * list of the generated help (the synopsis has "[FLAG" instead). */
static int lists_option(const char *text, const char *flag)
{
    size_t n = strlen(flag);
    for (const char *p = text; (p = strstr(p, flag)); p += n)
        if (p - text >= 3 && p[-1] == ' ' && p[-2] == ' ' && p[-3] == '\n' &&
            (p[n] == ' ' || p[n] == '\n'))
            return 1;
    return 0;
}

static void check_help(const char *tool, const char *const *flags)
{
    char *dir = lr_test_tmpdir();
    assert_int_equal(lr_test_run_cli(dir, BIN "%s --help", tool), 0);
    char *out = lr_test_slurp(dir, "out");
    char head[128];
    snprintf(head, sizeof head, "usage: %s ", tool);
    assert_true(strncmp(out, head, strlen(head)) == 0);
    for (int i = 0; flags[i]; i++)
        if (!lists_option(out, flags[i]))
            fail_msg("%s --help does not list %s:\n%s", tool, flags[i], out);
    free(out);
    lr_test_rmtree(dir);
}

/* Runs `tool args`: exit status 2 and stderr one line "TOOL: ..." holding every word of
 * want (the flag, the value); stdout empty (nothing ran). */
static void check_usage_error(const char *tool, const char *args, const char *const *want)
{
    char *dir = lr_test_tmpdir();
    int st = lr_test_run_cli(dir, BIN "%s %s", tool, args);
    char *err = lr_test_slurp(dir, "err"), *out = lr_test_slurp(dir, "out");
    if (st != 2)
        fail_msg("%s %s: exit %d, not 2: %s", tool, args, st, err);
    size_t len = strlen(err), n = strlen(tool);
    assert_true(len > n + 2 && strncmp(err, tool, n) == 0 && err[n] == ':');
    assert_true(err[len - 1] == '\n' && strchr(err, '\n') == err + len - 1);
    for (int i = 0; want[i]; i++)
        if (!strstr(err, want[i]))
            fail_msg("%s %s: the message does not name '%s': %s", tool, args, want[i], err);
    assert_int_equal(strlen(out), 0);
    free(err);
    free(out);
    lr_test_rmtree(dir);
}

#define WORDS(...) ((const char *const[]){__VA_ARGS__, NULL})

/* ---- lamprig-bench ------------------------------------------------------------------- */

/* The sections tools/bench/README.md documents and `make bench` runs. */
static const char *const bench_sections[] = {"optics", "cpu",    "render", "rig",
                                             "sweep",  "models", "dimmer", "camera",
                                             "console", "memory", NULL};

static void test_bench(void **state)
{
    (void)state;
    check_help("lamprig-bench",
               WORDS("--list", "--update-front", "--figures", "--check", "--write"));
    check_usage_error("lamprig-bench", "--no-such-flag", WORDS("'--no-such-flag'"));
    check_usage_error("lamprig-bench", "nosuch", WORDS("'nosuch'"));
    /* A flag valid only with another: named, nothing runs (no section starts). */
    check_usage_error("lamprig-bench", "--check rig", WORDS("--check", "--figures"));
    check_usage_error("lamprig-bench", "--figures --check --write", WORDS("--check", "--write"));
    check_usage_error("lamprig-bench", "--figures rig", WORDS("'rig'"));
    /* --list: one line per section, in the run order. */
    char *dir = lr_test_tmpdir();
    assert_int_equal(lr_test_run_cli(dir, BIN "lamprig-bench --list"), 0);
    char *out = lr_test_slurp(dir, "out");
    const char *p = out;
    for (int i = 0; bench_sections[i]; i++) {
        char line[32];
        snprintf(line, sizeof line, "  %s ", bench_sections[i]);
        const char *q = strstr(p, line);
        if (!q)
            fail_msg("--list: no line for '%s' after the previous section:\n%s",
                     bench_sections[i], out);
        p = q + 1;
    }
    free(out);
    lr_test_rmtree(dir);
}

/* ---- lamprig-modbus-sim -------------------------------------------------------------- */

static void test_modbus_sim_args(void **state)
{
    (void)state;
    check_help("lamprig-modbus-sim", WORDS("--port", "--panel", "--sweep", "--trace"));
    check_usage_error("lamprig-modbus-sim", "--no-such-flag", WORDS("'--no-such-flag'"));
    check_usage_error("lamprig-modbus-sim", "--port 0", WORDS("--port", "0", "1..65535"));
    check_usage_error("lamprig-modbus-sim", "--port 65536", WORDS("--port", "65536"));
    check_usage_error("lamprig-modbus-sim", "--panel 1001", WORDS("--panel", "1001", "0..1000"));
    check_usage_error("lamprig-modbus-sim", "--sweep -1", WORDS("--sweep", "-1", ">= 0"));
    check_usage_error("lamprig-modbus-sim", "--panel", WORDS("--panel", "needs a value"));
}

/* ---- lamprig-cpuref ------------------------------------------------------------------ */

#define SHELL_SCENE "configs/scenes/sphere_shell.json"

static void test_cpuref(void **state)
{
    (void)state;
    check_help("lamprig-cpuref",
               WORDS("--scene", "--out", "--var", "--width", "--height", "--samples", "--twin",
                     "--frames", "--vpl", "--no-vpl", "--threads", "--seed", "--set",
                     "--compare"));
    check_usage_error("lamprig-cpuref", "--scene a.json --out a.pfm --no-such-flag",
                      WORDS("'--no-such-flag'"));
    check_usage_error("lamprig-cpuref", "--scene a.json --out a.pfm --width 0",
                      WORDS("--width", "0", "1..16384"));
    check_usage_error("lamprig-cpuref", "--scene a.json --out a.pfm --threads 65",
                      WORDS("--threads", "65"));
    check_usage_error("lamprig-cpuref", "--scene a.json", WORDS("--out", "required"));
    /* 4x3 pixels, one sample and one VPL: the PFM has the asked size, the variance image
     * its default name (OUT with .var.pfm for .pfm). */
    char *dir = lr_test_tmpdir();
    int st = lr_test_run_cli(dir, BIN "lamprig-cpuref --scene " SHELL_SCENE " --width 4 "
                                  "--height 3 --samples 1 --vpl 1 --threads 1 --seed 7 "
                                  "--out %s/a.pfm", dir);
    if (st)
        fail_msg("lamprig-cpuref: exit %d: %s", st, lr_test_slurp(dir, "err"));
    char *pfm = lr_test_slurp(dir, "a.pfm");
    assert_true(strncmp(pfm, "PF\n4 3\n", 7) == 0);
    free(pfm);
    char *var = lr_test_slurp(dir, "a.var.pfm");
    assert_true(strncmp(var, "PF\n4 3\n", 7) == 0);
    free(var);
    lr_test_rmtree(dir);
}

/* ---- lamprig-transrad ---------------------------------------------------------------- */

static void test_transrad(void **state)
{
    (void)state;
    check_help("lamprig-transrad", WORDS("--set", "--patch", "--receiver", "--rays",
                                         "--transfer-mb", "--thin-wall", "--split", "--no-cache"));
    check_usage_error("lamprig-transrad", SHELL_SCENE " --no-such-flag", WORDS("'--no-such-flag'"));
    check_usage_error("lamprig-transrad", SHELL_SCENE " --patch -1", WORDS("--patch", "-1"));
    check_usage_error("lamprig-transrad", SHELL_SCENE " --rays 1.5", WORDS("--rays", "1.5"));
    check_usage_error("lamprig-transrad", SHELL_SCENE " --thin-wall maybe",
                      WORDS("--thin-wall", "'maybe'", "auto, off or on"));
    check_usage_error("lamprig-transrad", "--patch 40", WORDS("SCENE.json"));
    /* The scene first (as the READMEs write it) and coarse settings: the solve's lines. */
    char *dir = lr_test_tmpdir();
    int st = lr_test_run_cli(dir, BIN "lamprig-transrad " SHELL_SCENE " --no-cache --patch 40 "
                                  "--receiver 200 --rays 16 --thin-wall off");
    char *out = lr_test_slurp(dir, "out");
    if (st)
        fail_msg("lamprig-transrad: exit %d: %s", st, lr_test_slurp(dir, "err"));
    assert_non_null(strstr(out, "scene sphere_shell: "));
    assert_non_null(strstr(out, "\nlight 0: direct "));
    free(out);
    /* --set reaches the scene: an unknown field is the scene's error (exit 1), not usage. */
    st = lr_test_run_cli(dir, BIN "lamprig-transrad " SHELL_SCENE " --no-cache --set "
                              "render.no_such_field=1");
    char *err = lr_test_slurp(dir, "err");
    assert_int_equal(st, 1);
    assert_non_null(strstr(err, "no_such_field"));
    free(err);
    lr_test_rmtree(dir);
}

/* ---- lamprig-capsim ------------------------------------------------------------------ */

static void test_capsim(void **state)
{
    (void)state;
    check_help("lamprig-capsim",
               WORDS("--scene", "--calib", "--out", "--exposure", "--gain", "--noise", "--seed",
                     "--bits", "--vignette", "--gamma", "--cpu", "--frames", "--hdr", "--set",
                     "--quiet"));
    const char *req = "--scene a.json --calib rig --out a.png";
    char args[256];
    /* One of each reader (a range, the 64-bit seed, a choice, the two hand-read values); each
     * start costs lamprig-capsim about 0.2 s (OpenCV's shared libraries), so not every flag.
     * Automatic: the WORDS compound literals live in this block. */
    const struct {
        const char *extra;
        const char *const *want;
    } bad[] = {
        {"--no-such-flag", WORDS("'--no-such-flag'")},
        {"--exposure 0", WORDS("--exposure", "0")},
        {"--seed 4294967296", WORDS("--seed", "4294967296")},
        {"--bits 12", WORDS("--bits", "'12'")},
        {"--noise 0,4", WORDS("--noise", "'0,4'")},
        {"--vignette poly:1", WORDS("--vignette", "poly:1")},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        snprintf(args, sizeof args, "%s %s", req, bad[k].extra);
        check_usage_error("lamprig-capsim", args, bad[k].want);
    }
    check_usage_error("lamprig-capsim", "--scene a.json --out a.png", WORDS("--calib", "required"));
    /* Every option at an edge of its range is accepted: the run goes on to the calibration
     * folder, which has no camera.json here: that failure (exit 1, no usage pointer). */
    char *dir = lr_test_tmpdir();
    int st = lr_test_run_cli(dir, BIN "lamprig-capsim --scene " SHELL_SCENE " --calib %s "
                                  "--out %s/a.png --seed 4294967295 --bits 16 --noise none "
                                  "--exposure 1e-9 --gain 1e12 --gamma 0.1 --frames 1 "
                                  "--vignette cos4 --cpu --quiet", dir, dir);
    char *err = lr_test_slurp(dir, "err");
    if (st != 1 || !strstr(err, "camera.json") || strstr(err, "--help"))
        fail_msg("lamprig-capsim: exit %d: %s", st, err);
    free(err);
    lr_test_rmtree(dir);
}

/* ---- lamprig-reference: two commands, each its own table ------------------------------ */

static void test_reference(void **state)
{
    (void)state;
    check_help("lamprig-reference render",
               WORDS("--scene", "--out", "--variance", "--cache", "--cache-dir", "--width",
                     "--height", "--spp", "--pass", "--threads", "--seed", "--progress",
                     "--quiet"));
    check_help("lamprig-reference validate", WORDS("--photons", "--threads", "--seed"));
    check_usage_error("lamprig-reference render", "--scene a.json --width 0",
                      WORDS("--width", "0", "1..16384"));
    check_usage_error("lamprig-reference render", "--scene a.json --spp 1.5",
                      WORDS("--spp", "1.5"));
    check_usage_error("lamprig-reference render", "--out a.pfm", WORDS("--scene", "required"));
    check_usage_error("lamprig-reference render", "--scene a.json --no-such-flag",
                      WORDS("'--no-such-flag'"));
    check_usage_error("lamprig-reference validate", "--seed -1", WORDS("--seed", "-1"));
    check_usage_error("lamprig-reference", "bogus", WORDS("unknown command 'bogus'"));
    /* The top-level help lists both commands; no command at all is a usage error. */
    char *dir = lr_test_tmpdir();
    assert_int_equal(lr_test_run_cli(dir, BIN "lamprig-reference --help"), 0);
    char *out = lr_test_slurp(dir, "out");
    assert_non_null(strstr(out, "  render "));
    assert_non_null(strstr(out, "  validate "));
    free(out);
    assert_int_equal(lr_test_run_cli(dir, BIN "lamprig-reference"), 2);
    /* An ordinary run: validate with few photons prints its table. */
    int st = lr_test_run_cli(dir, BIN "lamprig-reference validate --photons 2000 --threads 1 "
                                  "--seed 5");
    if (st)
        fail_msg("lamprig-reference validate: exit %d: %s", st, lr_test_slurp(dir, "err"));
    out = lr_test_slurp(dir, "out");
    assert_non_null(strstr(out, "| quantity |"));
    assert_non_null(strstr(out, "2000 photons per problem"));
    free(out);
    lr_test_rmtree(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bench),
        cmocka_unit_test(test_modbus_sim_args),
        cmocka_unit_test(test_cpuref),
        cmocka_unit_test(test_transrad),
        cmocka_unit_test(test_capsim),
        cmocka_unit_test(test_reference),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
