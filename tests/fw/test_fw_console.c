/* firmware/: the shipped console rig (configs/rig/console.json) in-process, driven the way a
 * console drives it: an sACN packet, an ArtDmx and an OSC message move the candle's dimmer.
 * The file is used as shipped except for what a test on a shared machine must change: the
 * ports (sACN 5568 -> 15530 unicast, Art-Net 6454 -> 15531 without the broadcast announce,
 * OSC 9000 -> 15532, the Modbus lamp driver a libmodbus server on a free port), absolute
 * paths, a 16x16 preview output. Real consoles (OLA, QLC+) drive the receivers in
 * tests/hal/test_hal_dmx_peers.c. */
#include <lo/lo.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "firmware/rig/rig.h"
#include "hal/dev.h"
#include "render/base/json.h"
#include "render/scene/scene.h"
#include "tests/support/dmx_build.h"
#include "tests/support/fs.h"
#include "tests/support/hal_test.h"
#include "tests/support/modbus_server.h"
#include "tests/support/near.h"

#define MS 1000000LL
#define CFG LR_SOURCE_CONFIGS

/* Replaces the one occurrence of from in s (which must be there) by to; s has room for cap. */
static void replace(char *s, size_t cap, const char *from, const char *to)
{
    char *p = strstr(s, from);
    if (!p)
        fail_msg("console.json no longer contains '%s'", from);
    size_t fl = strlen(from), tl = strlen(to), rest = strlen(p + fl);
    assert_true(strlen(s) - fl + tl < cap);
    memmove(p + tl, p + fl, rest + 1);
    memcpy(p, to, tl);
}

static double scene_num(lr_rig *r, const char *key)
{
    char buf[128];
    lr_err e = {0};
    if (lr_scene_get(lr_rig_scene(r), key, buf, sizeof buf, &e))
        fail_msg("%s", e.msg);
    return strtod(buf, NULL);
}

static void run_for(lr_rig *r, int ms)
{
    lr_err e = {0};
    if (lr_rig_run_until(r, lr_now_ns() + ms * MS, &e))
        fail_msg("%s", e.msg);
}

/* The shipped console.json as this test runs it (see the top); sacn_extra: more sACN options
 * ("" none); lamp_port: the lamp driver's Modbus TCP port. */
static void console_text(char *text, size_t cap, const char *sacn_extra, int lamp_port)
{
    size_t len;
    char *shipped = (char *)lr_test_read(CFG "/rig/console.json", &len);
    assert_true(len < cap / 2);
    memcpy(text, shipped, len);
    text[len] = '\0';
    free(shipped);
    replace(text, cap, "\"../scenes/", "\"" CFG "/scenes/");
    replace(text, cap, "\"../controls/", "\"" CFG "/controls/");
    char sacn[256];
    snprintf(sacn, sizeof sacn,
             "\"type\": \"sacn\", \"name\": \"sacn\", \"port\": 15530, \"unicast_only\": true,%s",
             sacn_extra);
    replace(text, cap, "\"type\": \"sacn\", \"name\": \"sacn\",", sacn);
    replace(text, cap, "\"type\": \"artnet\", \"name\": \"artnet\",",
            "\"type\": \"artnet\", \"name\": \"artnet\", \"port\": 15531, \"announce\": \"none\",");
    replace(text, cap, "\"port\": 9000", "\"port\": 15532");
    char url[64];
    snprintf(url, sizeof url, "tcp://127.0.0.1:%d", lamp_port);
    replace(text, cap, "tcp://127.0.0.1:1502", url);
    replace(text, cap, "\"width\": 320, \"height\": 240",
            "\"width\": 16, \"height\": 16, \"renderer\": \"preview\"");
}

