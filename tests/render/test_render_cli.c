/* lamprig render, the command: files written, stats per frame, --events applied before their
 * frame (a dimmer event re-runs composition alone), --set, and one-line errors with exit
 * status 2 for bad arguments, naming FILE:LINE for a bad event. Runs build/bin/lamprig (built
 * by `make test` before the tests). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "render/base/file.h"
#include "render/base/json.h"
#include "render/image/image.h"
#include "render/scene/scene.h"
#include "tests/support/cli.h"
#include "tests/support/fs.h"
#include "tests/support/near.h"

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
    lr_test_rmtree(dir); /* free(dir) alone left /tmp/lamprig-test-* behind */
    return 0;
}

/* The child runs with this file's scratch folder (tests/support/cli.h). */
#define run(...) lr_test_run_cli(dir, __VA_ARGS__)

#define slurp(name) lr_test_slurp(dir, name)

/* Frame i of a --stats file: its passes joined by ',' must be `passes`; samples, converged
 * and time_s are checked when samples >= 0. */
static void expect_frame(const lr_json *j, int i, const char *passes, int samples,
                         bool converged, double time_s)
{
    lr_err e = {0};
    lr_jnode frames = lr_json_get(j, lr_json_root(j), "frames");
    assert_int_not_equal(frames, LR_JNONE);
    lr_jnode f = lr_json_at(j, frames, i);
    assert_int_not_equal(f, LR_JNONE);
    long index = -1;
    assert_int_equal(lr_json_get_int(j, f, "index", true, &index, &e), LR_OK);
    assert_int_equal(index, i);
    lr_jnode p = lr_json_get(j, f, "passes"), ms = lr_json_get(j, f, "ms");
    char got[128] = "", name[32];
    for (int k = 0; k < lr_json_count(j, p); k++) {
        assert_int_equal(lr_json_string(j, lr_json_at(j, p, k), "passes", name, sizeof name, &e),
                         LR_OK);
        snprintf(got + strlen(got), sizeof got - strlen(got), "%s%s", k ? "," : "", name);
        /* every pass that ran has its time, and only those */
        assert_int_not_equal(lr_json_get(j, ms, name), LR_JNONE);
    }
    assert_int_equal(lr_json_count(j, ms), lr_json_count(j, p));
    assert_string_equal(got, passes);
    if (samples < 0)
        return;
    long n = -1;
    bool conv = !converged;
    double t = -1;
    assert_int_equal(lr_json_get_int(j, f, "samples", true, &n, &e), LR_OK);
    assert_int_equal(lr_json_get_bool(j, f, "converged", true, &conv, &e), LR_OK);
    assert_int_equal(lr_json_get_number(j, f, "time_s", true, &t, &e), LR_OK);
    assert_int_equal(n, samples);
    assert_true(conv == converged);
    assert_near(t, time_s, 1e-9);
}

static lr_json *load_stats(void)
{
    char path[512];
    snprintf(path, sizeof path, "%s/s.json", dir);
    lr_json *j = NULL;
    lr_err e = {0};
    if (lr_json_load(path, &j, &e))
        fail_msg("%s", e.msg);
    return j;
}

/* The sum of a 32x24 HDR image the command wrote into dir, every value of which must be finite
 * and non-negative (radiance). */
static double radiance_sum(const char *file)
{
    char path[512];
    lr_image img = {0};
    lr_err e = {0};
    snprintf(path, sizeof path, "%s/%s", dir, file);
    if (lr_image_read_pfm(path, &img, &e))
        fail_msg("%s", e.msg);
    assert_int_equal(img.width, 32);
    assert_int_equal(img.height, 24);
    double sum = 0.0;
    for (int i = 0; i < 32 * 24 * 3; i++) {
        assert_true(img.rgb[i] >= 0.0f && img.rgb[i] < 1e30f);
        sum += img.rgb[i];
    }
    lr_image_free(&img);
    return sum;
}

