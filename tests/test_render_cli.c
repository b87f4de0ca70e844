/* lamprig render, the command: files written, stats per frame, --events applied before their
 * frame (a dimmer event re-runs composition alone), --set, and one-line errors with exit
 * status 2 for bad arguments, naming FILE:LINE for a bad event. Runs build/bin/lamprig (built
 * by `make test` before the tests). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include "render/base/file.h"
#include "render/image/image.h"
#include "tests/support/fs.h"

#define SMALL "--width 32 --height 24 --set render.K=4 --set render.N=2 --set render.map_size=32 " \
              "--set render.gbuffer_size=32 --set render.vpl_map_size=8 --set render.N_vpl=16 "  \
              "--set render.frames=2"

static char *dir;

static int setup(void **state)
{
    dir = lr_test_tmpdir();
    return 0;
}

static int teardown(void **state)
{
    free(dir);
    return 0;
}

/* Runs a shell command with stderr into dir/err; returns the exit status. */
static int run(const char *fmt, ...)
{
    char cmd[2048], full[2400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(cmd, sizeof cmd, fmt, ap);
    va_end(ap);
    snprintf(full, sizeof full, "%s >%s/out 2>%s/err", cmd, dir, dir);
    int st = system(full);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static char *slurp(const char *name)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    char *t = NULL;
    size_t n;
    lr_err e = {0};
    if (lr_file_read(path, &t, &n, &e))
        fail_msg("%s", e.msg);
    return t;
}

static void test_render_writes_images_and_stats(void **state)
{
    char ev[512];
    snprintf(ev, sizeof ev, "%s/events.txt", dir);
    FILE *f = fopen(ev, "w");
    fputs("# dimmer halfway down after convergence\n2 light.intensity 0.0025\n", f);
    fclose(f);
    int st = run("./build/bin/lamprig render --scene configs/scenes/candle.json " SMALL
                 " --frames 4 --events %s --out %s/c.png --hdr %s/c.pfm --stats %s/s.json",
                 ev, dir, dir, dir);
    char *err = slurp("err");
    if (st != 0)
        fail_msg("exit %d: %s", st, err);
    free(err);
    char *out = slurp("out");
    assert_non_null(strstr(out, "/c.png"));
    free(out);
    char *js = slurp("s.json");
    assert_non_null(strstr(js, "\"scene\":\"candle\""));
    assert_non_null(strstr(js, "\"width\":32,\"height\":24,\"uncovered_pixels\":"));
    assert_non_null(strstr(js, "{\"index\":0,\"passes\":[\"gbuffer\",\"radiosity\",\"vpl\",\"compose\"]"));
    assert_non_null(strstr(js, "{\"index\":1,\"passes\":[\"radiosity\",\"vpl\",\"compose\"]"));
    /* The event before frame 2: composition alone. Frame 3: converged, but the flame
     * flickers on the renderer's clock (frame i at i / 30 s): composition alone again. */
    assert_non_null(strstr(js, "{\"index\":2,\"passes\":[\"compose\"],\"ms\":{\"compose\":"));
    assert_non_null(strstr(js, "{\"index\":3,\"passes\":[\"compose\"],\"ms\":{\"compose\":"));
    assert_non_null(strstr(js, "\"samples\":2,\"converged\":true,\"time_s\":0.1}"));
    free(js);
    /* A steady flame (flicker.amplitude 0) at 10 fps: frame 3 has nothing left to do. */
    st = run("./build/bin/lamprig render --scene configs/scenes/candle.json " SMALL
             " --frames 4 --fps 10 --set lights[0].flicker.amplitude=0 --events %s --stats %s/s.json",
             ev, dir);
    if (st != 0)
        fail_msg("exit %d (steady flame)", st);
    js = slurp("s.json");
    assert_non_null(strstr(js, "{\"index\":3,\"passes\":[],\"ms\":{},\"total_ms\":0.0000,\"samples\":2"));
    assert_non_null(strstr(js, "\"time_s\":0.3}"));
    free(js);
    char path[512];
    lr_image img = {0};
    lr_err e = {0};
    snprintf(path, sizeof path, "%s/c.pfm", dir);
    if (lr_image_read_pfm(path, &img, &e))
        fail_msg("%s", e.msg);
    assert_int_equal(img.width, 32);
    assert_int_equal(img.height, 24);
    double sum = 0.0;
    for (int i = 0; i < 32 * 24 * 3; i++) {
        assert_true(img.rgb[i] >= 0.0f && img.rgb[i] < 1e30f);
        sum += img.rgb[i];
    }
    assert_true(sum > 0.0);
    lr_image_free(&img);
    snprintf(path, sizeof path, "%s/c.png", dir);
    if (lr_image_read_png(path, &img, &e))
        fail_msg("%s", e.msg);
    assert_int_equal(img.width, 32);
    lr_image_free(&img);
}

static void expect_usage(const char *args, const char *needle)
{
    int st = run("./build/bin/lamprig render %s", args);
    char *err = slurp("err");
    if (st != 2 || !strstr(err, needle))
        fail_msg("'%s': exit %d, stderr '%s' (expected 2 and '%s')", args, st, err, needle);
    /* One line. */
    char *nl = strchr(err, '\n');
    assert_true(nl && nl[1] == '\0');
    free(err);
}

static void test_bad_arguments(void **state)
{
    expect_usage("", "--scene");
    expect_usage("--scene configs/scenes/candle.json --frames 0", "--frames");
    expect_usage("--scene configs/scenes/candle.json --width x", "--width");
    expect_usage("--scene configs/scenes/candle.json --bogus 1", "--bogus");
    expect_usage("--scene configs/scenes/candle.json --fps 0", "--fps");
    expect_usage("--scene configs/scenes/candle.json --set light.intensity", "key=value");
    expect_usage("--scene configs/scenes/candle.json --set light.intensity=-1", "light.intensity");
    char ev[512];
    snprintf(ev, sizeof ev, "%s/bad.txt", dir);
    FILE *f = fopen(ev, "w");
    fputs("0 light.intensity 0.5\n\n3 light.nonsense 2\n", f);
    fclose(f);
    char args[1024], needle[600];
    snprintf(args, sizeof args, "--scene configs/scenes/candle.json " SMALL " --frames 4 --events %s", ev);
    snprintf(needle, sizeof needle, "%s:3:", ev);
    expect_usage(args, needle);
    f = fopen(ev, "w");
    fputs("# frames must be numbers\nfour light.intensity 0.5\n", f);
    fclose(f);
    snprintf(needle, sizeof needle, "%s:2:", ev);
    expect_usage(args, needle);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_render_writes_images_and_stats),
        cmocka_unit_test(test_bad_arguments),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
