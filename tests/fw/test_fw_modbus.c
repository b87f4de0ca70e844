/* The rig against a real libmodbus server on 127.0.0.1 (a free port) acting as the dimmer panel
 * (unit 1, holding register 0, 0-1000) and the lamp driver (unit 2, holding register 0,
 * 0-255): a panel change reaches the driver register through the curve and the rendered frame;
 * the server goes down and comes back and the rig recovers; the safe level is written at
 * shutdown. The rig runs in-process (lr_rig_run_until), headless, frames to a scratch dir. */
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

#include "firmware/rig/rig.h"
#include "hal/dev.h"
#include "render/base/json.h"
#include "render/image/image.h"
#include "render/scene/scene.h"
#include "tests/support/fs.h"
#include "tests/support/gl.h"
#include "tests/support/hal_test.h"
#include "tests/support/modbus_rogue.h"
#include "tests/support/modbus_server.h"
#include "tests/support/near.h"

#define MS 1000000LL
/* Only a hang guard: the rig settles in 1-3 s idle under ASan, several times that beside other
 * test binaries on a loaded 2-core machine. */
#define GUARD_MS 60000

typedef bool (*pred_fn)(lr_rig *r, lr_test_mb_server *s, int want);

/* Runs the rig in 10 ms steps until pred holds (guard: a hang fails the test). */
static bool run_until(lr_rig *r, lr_test_mb_server *s, pred_fn p, int want)
{
    int64_t end = lr_now_ns() + GUARD_MS * MS;
    while (lr_now_ns() < end) {
        lr_err e = {0};
        assert_int_equal(lr_rig_run_until(r, lr_now_ns() + 10 * MS, &e), LR_OK);
        if (p(r, s, want))
            return true;
    }
    return false;
}

static bool driver_is(lr_rig *r, lr_test_mb_server *s, int want)
{
    (void)r;
    return lr_test_mb_server_reg(s, 2, 0) == want;
}

static double intensity(lr_rig *r)
{
    char buf[64];
    assert_int_equal(lr_scene_get(lr_rig_scene(r), "light.intensity", buf, sizeof buf, NULL),
                     LR_OK);
    return strtod(buf, NULL);
}

/* Red channel (linear) at the centre of the newest frame in dir. */
static double newest_frame_centre(const char *dir)
{
    DIR *d = opendir(dir);
    assert_non_null(d);
    char best[300] = "";
    struct dirent *de;
    while ((de = readdir(d)))
        if (strncmp(de->d_name, "frame_", 6) == 0 && strcmp(de->d_name, best) > 0)
            snprintf(best, sizeof best, "%s", de->d_name);
    closedir(d);
    assert_true(best[0] != '\0');
    char path[700];
    snprintf(path, sizeof path, "%s/%s", dir, best);
    lr_image img = {0};
    lr_err e = {0};
    if (lr_image_read_png(path, &img, &e))
        fail_msg("%s", e.msg);
    size_t c = (size_t)(img.height / 2) * (size_t)img.width + (size_t)(img.width / 2);
    double v = img.rgb[3 * c];
    lr_image_free(&img);
    return v;
}

static void write_config(const char *dir, int port, const char *curve, double fade,
                         double safe)
{
    char text[2048];
    snprintf(text, sizeof text,
             "{\"scene\": \"%s/scenes/candle.json\",\n"
             " \"devices\": [{\"type\": \"modbus\", \"name\": \"panel\",\n"
             "   \"url\": \"tcp://127.0.0.1:%d\", \"poll_ms\": 20, \"timeout_ms\": 200,\n"
             "   \"retry_min_ms\": 50, \"retry_max_ms\": 200,\n"
             "   \"inputs\": [{\"control\": \"dimmer\", \"unit\": 1, \"reg\": 0, "
             "\"raw_min\": 0, \"raw_max\": 1000}],\n"
             "   \"lamp\": {\"unit\": 2, \"reg\": 0, \"raw_min\": 0, \"raw_max\": 255}}],\n"
             " \"controls\": [{\"control\": \"panel/dimmer\", \"param\": \"light.intensity\",\n"
             "   \"range\": [0, 0.01], \"curve\": \"%s\", \"fade_s\": %g, \"lamp\": true}],\n"
             " \"output\": {\"mode\": \"headless\", \"width\": 64, \"height\": 48, \"fps\": 60,\n"
             "   \"renderer\": \"preview\"},\n"
             " \"safe_level\": %g}\n",
             LR_SOURCE_CONFIGS, port, curve, fade, safe);
    free(lr_test_write(dir, "rig.json", text, (size_t)-1));
}