static void test_render_writes_images_and_stats(void **state)
{
    char ev[512];
    snprintf(ev, sizeof ev, "%s/events.txt", dir);
    FILE *f = fopen(ev, "w");
    fputs("# dimmer halfway down after convergence\n2 light.intensity 0.0025\n", f);
    fclose(f);
    /* The directional dipole, which accumulates: the plan's diffusion_grid converges after
     * its first frame (test_deterministic_stops_early). */
    int st = run("./build/bin/lamprig render --scene configs/scenes/candle.json " SMALL
                 " --set objects[0].model=directional_dipole"
                 " --frames 4 --events %s --out %s/c.png --hdr %s/c.pfm --stats %s/s.json",
                 ev, dir, dir, dir);
    char *err = slurp("err");
    if (st != 0)
        fail_msg("exit %d: %s", st, err);
    free(err);
    char *out = slurp("out");
    assert_non_null(strstr(out, "/c.png"));
    free(out);
    lr_json *j = load_stats();
    lr_err e = {0};
    char name[64];
    assert_int_equal(lr_json_get_string(j, lr_json_root(j), "scene", true, name, sizeof name, &e),
                     LR_OK);
    assert_string_equal(name, "candle");
    long wh[2] = {0, 0};
    assert_int_equal(lr_json_get_int(j, lr_json_root(j), "width", true, &wh[0], &e), LR_OK);
    assert_int_equal(lr_json_get_int(j, lr_json_root(j), "height", true, &wh[1], &e), LR_OK);
    assert_int_equal(wh[0], 32);
    assert_int_equal(wh[1], 24);
    assert_int_not_equal(lr_json_get(j, lr_json_root(j), "uncovered_pixels"), LR_JNONE);
    /* Passes are listed in bit order (render/renderer.h), not the order they ran in. */
    expect_frame(j, 0, "gbuffer,radiosity,vpl,compose,blend,irradiance", -1, false, 0);
    expect_frame(j, 1, "radiosity,vpl,compose,blend,irradiance", -1, false, 0);
    /* The event before frame 2: the blend alone. Frame 3: converged, but the flame flickers
     * on the renderer's clock (frame i at i / 30 s): the blend alone again. */
    expect_frame(j, 2, "blend", -1, false, 0);
    expect_frame(j, 3, "blend", 2, true, 0.1);
    lr_json_destroy(j);
    /* A steady flame (flicker.amplitude 0) at 10 fps: frame 3 has nothing left to do. */
    st = run("./build/bin/lamprig render --scene configs/scenes/candle.json " SMALL
             " --set objects[0].model=directional_dipole"
             " --frames 4 --fps 10 --set lights[0].flicker.amplitude=0 --events %s --stats %s/s.json",
             ev, dir);
    if (st != 0)
        fail_msg("exit %d (steady flame)", st);
    j = load_stats();
    expect_frame(j, 3, "", 2, true, 0.3);
    lr_jnode f3 = lr_json_at(j, lr_json_get(j, lr_json_root(j), "frames"), 3);
    double total = -1;
    assert_int_equal(lr_json_get_number(j, f3, "total_ms", true, &total, &e), LR_OK);
    assert_near(total, 0.0, 0.0);
    lr_json_destroy(j);
    assert_true(radiance_sum("c.pfm") > 0.0);
    char path[512];
    lr_image img = {0};
    snprintf(path, sizeof path, "%s/c.png", dir);
    if (lr_image_read_png(path, &img, &e))
        fail_msg("%s", e.msg);
    assert_int_equal(img.width, 32);
    lr_image_free(&img);
}

/* configs/scenes/jar_candle.json (issue 12's untuned scene) renders headless through the
 * command: its radiance is finite and non-negative everywhere, and light reaches the image
 * (82 % of the flame's light enters the wax, the rest leaves through the opening onto the
 * wall: test_scene's escape cone), so the sum is positive. */