static void console_moves_the_dimmer(void **state)
{
    (void)state;
    /* The lamp driver: a libmodbus server (unit 2, holding register 0) on a free port. */
    lr_test_mb_server *mb = lr_test_mb_server_start();
    char text[8192];
    console_text(text, sizeof text, "", lr_test_mb_server_port(mb));
    char *dir = lr_test_tmpdir();
    char *cfg = lr_test_write(dir, "rig.json", text, (size_t)-1);
    char *stats = lr_test_path(dir, "stats.json");
    lr_test_log log = {0};
    lr_rig_opts o = {.config = cfg, .stats_path = stats, .no_signals = true,
                     .log = {lr_test_log_fn, &log}};
    lr_rig *r;
    lr_err e = {0};
    if (lr_rig_create(&o, &r, &e))
        fail_msg("%s", e.msg);
    /* The candle's own intensity (configs/scenes/candle.json: 0.005 W/sr); the dimmer binding
     * is light.level, range [0, 2], square curve, 0.25 s fade: level = 2 x^2 of the position
     * x, and the intensity is 0.005 * level once the fade has ended. */
    run_for(r, 100);
    double i0 = 0.005;
    assert_near(scene_num(r, "light.intensity"), i0, 1e-12);

    int tx = lr_test_udp_socket(0);
    assert_true(tx >= 0);
    uint8_t b[700], sl[4] = {255, 0, 0, 0};
    /* sACN universe 1 channel 1 at 255: x = 1, level 2. */
    size_t n = lr_test_sacn_build(b, 1, 100, 0, 0, 0, sl, 4, 1);
    assert_int_equal(lr_test_udp_send(tx, 15530, b, n), (long)n);
    run_for(r, 600);
    assert_near(scene_num(r, "light.intensity"), 2 * i0, 1e-12);
    /* The lamp gets the curved level y = x^2 = 1: raw 255 of 0..255. */
    assert_int_equal(lr_test_mb_server_reg(mb, 2, 0), 255);
    /* Art-Net port-address 1 channel 1 at 0: level 0 (the latest event wins: the two
     * receivers are two devices feeding one binding, as two faders would). */
    sl[0] = 0;
    n = lr_test_artdmx_build(b, 1, sl, 4);
    assert_int_equal(lr_test_udp_send(tx, 15531, b, n), (long)n);
    run_for(r, 600);
    assert_near(scene_num(r, "light.intensity"), 0, 1e-12);
    assert_int_equal(lr_test_mb_server_reg(mb, 2, 0), 0);
    /* OSC /lamprig/dimmer 0.5: level 2 * 0.25 = 0.5. */
    lo_address to = lo_address_new("127.0.0.1", "15532");
    assert_true(lo_send(to, "/lamprig/dimmer", "f", 0.5f) > 0);
    lo_address_free(to);
    run_for(r, 600);
    assert_near(scene_num(r, "light.intensity"), 0.5 * i0, 1e-12);
    /* y = 0.25: raw round(0.25 * 255) = round(63.75) = 64. */
    assert_int_equal(lr_test_mb_server_reg(mb, 2, 0), 64);
    /* A packet that is not sACN (a wrong ACN identifier): counted by kind in the stats. */
    n = lr_test_sacn_build(b, 1, 100, 1, 0, 0, sl, 4, 1);
    b[4] = 'X';
    assert_int_equal(lr_test_udp_send(tx, 15530, b, n), (long)n);
    run_for(r, 100);
    close(tx);
    lr_rig_info info;
    lr_rig_get_info(r, &info);
    /* Events that changed something: the first sACN packet carries channels 2-4 too, at 0,
     * which moves knob1 (flicker, from the scene's 0.08 to 0) and knob2 (translucency, from
     * the scene's scale to 0.25); tint at 0 is its "initial" position (no change). Then the
     * Art-Net and OSC dimmers: 3 + 1 + 1. */
    assert_int_equal(info.events, 5);
    assert_near(scene_num(r, "lights[0].flicker.amplitude"), 0, 1e-12);
    /* The three inputs opened. */
    assert_int_equal(lr_test_log_count(&log, "sacn: udp 0.0.0.0:15530, universe 1 (unicast): open"),
                     1);
    assert_int_equal(lr_test_log_count(&log, "artnet: udp 0.0.0.0:15531, port-address 1: open"), 1);
    assert_int_equal(lr_test_log_count(&log, "osc: udp port 15532, /lamprig/...: open"), 1);
    lr_rig_destroy(r); /* writes the stats and the safe level 0 */
    assert_int_equal(lr_test_mb_server_reg(mb, 2, 0), 0);
    lr_test_mb_server_free(mb);
    /* The stats file's devices: each input with its counters. */
    lr_json *j;
    if (lr_json_load(stats, &j, &e))
        fail_msg("%s", e.msg);
    lr_jnode devs = lr_json_get(j, lr_json_root(j), "devices");
    assert_int_equal(lr_json_count(j, devs), 4);
    long v = -1;
    lr_jnode in = lr_json_get(j, lr_json_at(j, devs, 0), "input");
    assert_int_equal(lr_json_get_int(j, in, "packets", true, &v, &e), LR_OK);
    assert_int_equal(v, 2);
    assert_int_equal(lr_json_get_int(j, in, "taken", true, &v, &e), LR_OK);
    assert_int_equal(v, 1);
    assert_int_equal(lr_json_get_int(j, in, "bad_acn-id", true, &v, &e), LR_OK);
    assert_int_equal(v, 1);
    in = lr_json_get(j, lr_json_at(j, devs, 1), "input");
    assert_int_equal(lr_json_get_int(j, in, "taken", true, &v, &e), LR_OK);
    assert_int_equal(v, 1);
    in = lr_json_get(j, lr_json_at(j, devs, 2), "input");
    assert_int_equal(lr_json_get_int(j, in, "messages", true, &v, &e), LR_OK);
    assert_int_equal(v, 1);
    assert_int_equal(lr_json_get(j, lr_json_at(j, devs, 3), "input"), LR_JNONE); /* modbus */
    lr_json_destroy(j);
    free(cfg);
    free(stats);
    lr_test_rmtree(dir);
}