/* Panel 0-1000 → square curve → driver 0-255 and the scene's intensity; the frame's
 * brightness follows; server down then up; safe level at shutdown. */
static void test_panel_to_driver_and_frame(void **state)
{
    (void)state;
    lr_test_mb_server *s = lr_test_mb_server_start();
    char *dir = lr_test_tmpdir();
    char *frames = lr_test_path(dir, "frames");
    write_config(dir, lr_test_mb_server_port(s), "square", 0, 0.2);
    char *cfg = lr_test_path(dir, "rig.json");
    lr_test_log log = {0};
    lr_rig_opts o = {.config = cfg, .out_dir = frames, .no_signals = true,
                     .log = {lr_test_log_fn, &log}};
    lr_rig *r;
    lr_err e = {0};
    if (lr_rig_create(&o, &r, &e))
        fail_msg("%s", e.msg);

    /* Panel at 500: level = 0.5^2 = 0.25 → raw round(63.75) = 64; intensity 0.0025. */
    lr_test_mb_server_set_reg(s, 1, 0, 500);
    assert_true(run_until(r, s, driver_is, 64));
    assert_near(intensity(r), 0.0025, 1e-9);
    /* Preview frame: centre red = 1 - exp(-I / I_file), I_file = 0.005 (8-bit sRGB). */
    assert_true(run_until(r, s, driver_is, 64)); /* one more step: the frame is written */
    double dim = newest_frame_centre(frames);
    assert_near(dim, 1 - exp(-0.5), 0.01);

    /* Panel at 1000: full → 255, intensity 0.01, brighter frame. */
    lr_test_mb_server_set_reg(s, 1, 0, 1000);
    assert_true(run_until(r, s, driver_is, 255));
    assert_near(intensity(r), 0.01, 1e-9);
    lr_rig_run_until(r, lr_now_ns() + 50 * MS, &e);
    double bright = newest_frame_centre(frames);
    assert_near(bright, 1 - exp(-2.0), 0.01);
    assert_true(bright > dim);

    /* Server down: the rig keeps running (frames, no crash) and logs the link state once. */
    lr_test_mb_server_stop(s);
    int64_t until = lr_now_ns() + 600 * MS;
    while (lr_now_ns() < until)
        lr_rig_run_until(r, until, &e);
    assert_true(lr_test_log_count(&log, "panel") >= 1);
    /* Up again with a new panel position: 300 → 0.09 → raw round(22.95) = 23. */
    lr_test_mb_server_set_reg(s, 1, 0, 300);
    lr_test_mb_server_restart(s);
    assert_true(run_until(r, s, driver_is, 23));
    assert_near(intensity(r), 0.0009, 1e-9);

    /* Shutdown: safe level 0.2 → round(51) = 51, acknowledged before destroy returns. */
    lr_rig_info info;
    lr_rig_get_info(r, &info);
    assert_true(info.frames >= 3);
    assert_true(info.events >= 3);
    lr_rig_destroy(r);
    assert_int_equal(lr_test_mb_server_reg(s, 2, 0), 51);
    lr_test_mb_server_free(s);
    free(cfg);
    free(frames);
    lr_test_rmtree(dir);
}

/* Linear RGB of the newest frame in dir (the caller frees). */
static lr_image newest_frame(const char *dir)
{
    DIR *d = opendir(dir);
    assert_non_null(d);
    char best[300] = "";
    struct dirent *de;
    while ((de = readdir(d)))
        if (strncmp(de->d_name, "frame_", 6) == 0 && strcmp(de->d_name, best) > 0)
            snprintf(best, sizeof best, "%s", de->d_name);
    closedir(d);
    char path[700];
    snprintf(path, sizeof path, "%s/%s", dir, best);
    lr_image img = {0};
    lr_err e = {0};
    if (lr_image_read_png(path, &img, &e))
        fail_msg("%s", e.msg);
    return img;
}

/* Scene-linear value (times the exposure) of a display value the renderer's ACES tone curve
 * produced: the curve is increasing, so bisection. */
static double untonemap(float v)
{
    lr_tonemap tm = {LR_TONEMAP_ACES, 1.0f};
    double lo = 0, hi = 64;
    for (int i = 0; i < 60; i++) {
        double mid = 0.5 * (lo + hi);
        if (lr_tonemap_apply(&tm, (float)mid) < v)
            lo = mid;
        else
            hi = mid;
    }
    return 0.5 * (lo + hi);
}

