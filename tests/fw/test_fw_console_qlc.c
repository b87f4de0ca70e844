/* firmware/: QLC+ (headless, in a network namespace of its own, driven through its web socket
 * as tests/hal/test_hal_dmx_peers.c drives it) through the shipped console rig
 * (configs/rig/console.json, in-process) to both the rendered dimmer and the Modbus lamp. The
 * file is used as shipped except for absolute paths, a 16x16 preview output, the lamp on a
 * libmodbus server's free port and sACN's interface (the veth end: this namespace has no
 * default route for the multicast join). Art-Net keeps its fixed port 6454: the namespace is
 * the test's own. Skipped without qlcplus, ip or root. The latency from the web socket frame
 * to the rendered change and to the lamp's register is printed, not asserted (it includes
 * QLC+'s own output cadence). */
#include <errno.h>
#include <math.h>
#include <poll.h>
#include <sched.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "firmware/rig/rig.h"
#include "render/scene/scene.h"
#include "tests/support/dmx_build.h"
#include "tests/support/fs.h"
#include "tests/support/hal_test.h"
#include "tests/support/modbus_server.h"
#include "tests/support/near.h"

#define MS 1000000LL
#define CFG LR_SOURCE_CONFIGS
#define NS_NET "10.157.0"

static int sh(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static int sh(const char *fmt, ...)
{
    char cmd[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(cmd, sizeof cmd, fmt, ap);
    va_end(ap);
    return system(cmd);
}

static bool have(const char *prog)
{
    return sh("command -v %s >/dev/null 2>&1", prog) == 0;
}

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

/* RFC 6455, the smallest client: the upgrade, then masked text frames. */
static int ws_open(const char *host, int port)
{
    int fd = lr_test_tcp_connect(host, port);
    if (fd < 0)
        return -1;
    char req[256];
    int n = snprintf(req, sizeof req,
                     "GET /qlcplusWS HTTP/1.1\r\nHost: %s:%d\r\nUpgrade: websocket\r\n"
                     "Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
                     "Sec-WebSocket-Version: 13\r\n\r\n", host, port);
    char resp[512] = "";
    size_t got = 0;
    if (write(fd, req, (size_t)n) != n)
        goto fail;
    while (got < sizeof resp - 1 && !strstr(resp, "\r\n\r\n")) {
        struct pollfd pf = {.fd = fd, .events = POLLIN};
        if (poll(&pf, 1, 2000) != 1)
            goto fail;
        ssize_t k = read(fd, resp + got, sizeof resp - 1 - got);
        if (k <= 0)
            goto fail;
        got += (size_t)k;
        resp[got] = '\0';
    }
    if (strncmp(resp, "HTTP/1.1 101", 12) == 0)
        return fd;
fail:
    close(fd);
    return -1;
}

static void ws_text(int fd, const char *text)
{
    size_t n = strlen(text);
    assert_true(n < 126);
    uint8_t f[140];
    const uint8_t mask[4] = {0x12, 0x34, 0x56, 0x78};
    f[0] = 0x81;
    f[1] = 0x80 | (uint8_t)n;
    memcpy(f + 2, mask, 4);
    for (size_t i = 0; i < n; i++)
        f[6 + i] = (uint8_t)text[i] ^ mask[i % 4];
    assert_int_equal(write(fd, f, 6 + n), (ssize_t)(6 + n));
}

typedef struct peer {
    char ns[64], dir[64];
    pid_t qlc;
} peer;

static int peer_setup(void **state)
{
    *state = calloc(1, sizeof(peer));
    return *state ? 0 : -1;
}

/* Runs after a failed assertion too: no console or namespace is left behind. */
static int peer_teardown(void **state)
{
    peer *p = *state;
    if (p->qlc > 0) {
        kill(p->qlc, SIGTERM);
        waitpid(p->qlc, NULL, 0);
    }
    if (p->ns[0])
        sh("ip netns del %s 2>/dev/null", p->ns);
    if (p->dir[0])
        sh("rm -rf %s", p->dir);
    free(p);
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

static void qlcplus_drives_the_rig(void **state)
{
    peer *p = *state;
    if (!have("qlcplus") || !have("ip")) {
        print_message("qlcplus or ip not installed (Debian qlcplus, iproute2): skipped\n");
        skip();
    }
    if (geteuid() != 0 || unshare(CLONE_NEWNET) != 0 || sh("ip link set lo up") != 0) {
        print_message("no network namespace of our own (root needed): skipped\n");
        skip();
    }
    snprintf(p->ns, sizeof p->ns, "lamprig-qlcrig-%d", (int)getpid());
    if (sh("ip netns add %s && ip link add veth-lqr type veth peer name veth-qr netns %s && "
           "ip addr add " NS_NET ".1/24 brd + dev veth-lqr && ip link set veth-lqr up && "
           "ip -n %s addr add " NS_NET ".2/24 brd + dev veth-qr && ip -n %s link set veth-qr up",
           p->ns, p->ns, p->ns, p->ns) != 0) {
        print_message("could not set up the veth pair: skipped\n");
        skip();
    }
    snprintf(p->dir, sizeof p->dir, "/tmp/lamprig-qlcrig.XXXXXX");
    assert_non_null(mkdtemp(p->dir));
    char ws[128];
    snprintf(ws, sizeof ws, "%s/console.qxw", p->dir);
    FILE *f = fopen(ws, "w");
    assert_non_null(f);
    fputs(WORKSPACE, f);
    fclose(f);
    p->qlc = fork();
    assert_true(p->qlc >= 0);
    if (p->qlc == 0) {
        char log[128], env_home[128];
        snprintf(log, sizeof log, "%s/qlcplus.log", p->dir);
        snprintf(env_home, sizeof env_home, "HOME=%s", p->dir);
        if (!freopen(log, "w", stdout) || !freopen(log, "a", stderr))
            _exit(127);
        /* Its loopback left down (test_hal_dmx_peers.c says why): Art-Net on the veth. */
        execlp("ip", "ip", "netns", "exec", p->ns, "env", "QT_QPA_PLATFORM=offscreen", env_home,
               "XDG_RUNTIME_DIR=/tmp", "qlcplus", "--nowm", "--nogui", "--web", "--open", ws,
               (char *)NULL);
        _exit(127);
    }
    /* The rig: the shipped console.json. */
    lr_test_mb_server *mb = lr_test_mb_server_start();
    char text[8192];
    size_t len;
    char *shipped = (char *)lr_test_read(CFG "/rig/console.json", &len);
    assert_true(len < sizeof text / 2);
    memcpy(text, shipped, len);
    text[len] = '\0';
    free(shipped);
    replace(text, sizeof text, "\"../scenes/", "\"" CFG "/scenes/");
    replace(text, sizeof text, "\"../controls/", "\"" CFG "/controls/");
    replace(text, sizeof text, "\"type\": \"sacn\", \"name\": \"sacn\",",
            "\"type\": \"sacn\", \"name\": \"sacn\", \"interface\": \"" NS_NET ".1\",");
    char url[64];
    snprintf(url, sizeof url, "tcp://127.0.0.1:%d", lr_test_mb_server_port(mb));
    replace(text, sizeof text, "tcp://127.0.0.1:1502", url);
    replace(text, sizeof text, "\"width\": 320, \"height\": 240",
            "\"width\": 16, \"height\": 16, \"renderer\": \"preview\"");
    char *dir = lr_test_tmpdir();
    char *cfg = lr_test_write(dir, "rig.json", text, (size_t)-1);
    lr_test_log log = {0};
    lr_rig_opts o = {.config = cfg, .no_signals = true, .log = {lr_test_log_fn, &log}};
    lr_rig *r;
    lr_err e = {0};
    if (lr_rig_create(&o, &r, &e))
        fail_msg("%s", e.msg);
    int fd = -1;
    for (int i = 0; i < 150 && fd < 0; i++) {
        if (lr_rig_run_until(r, lr_now_ns() + 100 * MS, &e))
            fail_msg("%s", e.msg);
        fd = ws_open(NS_NET ".2", 9999);
    }
    if (fd < 0) {
        sh("cat %s/qlcplus.log >&2", p->dir);
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
        ws_text(fd, steps[i].cmd);
        double t1, tr, tl;
        run_to(r, mb, steps[i].intensity, steps[i].raw, t0, 5000, &t1, &tr, &tl);
        print_message("QLC+ %s: intensity first changed after %.0f ms, reached %.6g after %.0f "
                      "ms (the 0.25 s fade), lamp raw %d after %.0f ms (web socket frame to the "
                      "rig's state, QLC+'s output cadence included)\n",
                      steps[i].cmd, t1, steps[i].intensity, tr, steps[i].raw, tl);
        assert_true(tr >= 0);
        assert_true(tl >= 0);
        assert_near(scene_num(r, "light.intensity"), steps[i].intensity, 1e-12);
    }
    close(fd);
    lr_rig_destroy(r);
    lr_test_mb_server_free(mb);
    free(cfg);
    lr_test_rmtree(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(qlcplus_drives_the_rig, peer_setup, peer_teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