static void test_render_jar_candle(void **state)
{
    (void)state;
    int st = run("./build/bin/lamprig render --scene configs/scenes/jar_candle.json " SMALL
                 " --frames 2 --hdr %s/j.pfm --stats %s/s.json", dir, dir);
    char *err = slurp("err");
    if (st != 0)
        fail_msg("exit %d: %s", st, err);
    free(err);
    lr_json *j = load_stats();
    lr_err e = {0};
    char name[64];
    assert_int_equal(lr_json_get_string(j, lr_json_root(j), "scene", true, name, sizeof name, &e),
                     LR_OK);
    assert_string_equal(name, "jar_candle");
    lr_json_destroy(j);
    assert_true(radiance_sum("j.pfm") > 0.0);
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

/* Output paths are checked before anything renders: a directory, or a file in a folder that
 * does not exist, is a bad argument (exit 2, one line naming the flag), and no frame is
 * rendered (stdout has no summary line) and no other output is written. */
static void test_output_paths_checked_first(void **state)
{
    char args[2048], ok[600];
    snprintf(ok, sizeof ok, "%s/ok.png", dir);
    const char *cases[][2] = {
        {"--out %s", "is a directory"},
        {"--out %s/ok.png --hdr %s/missing/x.pfm", "--hdr"},
        {"--out %s/ok.png --stats %s", "--stats"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char paths[1400];
        snprintf(paths, sizeof paths, cases[k][0], dir, dir);
        snprintf(args, sizeof args, "--scene configs/scenes/candle.json " SMALL " --frames 1 %s",
                 paths);
        expect_usage(args, cases[k][1]);
        char *out = slurp("out");
        if (strstr(out, "lamprig render:"))
            fail_msg("'%s': rendered before refusing its output: '%s'", args, out);
        free(out);
        assert_int_equal(access(ok, F_OK), -1);
    }
}

/* Expects exit status 2, no summary line on stdout, and every needle on stderr. */
static void expect_refused(const char *args, const char *const *needles, int n)
{
    int st = run("./build/bin/lamprig render %s", args);
    char *err = slurp("err"), *out = slurp("out");
    if (st != 2)
        fail_msg("'%s': exit %d (expected 2), stderr '%s'", args, st, err);
    for (int i = 0; i < n; i++)
        if (!strstr(err, needles[i]))
            fail_msg("'%s': stderr '%s' lacks '%s'", args, err, needles[i]);
    if (strstr(out, "lamprig render:"))
        fail_msg("'%s': rendered before refusing: '%s'", args, out);
    free(err);
    free(out);
}

/* Issue 33, "silent black renders": a scene no light of which lights anything renders all
 * zeros (exactly: test_cpu_energy's Phi = 0), so the loader's warnings reach stderr (they were
 * dropped: render passed no sink) and render refuses the scene before any pass runs (exit 2)
 * unless --allow-dark. configs/scenes/sphere.json keeps its light inside the material on
 * purpose (the energy test's counter-example, configs/scenes/README.md). */
static void test_dark_scene_refused(void **state)
{
    const char *sphere[] = {
        /* the loader's warning, naming the file:line, the light, where it is, the object */
        "lamprig render: warning: configs/scenes/sphere.json:16: lights[0] 'core' at (0, 0, 0) "
        "is inside the material of objects[0] 'ball' (white_no_absorption): it lights nothing "
        "the renderer draws",
        /* the refusal */
        "lamprig render: sphere: no light lights anything the renderer draws", "--allow-dark"};
    expect_refused("--scene configs/scenes/sphere.json " SMALL " --frames 1", sphere, 3);
    /* A --set that darkens the scene: the check runs after --set (and the plan). */
    const char *zero[] = {"lights[0] 'flame' has zero power (intensity 0, color 1, 0.55, 0.2)",
                          "no light lights anything"};
    expect_refused("--scene configs/scenes/candle.json --no-plan " SMALL
                   " --set lights[0].intensity=0 --frames 1", zero, 2);
    const char *wax[] = {"lights[0] 'flame' at (0, 0, 60) is inside the material of objects[0] "
                         "'pillar' (candle_wax)"};
    expect_refused("--scene configs/scenes/candle.json --no-plan " SMALL
                   " --set lights[0].position=0,0,60 --frames 1", wax, 1);
    /* --allow-dark renders it: black to the last bit, the table and wall included (the wax
     * hides the flame from them too), with the warning. */
    int st = run("./build/bin/lamprig render --scene configs/scenes/candle.json --no-plan " SMALL
                 " --set lights[0].position=0,0,60 --frames 1 --allow-dark --hdr %s/d.pfm", dir);
    char *err = slurp("err");
    if (st != 0)
        fail_msg("--allow-dark: exit %d: %s", st, err);
    assert_non_null(strstr(err, "warning: candle: no light lights anything"));
    free(err);
    assert_true(radiance_sum("d.pfm") == 0.0);
    /* The shipped candle lights something: no such warning. */
    st = run("./build/bin/lamprig render --scene configs/scenes/candle.json --no-plan " SMALL
             " --frames 1 --hdr %s/l.pfm", dir);
    err = slurp("err");
    if (st != 0 || strstr(err, "lights nothing") || strstr(err, "no light lights"))
        fail_msg("candle: exit %d, stderr '%s'", st, err);
    free(err);
    assert_true(radiance_sum("l.pfm") > 0.0);
    /* Every command that loads a scene prints the loader's warnings: plan too (which then
     * refuses the scene for want of a budget). */
    st = run("./build/bin/lamprig plan --scene configs/scenes/sphere.json");
    err = slurp("err");
    if (st != 2 || !strstr(err, "lamprig plan: warning: configs/scenes/sphere.json:16: "
                                 "lights[0] 'core'"))
        fail_msg("plan: exit %d, stderr '%s'", st, err);
    free(err);
}

/* The image of a 32x24 PFM in dir (the caller frees img->rgb). */
static void read_pfm(const char *file, lr_image *img)
{
    char path[512];
    lr_err e = {0};
    snprintf(path, sizeof path, "%s/%s", dir, file);
    if (lr_image_read_pfm(path, img, &e))
        fail_msg("%s", e.msg);
    assert_int_equal(img->width * img->height, 32 * 24);
}

/* Issue 33, "deterministic models redraw identical frames": sh_translucency (like
 * diffusion_grid and translucent_radiosity) draws the same maps every frame, so the renderer
 * stops accumulating after the first one whatever render.frames says, and render --frames N
 * draws no frame that cannot change the image. A stochastic model (the directional dipole,
 * sampled afresh each frame) still draws every frame. The candle's light paths that cost CPU
 * time (bounce, VPL visibility) are off: they do not decide when the maps converge. */
#define FAST SMALL " --no-plan --set render.frames=8 --set render.receiver_bounce=false " \
                   "--set render.vpl_visibility=false "
static void test_deterministic_stops_early(void **state)
{
    lr_err e = {0};
    /* A steady flame: one frame drawn of the 8 asked for. */
    int st = run("./build/bin/lamprig render --scene configs/scenes/candle.json " FAST
                 "--set objects[0].model=sh_translucency --set lights[0].flicker.amplitude=0 "
                 "--frames 8 --hdr %s/steady.pfm --stats %s/s.json", dir, dir);
    char *err = slurp("err");
    if (st != 0)
        fail_msg("exit %d: %s", st, err);
    assert_non_null(strstr(err, "lamprig render: converged after 1 frame: deterministic "
                                "(pillar sh_translucency"));
    assert_non_null(strstr(err, "frames 2-8 of 8 not drawn"));
    free(err);
    lr_json *j = load_stats();
    long n = -1;
    assert_int_equal(lr_json_get_int(j, lr_json_root(j), "frames_requested", true, &n, &e), 0);
    assert_int_equal(n, 8);
    assert_int_equal(lr_json_get_int(j, lr_json_root(j), "frames_drawn", true, &n, &e), 0);
    assert_int_equal(n, 1);
    assert_int_equal(lr_json_count(j, lr_json_get(j, lr_json_root(j), "frames")), 1);
    char why[LR_ERR_MSG_MAX];
    assert_int_equal(lr_json_get_string(j, lr_json_root(j), "stopped_early", true, why,
                                        sizeof why, &e), 0);
    assert_non_null(strstr(why, "converged after 1 frame: deterministic"));
    expect_frame(j, 0, "gbuffer,radiosity,vpl,compose,blend,irradiance", 1, true, 0.0);
    bool det = false;
    lr_jnode f0 = lr_json_at(j, lr_json_get(j, lr_json_root(j), "frames"), 0);
    assert_int_equal(lr_json_get_bool(j, f0, "deterministic", true, &det, &e), 0);
    assert_true(det);
    lr_json_destroy(j);

    /* The flickering flame: frame 8 is composed at its clock 7/30 s, the blend alone, so the
     * image is the steady one times the flame's flicker factor then (transport is linear in
     * the intensity), as 8 drawn frames gave it. */
    st = run("./build/bin/lamprig render --scene configs/scenes/candle.json " FAST
             "--set objects[0].model=sh_translucency --frames 8 --hdr %s/flicker.pfm "
             "--stats %s/s.json", dir, dir);
    if (st != 0)
        fail_msg("exit %d (flicker)", st);
    j = load_stats();
    assert_int_equal(lr_json_get_int(j, lr_json_root(j), "frames_drawn", true, &n, &e), 0);
    assert_int_equal(n, 2);
    expect_frame(j, 1, "blend", 1, true, 7.0 / 30.0);
    lr_json_destroy(j);
    lr_scene *scene = NULL;
    if (lr_scene_load("configs/scenes/candle.json", NULL, &scene, &e))
        fail_msg("%s", e.msg);
    double f = 0.0;
    lr_light_flicker_at(lr_scene_light_at(scene, 0), 7.0 / 30.0, &f, NULL);
    lr_scene_destroy(scene);
    assert_true(fabs(f - 1.0) > 1e-3); /* the clock matters */
    lr_image a = {0}, b = {0};
    read_pfm("steady.pfm", &a);
    read_pfm("flicker.pfm", &b);
    double peak = 0.0, worst = 0.0;
    for (int i = 0; i < 32 * 24 * 3; i++)
        peak = fmax(peak, a.rgb[i]);
    assert_true(peak > 0.0);
    for (int i = 0; i < 32 * 24 * 3; i++)
        worst = fmax(worst, fabs(b.rgb[i] - f * a.rgb[i]) / peak);
    /* float32 products: a few ulp of the peak */
    if (worst > 1e-6)
        fail_msg("flicker image != %g x steady image: worst %g of the peak", f, worst);
    lr_image_free(&a);
    lr_image_free(&b);

    /* The directional dipole samples each frame afresh: all 3 frames drawn, accumulating. */
    st = run("./build/bin/lamprig render --scene configs/scenes/candle.json " FAST
             "--set objects[0].model=directional_dipole --set lights[0].flicker.amplitude=0 "
             "--frames 3 --stats %s/s.json", dir);
    err = slurp("err");
    if (st != 0 || strstr(err, "converged"))
        fail_msg("dipole: exit %d, stderr '%s'", st, err);
    free(err);
    j = load_stats();
    assert_int_equal(lr_json_get_int(j, lr_json_root(j), "frames_drawn", true, &n, &e), 0);
    assert_int_equal(n, 3);
    for (int i = 0; i < 3; i++)
        expect_frame(j, i, i ? "radiosity,vpl,compose,blend,irradiance"
                             : "gbuffer,radiosity,vpl,compose,blend,irradiance",
                     i + 1, false, i / 30.0);
    assert_int_equal(lr_json_type(j, lr_json_get(j, lr_json_root(j), "stopped_early")),
                     LR_JSON_NULL);
    lr_json_destroy(j);
}

/* An optically thick material outside what a model's numerics held (issue 34). sh_translucency
 * at sigma_a = 200 /mm gave Inf pixels (its energy scale was 0/0), which `lamprig render`
 * refused to write ("pixels are not finite", exit 1): now the image is written, exit 0, every
 * value finite. The sphere's light sits inside the ball (a dark scene, rendered with
 * --allow-dark), behind 40 mm of the material: the ball is black. translucent_radiosity at
 * sigma_a 1e4 /mm, beyond its sigma_tr limit, is refused before rendering: exit 2, one line
 * that names the key, the value and the model's range, nothing written. */
static void test_thick_material(void **state)
{
    (void)state;
    size_t len;
    char path[600];
    snprintf(path, sizeof path, "%s/scenes/sphere.json", LR_SOURCE_CONFIGS);
    unsigned char *text = lr_test_read(path, &len);
    char *at = strstr((char *)text, "\"sigma_a\": [0, 0, 0]");
    assert_non_null(at);
    char scene[4096];
    snprintf(scene, sizeof scene, "%.*s\"sigma_a\": [200, 200, 200]%s", (int)(at - (char *)text),
             (const char *)text, at + strlen("\"sigma_a\": [0, 0, 0]"));
    free(text);
    char *sph = lr_test_write(dir, "hot.json", scene, (size_t)-1);
    int st = run("build/bin/lamprig render --scene %s --no-plan --set objects[0].model="
                 "sh_translucency --width 80 --height 60 --frames 1 --allow-dark --out %s/hot.png "
                 "--hdr %s/hot.pfm",
                 sph, dir, dir);
    char *err = slurp("err");
    print_message("%s", err);
    assert_int_equal(st, 0);
    assert_null(strstr(err, "not finite"));
    free(err);
    char f[700];
    snprintf(f, sizeof f, "%s/hot.pfm", dir);
    lr_image img;
    lr_err e = {0};
    if (lr_image_read_pfm(f, &img, &e))
        fail_msg("%s", e.msg);
    assert_int_equal(img.width * img.height, 80 * 60);
    assert_int_equal(lr_image_count_nonfinite(&img), 0);
    lr_image_free(&img);

    st = run("build/bin/lamprig render --scene %s --no-plan --set objects[0].model="
             "translucent_radiosity --set objects[0].material.sigma_a=1e4,1e4,1e4 --width 80 "
             "--height 60 --frames 1 --allow-dark --hdr %s/cold.pfm",
             sph, dir);
    err = slurp("err");
    print_message("%s", err);
    assert_int_equal(st, 2);
    assert_non_null(strstr(err, "objects[0].material.sigma_a: sigma_a = 10000"));
    assert_non_null(strstr(err, "outside translucent_radiosity's valid range sigma_tr <= "));
    free(err);
    snprintf(f, sizeof f, "%s/cold.pfm", dir);
    assert_int_equal(access(f, F_OK), -1);
    free(sph);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_dark_scene_refused),
        cmocka_unit_test(test_deterministic_stops_early),
        cmocka_unit_test(test_render_jar_candle),
        cmocka_unit_test(test_render_writes_images_and_stats),
        cmocka_unit_test(test_bad_arguments),
        cmocka_unit_test(test_output_paths_checked_first),
        cmocka_unit_test(test_thick_material),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