/* Ratio of the scene-linear radiance of frame b to frame a (b the brighter), over the pixels off
 * the tone curve's shoulder in b and above 8-bit quantization in a. */
static double radiance_ratio(const lr_image *a, const lr_image *b)
{
    double sa = 0, sb = 0;
    int used = 0;
    for (size_t i = 0; i < (size_t)a->width * (size_t)a->height * 3; i++)
        if (b->rgb[i] < 0.8f && a->rgb[i] > 0.02f) {
            sa += untonemap(a->rgb[i]);
            sb += untonemap(b->rgb[i]);
            used++;
        }
    assert_true(used > 100);
    return sb / sa;
}

static bool settled(lr_rig *r, lr_test_mb_server *s, int want)
{
    lr_rig_info info;
    lr_rig_get_info(r, &info);
    return lr_test_mb_server_reg(s, 2, 0) == want && info.idle;
}

/* The shipped modbus-demo rig with --modbus pointing at the test server, rendering with the
 * real renderer (seed 003's passes, software GL): linear curve, 0-1000 → 0-255 (after its
 * 0.15 s fade); output "kms" falls back to headless with a message; doubling the panel doubles
 * the converged frame's radiance (transport is linear in intensity; the PNG's ACES tone curve
 * is undone, 8-bit quantization and the curve's shoulder aside). */
static void test_shipped_modbus_demo(void **state)
{
    (void)state;
    lr_gl *gl;
    assert_int_equal(lr_test_gl_create(&gl), LR_OK); /* pins the driver for LSan */
    lr_gl_destroy(gl);
    lr_test_mb_server *s = lr_test_mb_server_start();
    char url[64];
    snprintf(url, sizeof url, "tcp://127.0.0.1:%d", lr_test_mb_server_port(s));
    char *dir = lr_test_tmpdir();
    lr_test_log log = {0};
    lr_rig_opts o = {.config = LR_SOURCE_CONFIGS "/rig/modbus-demo.json", .modbus_url = url,
                     .out_dir = dir, .no_signals = true, .log = {lr_test_log_fn, &log}};
    lr_test_mb_server_set_reg(s, 1, 0, 100);
    lr_rig *r;
    lr_err e = {0};
    if (lr_rig_create(&o, &r, &e))
        fail_msg("%s", e.msg);
    lr_rig_info info;
    lr_rig_get_info(r, &info);
    assert_string_equal(info.output, "headless");
    assert_string_equal(info.view, "passes");
    /* No /dev/dri (or no connected output) on the test machine: said once, clearly. */
    assert_int_equal(lr_test_log_count(&log, "output: kms: "), 1);
    assert_int_equal(lr_test_log_count(&log, "; running headless"), 1);

    /* 100 → 0.1 → round(25.5) = 26; converged. */
    assert_true(run_until(r, s, settled, 26));
    assert_near(intensity(r), 0.001, 1e-12);
    lr_image a = newest_frame(dir);
    /* 200 → 0.2 → 51. */
    lr_test_mb_server_set_reg(s, 1, 0, 200);
    assert_true(run_until(r, s, settled, 51));
    assert_near(intensity(r), 0.002, 1e-12);
    lr_image b = newest_frame(dir);
    assert_near(radiance_ratio(&a, &b), 2.0, 0.01);
    lr_image_free(&a);
    lr_image_free(&b);

    /* 600 → 0.6 → 153; the scene's intensity exactly 0.6 of the range after the fade. */
    lr_test_mb_server_set_reg(s, 1, 0, 600);
    assert_true(run_until(r, s, settled, 153));
    assert_near(intensity(r), 0.006, 1e-12);
    lr_rig_destroy(r);
    assert_int_equal(lr_test_mb_server_reg(s, 2, 0), 0); /* safe_level 0 */
    lr_test_mb_server_free(s);
    lr_test_rmtree(dir);
}

/* The same over RTU on a pseudo-terminal pair: the shipped modbus-demo rig with
 * --modbus rtu:LINK?baud=19200&parity=E, LINK a symlink to the pty's slave end (as udev's
 * /dev/serial/by-id links are), the real renderer at the demo's budget. A panel change reaches
 * the driver register and the frame's radiance; the bus goes away (the pty is closed, the
 * device node disappears) and comes back as a new pty behind the same link: the rig logs the
 * loss, reconnects, reads the moved panel and resends the level to a driver that restarted
 * at 0. The safe level reaches the driver at shutdown. */
