/* firmware/: consoles nobody on this team wrote through the shipped console rig
 * (configs/rig/console.json, in-process) to both the rendered dimmer and the Modbus lamp:
 *  - QLC+ (headless, in a network namespace of its own, driven through its web socket as
 *    tests/hal/test_hal_dmx_peers.c drives it) over Art-Net;
 *  - OLA's olad (in a namespace of its own, as its own user), given values by ola_set_dmx, over
 *    E1.31 multicast; then liblo's oscsend on the rig's OSC port: a dimmer and a scene.
 * (tests/support/console_peer.h.) The file is used as shipped except for absolute paths, a
 * 16x16 preview output, the lamp on a libmodbus server's free port and sACN's interface (the
 * veth end: this namespace has no default route for the multicast join). Art-Net and OSC keep
 * their fixed ports 6454 and 9000: the namespace is the test's own. Each test is skipped
 * without its programs, ip or root. The latency from the console's command to the rendered
 * change and to the lamp's register is printed, not asserted (it includes the console's own
 * output cadence). */
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
#include "render/scene/scene.h"
#include "tests/support/console_peer.h"
#include "tests/support/dmx_build.h"
#include "tests/support/fs.h"
#include "tests/support/hal_test.h"
#include "tests/support/modbus_server.h"
#include "tests/support/near.h"

#define MS 1000000LL
#define CFG LR_SOURCE_CONFIGS
#define NS_NET "10.157.0"

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

/* The rig: the shipped console.json, sACN on net.1 (the veth end), in dir. */
static lr_rig *console_rig(const char *net, lr_test_mb_server *mb, const char *dir,
                           lr_test_log *log)
{
    char text[8192];
    size_t len;
    char *shipped = (char *)lr_test_read(CFG "/rig/console.json", &len);
    assert_true(len < sizeof text / 2);
    memcpy(text, shipped, len);
    text[len] = '\0';
    free(shipped);
    replace(text, sizeof text, "\"../scenes/", "\"" CFG "/scenes/");
    replace(text, sizeof text, "\"../controls/", "\"" CFG "/controls/");
    char sacn[160];
    snprintf(sacn, sizeof sacn, "\"type\": \"sacn\", \"name\": \"sacn\", \"interface\": \"%s.1\",",
             net);
    replace(text, sizeof text, "\"type\": \"sacn\", \"name\": \"sacn\",", sacn);
    char url[64];
    snprintf(url, sizeof url, "tcp://127.0.0.1:%d", lr_test_mb_server_port(mb));
    replace(text, sizeof text, "tcp://127.0.0.1:1502", url);
    replace(text, sizeof text, "\"width\": 320, \"height\": 240",
            "\"width\": 16, \"height\": 16, \"renderer\": \"preview\"");
    char *cfg = lr_test_write(dir, "rig.json", text, (size_t)-1);
    lr_rig_opts o = {.config = cfg, .no_signals = true, .log = {lr_test_log_fn, log}};
    lr_rig *r;
    lr_err e = {0};
    if (lr_rig_create(&o, &r, &e))
        fail_msg("%s", e.msg);
    free(cfg);
    return r;
}

/* QLC+ sends its second universe (index 1) as Art-Net port-address 1, console.json's
 * universe 1, by broadcast to NS_NET.255; its Simple Desk addresses it as 513..1024. */
static const char WORKSPACE[] =
    "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<!DOCTYPE Workspace>\n"
    "<Workspace xmlns=\"http://www.qlcplus.org/Workspace\" CurrentWindow=\"SimpleDesk\">\n"
    " <Creator><Name>Q Light Controller Plus</Name><Version>4.12.6</Version>"
    "<Author>lamprig tests</Author></Creator>\n"
    " <Engine>\n  <InputOutputMap>\n   <BeatGenerator BeatType=\"Disabled\" BPM=\"0\"/>\n"
    "   <Universe Name=\"Universe 1\" ID=\"0\"/>\n"
    "   <Universe Name=\"Universe 2\" ID=\"1\"><Output Plugin=\"ArtNet\" Line=\"0\"/></Universe>\n"
    "  </InputOutputMap>\n </Engine>\n</Workspace>\n";

static int peer_setup(void **state)
{
    *state = calloc(1, sizeof(lr_test_peer));
    return *state ? 0 : -1;
}