/* "loss": "fade": when the console goes quiet for loss_ms, the dimmer fades back to the
 * position the control map took from the scene (light.level 1 of range [0, 2], square curve:
 * x = sqrt(1/2)), so the intensity returns to the scene's own 0.005 W/sr. */
static void console_loss_fades_to_the_scene(void **state)
{
    (void)state;
    char text[8192];
    console_text(text, sizeof text, " \"loss\": \"fade\", \"loss_ms\": 300, \"fade_ms\": 200,",
                 9); /* nobody on port 9: the lamp retries, the rest runs */
    char *dir = lr_test_tmpdir();
    char *cfg = lr_test_write(dir, "rig.json", text, (size_t)-1);
    lr_test_log log = {0};
    lr_rig_opts o = {.config = cfg, .no_signals = true, .log = {lr_test_log_fn, &log}};
    lr_rig *r;
    lr_err e = {0};
    if (lr_rig_create(&o, &r, &e))
        fail_msg("%s", e.msg);
    run_for(r, 100);
    int tx = lr_test_udp_socket(0);
    uint8_t b[700], sl[1] = {255};
    size_t n = lr_test_sacn_build(b, 1, 100, 0, 0, 0, sl, 1, 1);
    assert_int_equal(lr_test_udp_send(tx, 15530, b, n), (long)n);
    close(tx);
    /* 0.2 s: the packet is taken and its 0.25 s fade is under way; before the 0.3 s loss. */
    run_for(r, 200);
    assert_int_equal(lr_test_log_count(&log, "no source left"), 0);
    /* The loss at 0.3 s, the 0.2 s loss fade and the binding's own 0.25 s fade: all done by
     * 1.5 s. Level 2 (1/2) = 1: the scene's intensity again. */
    run_for(r, 1300);
    assert_int_equal(lr_test_log_count(&log, "universe 1: no source left; fading to the scene's "
                                             "values"), 1);
    assert_near(scene_num(r, "light.intensity"), 0.005, 1e-12);
    /* The packet moved the dimmer up, and the loss fade brought it back: the loss line says a
     * source was there, the events that the dimmer moved at least twice. */
    lr_rig_info info;
    lr_rig_get_info(r, &info);
    assert_true(info.events >= 2);
    lr_rig_destroy(r);
    free(cfg);
    lr_test_rmtree(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(console_moves_the_dimmer),
        cmocka_unit_test(console_loss_fades_to_the_scene),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