static void test_rtu_over_pty(void **state)
{
    (void)state;
    lr_gl *gl;
    assert_int_equal(lr_test_gl_create(&gl), LR_OK); /* pins the driver for LSan */
    lr_gl_destroy(gl);
    char *dir = lr_test_tmpdir();
    char *link = lr_test_path(dir, "ttyPANEL");
    char *frames = lr_test_path(dir, "frames");
    lr_test_mb_server *s = lr_test_mb_server_start_rtu(link);
    char url[700];
    snprintf(url, sizeof url, "rtu:%s?baud=19200&parity=E&data=8&stop=1", link);
    lr_test_mb_server_set_reg(s, 1, 0, 100);
    lr_test_log log = {0};
    lr_rig_opts o = {.config = LR_SOURCE_CONFIGS "/rig/modbus-demo.json", .modbus_url = url,
                     .headless = true, .out_dir = frames, .no_signals = true,
                     .log = {lr_test_log_fn, &log}};
    lr_rig *r;
    lr_err e = {0};
    if (lr_rig_create(&o, &r, &e))
        fail_msg("%s", e.msg);
    lr_rig_info info;
    lr_rig_get_info(r, &info);
    assert_string_equal(info.view, "passes");

    /* 100 → 0.1 → round(25.5) = 26 on the driver, 0.001 W/sr in the scene; converged. */
    assert_true(run_until(r, s, settled, 26));
    assert_near(intensity(r), 0.001, 1e-12);
    lr_rig_get_info(r, &info);
    assert_near(info.lamp_level, 0.1, 1e-12);
    lr_image a = newest_frame(frames);
    /* 200 → 51; the converged frame's radiance doubles. */
    lr_test_mb_server_set_reg(s, 1, 0, 200);
    assert_true(run_until(r, s, settled, 51));
    assert_near(intensity(r), 0.002, 1e-12);
    lr_image b = newest_frame(frames);
    assert_near(radiance_ratio(&a, &b), 2.0, 0.01);
    lr_image_free(&b);
    assert_int_equal(lr_test_log_count(&log, "retrying with backoff"), 0);

    /* The bus goes away for 0.8 s: the rig keeps running and logs the loss. */
    lr_test_mb_server_stop(s);
    int64_t until = lr_now_ns() + 800 * MS;
    while (lr_now_ns() < until)
        assert_int_equal(lr_rig_run_until(r, until, &e), LR_OK);
    assert_true(lr_test_log_count(&log, "retrying with backoff") >= 1);
    /* Back as a new pty behind the same link, the panel moved to 300 and the driver at 0:
     * 0.3 → round(76.5) = 77, resent; the frame follows (3× the first one). */
    lr_test_mb_server_set_reg(s, 1, 0, 300);
    lr_test_mb_server_set_reg(s, 2, 0, 0);
    lr_test_mb_server_restart(s);
    assert_true(run_until(r, s, settled, 77));
    assert_near(intensity(r), 0.003, 1e-12);
    assert_true(lr_test_log_count(&log, "open (after") >= 1);
    lr_image c = newest_frame(frames);
    assert_near(radiance_ratio(&a, &c), 3.0, 0.015);
    lr_image_free(&a);
    lr_image_free(&c);

    lr_rig_destroy(r);
    assert_int_equal(lr_test_mb_server_reg(s, 2, 0), 0); /* safe_level 0, acknowledged */
    lr_test_mb_server_free(s);
    free(link);
    free(frames);
    lr_test_rmtree(dir);
}

/* No server at all at start: the rig starts anyway (the device is retried), renders, and
 * picks the panel up when the server appears. A bad --modbus URL is refused up front. */