/* Runs after a failed assertion too: no console or namespace is left behind. */
static int peer_teardown(void **state)
{
    lr_test_peer_stop(*state);
    free(*state);
    return 0;
}

/* Runs the rig until the dimmer's intensity is `want` and the lamp's register `raw`, or
 * guard_ms; the times (ms from t0) of the intensity's first change (the fade's first step:
 * the control latency itself) and of reaching each, -1 when not reached. */
static void run_to(lr_rig *r, lr_test_mb_server *mb, double want, int raw, int64_t t0,
                   int guard_ms, double *t_first, double *t_render, double *t_lamp)
{
    *t_first = *t_render = *t_lamp = -1;
    double before = scene_num(r, "light.intensity");
    lr_err e = {0};
    while ((*t_render < 0 || *t_lamp < 0) && lr_now_ns() - t0 < guard_ms * MS) {
        if (lr_rig_run_until(r, lr_now_ns() + 5 * MS, &e))
            fail_msg("%s", e.msg);
        double ms = (double)(lr_now_ns() - t0) * 1e-6;
        if (*t_first < 0 && scene_num(r, "light.intensity") != before)
            *t_first = ms;
        if (*t_render < 0 && fabs(scene_num(r, "light.intensity") - want) < 1e-12)
            *t_render = ms;
        if (*t_lamp < 0 && lr_test_mb_server_reg(mb, 2, 0) == raw)
            *t_lamp = ms;
    }
}

/* After a console's command at t0: the rig reaches the intensity and the lamp's raw level
 * within 5 s; the times printed (what: the command; note: what they include). */
static void reaches(lr_rig *r, lr_test_mb_server *mb, const char *what, int64_t t0,
                    double intensity, int raw, const char *note)
{
    double t1, tr, tl;
    run_to(r, mb, intensity, raw, t0, 5000, &t1, &tr, &tl);
    print_message("%s: intensity first changed after %.0f ms, reached %.6g after %.0f ms (the "
                  "0.25 s fade), lamp raw %d after %.0f ms (%s)\n",
                  what, t1, intensity, tr, raw, tl, note);
    assert_true(tr >= 0);
    assert_true(tl >= 0);
    assert_near(scene_num(r, "light.intensity"), intensity, 1e-12);
}

static void qlcplus_drives_the_rig(void **state)
{
    lr_test_peer *p = *state;
    char why[160];
    if (!lr_test_have("qlcplus")) {
        print_message("qlcplus not installed (Debian qlcplus): skipped\n");
        skip();
    }
    if (!lr_test_netns_ok(why, sizeof why) || !lr_test_peer_ns(p, "qlcrig", NS_NET, why, sizeof why)) {
        print_message("%s\n", why);
        skip();
    }
    lr_test_qlc_start(p, WORKSPACE);
    lr_test_mb_server *mb = lr_test_mb_server_start();
    char *dir = lr_test_tmpdir();
    lr_test_log log = {0};
    lr_rig *r = console_rig(NS_NET, mb, dir, &log);
    lr_err e = {0};
    int fd = -1;
    for (int i = 0; i < 150 && fd < 0; i++) {
        if (lr_rig_run_until(r, lr_now_ns() + 100 * MS, &e))
            fail_msg("%s", e.msg);
        fd = lr_test_qlc_ws_open(NS_NET ".2");
    }
    if (fd < 0) {
        lr_test_sh("cat %s/qlcplus.log >&2", p->dir);
        fail_msg("QLC+'s web socket did not answer in 15 s (its log above)");
    }
    /* The dimmer binding (configs/controls/candle.json): light.level over [0, 2], square
     * curve, 0.25 s fade; the candle's own intensity 0.005 W/sr is level 1. Fader x = 255/255:
     * level 2, intensity 0.01; the lamp's y = x^2 = 1: raw 255. Then x = 51/255 = 0.2: level
     * 2 x^2 = 0.08, intensity 0.0004; y = 0.04: raw round(0.04 * 255) = round(10.2) = 10. */
    const struct {
        const char *cmd;
        double intensity;
        int raw;
    } steps[] = {{"CH|513|255", 0.01, 255}, {"CH|513|51", 0.005 * 2 * 0.04, 10}};
    for (size_t i = 0; i < sizeof steps / sizeof steps[0]; i++) {
        int64_t t0 = lr_now_ns();
        lr_test_qlc_ws_text(fd, steps[i].cmd);
        reaches(r, mb, steps[i].cmd, t0, steps[i].intensity, steps[i].raw,
                "web socket frame to the rig's state, QLC+'s output cadence included");
    }
    close(fd);
    lr_rig_destroy(r);
    lr_test_mb_server_free(mb);
    lr_test_rmtree(dir);
}