static void test_missing_at_start(void **state)
{
    (void)state;
    lr_test_mb_server *s = lr_test_mb_server_start();
    lr_test_mb_server_stop(s);
    char *dir = lr_test_tmpdir();
    write_config(dir, lr_test_mb_server_port(s), "linear", 0, 0);
    char *cfg = lr_test_path(dir, "rig.json");
    lr_test_log log = {0};
    lr_rig_opts o = {.config = cfg, .no_signals = true, .log = {lr_test_log_fn, &log}};
    lr_rig *r;
    lr_err e = {0};
    if (lr_rig_create(&o, &r, &e))
        fail_msg("%s", e.msg);
    int64_t until = lr_now_ns() + 400 * MS;
    while (lr_now_ns() < until)
        lr_rig_run_until(r, until, &e);
    lr_rig_info info;
    lr_rig_get_info(r, &info);
    assert_true(info.frames >= 1);
    /* Logged once per state change, not once per retry (several retries happened). */
    int lines = lr_test_log_count(&log, "panel");
    assert_true(lines >= 1 && lines <= 2);
    lr_test_mb_server_set_reg(s, 1, 0, 1000);
    lr_test_mb_server_restart(s);
    assert_true(run_until(r, s, driver_is, 255));
    lr_rig_destroy(r);

    o.modbus_url = "tcp://127.0.0.1:0";
    assert_int_equal(lr_rig_create(&o, &r, &e), LR_EPARSE);
    assert_string_equal(e.msg, "--modbus: modbus URL 'tcp://127.0.0.1:0': port '0' is not "
                               "1..65535");
    lr_test_mb_server_free(s);
    free(cfg);
    lr_test_rmtree(dir);
}

/* A peer answering every request late first (tests/support/modbus_rogue.c LATE): the rig's
 * stats file shows the link's counters, the stale answers among them, and the dimmer follows
 * the panel's register 0 (300 of 1000), never the late answer (the driver register, read back
 * as 77 = round(0.3 * 255)). */
static void test_stale_answers_in_stats(void **state)
{
    (void)state;
    lr_test_rogue *g = lr_test_rogue_start(LR_ROGUE_LATE, 0);
    lr_test_rogue_set_reg(g, 0, 300);
    char *dir = lr_test_tmpdir();
    write_config(dir, lr_test_rogue_port(g), "linear", 0, 0);
    char *cfg = lr_test_path(dir, "rig.json");
    char *stats = lr_test_path(dir, "stats.json");
    lr_test_log log = {0};
    lr_rig_opts o = {.config = cfg, .stats_path = stats, .no_signals = true,
                     .log = {lr_test_log_fn, &log}};
    lr_rig *r;
    lr_err e = {0};
    if (lr_rig_create(&o, &r, &e))
        fail_msg("%s", e.msg);
    int64_t end = lr_now_ns() + GUARD_MS * MS;
    while (lr_now_ns() < end &&
           (lr_test_rogue_requests(g) < 30 || lr_test_rogue_driver(g, 0) != 77))
        assert_int_equal(lr_rig_run_until(r, lr_now_ns() + 10 * MS, &e), LR_OK);
    assert_true(lr_test_rogue_requests(g) >= 30);
    assert_int_equal(lr_test_rogue_driver(g, 0), 77);
    assert_near(intensity(r), 0.003, 1e-12);
    lr_rig_destroy(r); /* writes the stats */
    lr_json *j;
    if (lr_json_load(stats, &j, &e))
        fail_msg("%s", e.msg);
    lr_jnode devs = lr_json_get(j, lr_json_root(j), "devices");
    assert_int_equal(lr_json_count(j, devs), 1);
    lr_jnode d = lr_json_at(j, devs, 0);
    char buf[64];
    assert_int_equal(lr_json_string(j, lr_json_get(j, d, "kind"), "kind", buf, sizeof buf, &e),
                     LR_OK);
    assert_string_equal(buf, "modbus");
    lr_jnode mb = lr_json_get(j, d, "modbus");
    long stale = 0, responses = 0, bad = 0;
    assert_int_equal(lr_json_get_int(j, mb, "stale", true, &stale, &e), LR_OK);
    assert_int_equal(lr_json_get_int(j, mb, "responses", true, &responses, &e), LR_OK);
    assert_int_equal(lr_json_get_int(j, mb, "bad_responses", true, &bad, &e), LR_OK);
    /* Every answer after the first came behind a late one (the last may still be on its way). */
    assert_true(stale >= 20);
    assert_true(stale + 2 >= responses);
    assert_int_equal(bad, 0);
    lr_json_destroy(j);
    lr_test_rogue_free(g);
    free(cfg);
    free(stats);
    lr_test_rmtree(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_panel_to_driver_and_frame),
        cmocka_unit_test(test_shipped_modbus_demo),
        cmocka_unit_test(test_missing_at_start),
        cmocka_unit_test(test_rtu_over_pty),
        cmocka_unit_test(test_stale_answers_in_stats),
    };
    if (getenv("LR_TEST_FILTER")) /* e.g. LR_TEST_FILTER='test_soak*' to run one test */
        cmocka_set_test_filter(getenv("LR_TEST_FILTER"));
    return cmocka_run_group_tests(tests, NULL, NULL);
}