#define OLA_NET "10.158.0"

/* OLA: olad patched to send its universe 1 over E1.31 (multicast 239.255.0.1 from the veth end
 * OLA_NET.2), given the looks by ola_set_dmx; then oscsend to the rig's OSC port 9000: a
 * dimmer value and a scene of its list. The same two looks as QLC+'s on channel 1, then
 * /lamprig/dimmer 0.5: level 2 x^2 = 0.5, intensity 0.0025; the lamp y = 0.25: raw
 * round(63.75) = 64. */
static void ola_and_oscsend_drive_the_rig(void **state)
{
    lr_test_peer *p = *state;
    char why[160];
    const char *need[] = {"olad", "ola_patch", "ola_set_dmx", "ola_dev_info", "oscsend", NULL};
    for (int i = 0; need[i]; i++)
        if (!lr_test_have(need[i])) {
            print_message("%s not installed (Debian ola, liblo-tools): skipped\n", need[i]);
            skip();
        }
    if (!lr_test_netns_ok(why, sizeof why) ||
        !lr_test_peer_ns(p, "olarig", OLA_NET, why, sizeof why)) {
        print_message("%s\n", why);
        skip();
    }
    if (!lr_test_olad_start(p, OLA_NET ".2")) {
        lr_test_sh("cat %s/olad.log >&2", p->dir);
        fail_msg("olad did not come up in 10 s (its log above)");
    }
    int de = lr_test_olad_device(p, "E1.31");
    assert_true(de > 0);
    assert_int_equal(lr_test_sh("ip netns exec %s ola_patch -d %d -p 0 -u 1", p->ns, de), 0);
    lr_test_mb_server *mb = lr_test_mb_server_start();
    char *dir = lr_test_tmpdir();
    lr_test_log log = {0};
    lr_rig *r = console_rig(OLA_NET, mb, dir, &log);
    lr_err e = {0};
    if (lr_rig_run_until(r, lr_now_ns() + 300 * MS, &e))
        fail_msg("%s", e.msg);
    const struct {
        bool in_ns; /* run in OLA's namespace */
        const char *cmd;
        double intensity;
        int raw;
    } steps[] = {
        {true, "ola_set_dmx -u 1 -d 255", 0.01, 255},
        {true, "ola_set_dmx -u 1 -d 51", 0.005 * 2 * 0.04, 10},
        {false, "oscsend 127.0.0.1 9000 /lamprig/dimmer f 0.5", 0.005 * 2 * 0.25, 64},
    };
    for (size_t i = 0; i < sizeof steps / sizeof steps[0]; i++) {
        int64_t t0 = lr_now_ns();
        int rc = steps[i].in_ns ? lr_test_sh("ip netns exec %s %s", p->ns, steps[i].cmd)
                                : lr_test_sh("%s", steps[i].cmd);
        assert_int_equal(rc, 0);
        reaches(r, mb, steps[i].cmd, t0, steps[i].intensity, steps[i].raw,
                "the command's own start included");
    }
    /* A scene of the OSC device's list: loaded off the loop, then shown. */
    assert_int_equal(lr_test_sh("oscsend 127.0.0.1 9000 /lamprig/scene s votive"), 0);
    int64_t guard = lr_now_ns() + 60000 * MS;
    while (!strstr(lr_scene_path(lr_rig_scene(r)), "votive.json") && lr_now_ns() < guard)
        if (lr_rig_run_until(r, lr_now_ns() + 20 * MS, &e))
            fail_msg("%s", e.msg);
    assert_non_null(strstr(lr_scene_path(lr_rig_scene(r)), "votive.json"));
    lr_rig_destroy(r);
    lr_test_mb_server_free(mb);
    lr_test_rmtree(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(qlcplus_drives_the_rig, peer_setup, peer_teardown),
        cmocka_unit_test_setup_teardown(ola_and_oscsend_drive_the_rig, peer_setup,
                                        peer_teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
