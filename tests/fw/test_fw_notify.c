/* sd_notify from the rig (firmware/rig/notify.h), against a unix datagram socket that plays
 * systemd's side of NOTIFY_SOCKET:
 * - the module with a made-up clock: WATCHDOG_USEC/2 pacing, one ping per period, READY,
 *   RELOADING with MONOTONIC_USEC, STOPPING; no watchdog without WATCHDOG_USEC, for another
 *   WATCHDOG_PID or a malformed value;
 * - the rig loop in-process: READY=1 first, then WATCHDOG=1 with a STATUS line, never faster
 *   than the period, also while the rig is idle (the ping deadline wakes the poll); a loop
 *   that does not run sends nothing, and its first wake after the stall pings at once;
 * - build/bin/lamprig as a service would run it: stopped with SIGSTOP (the loop stalls, the
 *   process lives), no message for several watchdog periods, which is what makes systemd
 *   kill and restart it; after SIGCONT the pings resume; SIGHUP gives RELOADING=1 then
 *   READY=1; SIGTERM gives STOPPING=1 and exit 0.
 * Waits are failure guards (generous), never timing assertions; a stopped process sending
 * nothing and a pacing bound (pings <= elapsed / period + 1) hold on any machine. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include "firmware/rig/notify.h"
#include "firmware/rig/rig.h"
#include "hal/dev.h"
#include "tests/support/fs.h"
#include "tests/support/hal_test.h"

#define MS 1000000LL
#define LAMPRIG LR_SOURCE_CONFIGS "/../build/bin/lamprig"
#define GUARD_MS 60000 /* failure guard for anything that must eventually arrive */

/* ---- systemd's side: a bound datagram socket, NOTIFY_SOCKET pointing at it ---- */

typedef struct listener {
    char *dir;
    char *path;
    int fd;
} listener;

static void listen_start(listener *l)
{
    l->dir = lr_test_tmpdir();
    l->path = lr_test_path(l->dir, "notify.sock");
    l->fd = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    assert_true(l->fd >= 0);
    struct sockaddr_un a = {.sun_family = AF_UNIX};
    assert_true(strlen(l->path) < sizeof a.sun_path);
    strcpy(a.sun_path, l->path);
    assert_int_equal(bind(l->fd, (struct sockaddr *)&a, sizeof a), 0);
    setenv("NOTIFY_SOCKET", l->path, 1);
}

static void listen_stop(listener *l)
{
    unsetenv("NOTIFY_SOCKET");
    unsetenv("WATCHDOG_USEC");
    unsetenv("WATCHDOG_PID");
    close(l->fd);
    free(l->path);
    lr_test_rmtree(l->dir);
}

/* One datagram within timeout_ms (0: only one already queued); returns its length, 0 none. */
static int recv_msg(listener *l, int timeout_ms, char *buf, size_t cap)
{
    struct pollfd p = {l->fd, POLLIN, 0};
    int n = poll(&p, 1, timeout_ms);
    if (n <= 0)
        return 0;
    ssize_t k = recv(l->fd, buf, cap - 1, 0);
    assert_true(k > 0);
    buf[k] = '\0';
    return (int)k;
}

static bool has_line(const char *msg, const char *line)
{
    size_t n = strlen(line);
    for (const char *p = msg; p && *p; p = strchr(p, '\n') ? strchr(p, '\n') + 1 : NULL)
        if (!strncmp(p, line, n) && (p[n] == '\n' || p[n] == '\0'))
            return true;
    return false;
}

static int drain(listener *l)
{
    char buf[512];
    int n = 0;
    while (recv_msg(l, 0, buf, sizeof buf))
        n++;
    return n;
}

/* ---- the module, with a made-up clock ---- */

static void test_module_paces_and_reports(void **state)
{
    (void)state;
    listener l;
    listen_start(&l);
    setenv("WATCHDOG_USEC", "200000", 1);
    const int64_t t0 = 1000 * MS;
    lr_notify *n;
    lr_err e = {0};
    assert_int_equal(lr_notify_create(t0, &n, &e), LR_OK);
    /* sd_watchdog_enabled(3): ping at half the timeout. */
    assert_int_equal(lr_notify_interval_ns(n), 100 * MS);
    assert_int_equal(lr_notify_deadline(n), t0);
    char buf[512];
    lr_notify_ready(n, "starting");
    assert_true(recv_msg(&l, 0, buf, sizeof buf));
    assert_string_equal(buf, "READY=1\nSTATUS=starting");
    lr_notify_tick(n, t0, "s1");
    assert_true(recv_msg(&l, 0, buf, sizeof buf));
    assert_string_equal(buf, "WATCHDOG=1\nSTATUS=s1");
    assert_int_equal(lr_notify_deadline(n), t0 + 100 * MS);
    /* Before the deadline: nothing, however often the loop wakes. */
    for (int64_t t = t0; t < t0 + 100 * MS; t += 7 * MS)
        lr_notify_tick(n, t, "s2");
    assert_int_equal(drain(&l), 0);
    lr_notify_tick(n, t0 + 100 * MS, NULL);
    assert_true(recv_msg(&l, 0, buf, sizeof buf));
    assert_string_equal(buf, "WATCHDOG=1");
    /* A late wake (a stall of 3.5 periods) pings once and counts the period from then. */
    lr_notify_tick(n, t0 + 450 * MS, NULL);
    assert_int_equal(drain(&l), 1);
    assert_int_equal(lr_notify_deadline(n), t0 + 550 * MS);
    assert_int_equal(lr_notify_pings(n), 3);
    lr_notify_reloading(n, 123456789 * 1000LL);
    assert_true(recv_msg(&l, 0, buf, sizeof buf));
    assert_string_equal(buf, "RELOADING=1\nMONOTONIC_USEC=123456789");
    lr_notify_stopping(n);
    assert_true(recv_msg(&l, 0, buf, sizeof buf));
    assert_string_equal(buf, "STOPPING=1");
    lr_notify_destroy(n);
    listen_stop(&l);
}

static void check_no_watchdog(const char *usec, const char *pid)
{
    listener l;
    listen_start(&l);
    if (usec)
        setenv("WATCHDOG_USEC", usec, 1);
    if (pid)
        setenv("WATCHDOG_PID", pid, 1);
    lr_notify *n;
    lr_err e = {0};
    assert_int_equal(lr_notify_create(0, &n, &e), LR_OK);
    assert_int_equal(lr_notify_interval_ns(n), 0);
    assert_true(lr_notify_deadline(n) == INT64_MAX);
    lr_notify_tick(n, INT64_MAX - 1, "x");
    assert_int_equal(drain(&l), 0);
    lr_notify_ready(n, NULL); /* readiness is still told */
    char buf[64];
    assert_true(recv_msg(&l, 0, buf, sizeof buf));
    assert_string_equal(buf, "READY=1");
    lr_notify_destroy(n);
    listen_stop(&l);
}

static void test_module_without_watchdog(void **state)
{
    (void)state;
    check_no_watchdog(NULL, NULL);
    check_no_watchdog("not-a-number", NULL);
    check_no_watchdog("0", NULL);
    char other[32];
    snprintf(other, sizeof other, "%d", (int)getpid() + 1);
    check_no_watchdog("200000", other); /* meant for another process */
    /* No NOTIFY_SOCKET at all: every call is harmless. */
    unsetenv("NOTIFY_SOCKET");
    setenv("WATCHDOG_USEC", "200000", 1);
    lr_notify *n;
    lr_err e = {0};
    assert_int_equal(lr_notify_create(0, &n, &e), LR_OK);
    lr_notify_ready(n, "x");
    lr_notify_tick(n, 0, "x");
    lr_notify_stopping(n);
    assert_int_equal(lr_notify_pings(n), 1);
    lr_notify_destroy(n);
    unsetenv("WATCHDOG_USEC");
}

/* ---- the rig loop, in-process ---- */

static const char rig_text[] =
    "{\"scene\": \"%s/scenes/candle.json\",\n"
    " \"devices\": [{\"type\": \"sim\", \"text\": \"0.05 dimmer absolute 0.5\\n"
    "0.10 dimmer absolute 1.0\\n\"}],\n"
    " \"controls\": [{\"control\": \"dimmer\", \"param\": \"light.intensity\",\n"
    "   \"range\": [0, 0.01]}],\n"
    " \"scene_set\": {\"lights[0].flicker.amplitude\": 0},\n"
    " \"output\": {\"width\": 32, \"height\": 24, \"fps\": 100, \"renderer\": \"preview\"}}\n";

static void test_rig_loop_pings(void **state)
{
    (void)state;
    listener l;
    listen_start(&l);
    setenv("WATCHDOG_USEC", "40000", 1); /* a ping every 20 ms */
    const int64_t period = 20 * MS;
    char text[1024];
    snprintf(text, sizeof text, rig_text, LR_SOURCE_CONFIGS);
    char *cfg = lr_test_write(l.dir, "rig.json", text, (size_t)-1);
    lr_test_log log = {0};
    lr_rig_opts o = {.config = cfg, .no_signals = true, .no_plan = true,
                     .log = {lr_test_log_fn, &log}};
    lr_rig *r;
    lr_err e = {0};
    if (lr_rig_create(&o, &r, &e))
        fail_msg("%s", e.msg);
    assert_int_equal(drain(&l), 0); /* not ready before the loop runs */

    /* READY=1 first, then pings carrying the status, until the script is done and the
     * picture converged (the rig idle). */
    char buf[512];
    int ready = 0, pings = 0, other = 0;
    int64_t start = lr_now_ns(), guard = start + GUARD_MS * MS;
    lr_rig_info info;
    do {
        assert_int_equal(lr_rig_run_until(r, lr_now_ns() + 10 * MS, &e), LR_OK);
        while (recv_msg(&l, 0, buf, sizeof buf)) {
            if (has_line(buf, "READY=1")) {
                assert_int_equal(pings, 0);
                ready++;
            } else if (has_line(buf, "WATCHDOG=1")) {
                assert_int_equal(ready, 1);
                assert_non_null(strstr(buf, "\nSTATUS=candle.json, headless; "));
                assert_non_null(strstr(buf, " frames, "));
                pings++;
            } else {
                other++;
            }
        }
        lr_rig_get_info(r, &info);
    } while ((!info.idle || pings < 3 || info.events < 1) && lr_now_ns() < guard);
    int64_t elapsed = lr_now_ns() - start;
    assert_true(info.idle);
    assert_int_equal(ready, 1);
    assert_int_equal(other, 0);
    assert_true(pings >= 3);
    /* Paced: consecutive pings are at least one period apart. */
    assert_true(pings <= elapsed / period + 1);

    /* Idle: no frame or device deadline is due, yet the loop wakes for the ping. 6 periods
     * of idle loop in one call (the socket queues 10 datagrams by default and nobody reads
     * meanwhile): without the ping deadline in the poll timeout only the entry pings. */
    assert_int_equal(drain(&l), 0);
    int64_t t = lr_now_ns();
    assert_int_equal(lr_rig_run_until(r, t + 6 * period, &e), LR_OK);
    int idle_pings = drain(&l);
    assert_true(idle_pings >= 3);
    assert_true(idle_pings <= (lr_now_ns() - t) / period + 1);

    /* A stall: the loop does not run for 5 periods; nothing is sent meanwhile, and the
     * first wake after it pings at once. */
    usleep(5 * 20 * 1000);
    assert_int_equal(drain(&l), 0);
    assert_int_equal(lr_rig_run_until(r, lr_now_ns(), &e), LR_OK); /* one pass */
    assert_true(recv_msg(&l, 0, buf, sizeof buf));
    assert_true(has_line(buf, "WATCHDOG=1"));

    /* Reload: RELOADING=1 (with the monotonic time), then READY=1 again. */
    assert_int_equal(lr_rig_reload(r, &e), LR_OK);
    assert_true(recv_msg(&l, 0, buf, sizeof buf));
    assert_true(has_line(buf, "RELOADING=1"));
    assert_non_null(strstr(buf, "\nMONOTONIC_USEC="));
    assert_true(recv_msg(&l, 0, buf, sizeof buf));
    assert_true(has_line(buf, "READY=1"));
    assert_non_null(strstr(buf, "1 reloads (0 failed)"));
    lr_rig_destroy(r);
    assert_true(recv_msg(&l, 0, buf, sizeof buf));
    assert_string_equal(buf, "STOPPING=1");
    free(cfg);
    listen_stop(&l);
}

/* ---- build/bin/lamprig, stalled from outside ---- */

/* Waits (failure guard) for a message with `line`; counts WATCHDOG=1 seen on the way. */
static bool wait_for(listener *l, const char *line, int *pings)
{
    char buf[512];
    int64_t guard = lr_now_ns() + GUARD_MS * MS;
    while (lr_now_ns() < guard) {
        if (!recv_msg(l, 200, buf, sizeof buf))
            continue;
        if (has_line(buf, "WATCHDOG=1") && pings)
            (*pings)++;
        if (has_line(buf, line))
            return true;
    }
    return false;
}

static void test_stalled_process_stops_pings(void **state)
{
    (void)state;
    listener l;
    listen_start(&l);
    char text[1024];
    snprintf(text, sizeof text, rig_text, LR_SOURCE_CONFIGS);
    char *cfg = lr_test_write(l.dir, "rig.json", text, (size_t)-1);
    char *out = lr_test_path(l.dir, "out.txt");
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        int fd = open(out, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fd >= 0) {
            dup2(fd, 1);
            dup2(fd, 2);
        }
        /* What systemd sets for WatchdogSec=0.1 (WATCHDOG_PID names the main process). */
        char p[32];
        snprintf(p, sizeof p, "%d", (int)getpid());
        setenv("WATCHDOG_PID", p, 1);
        setenv("WATCHDOG_USEC", "100000", 1);
        unsetenv("ASAN_OPTIONS");
        unsetenv("LSAN_OPTIONS");
        execl(LAMPRIG, LAMPRIG, "run", "--config", cfg, "--no-plan", "--duration", "120",
              (char *)NULL);
        _exit(127);
    }
    int pings = 0;
    assert_true(wait_for(&l, "READY=1", &pings));
    assert_int_equal(pings, 0);
    int more = 0;
    for (int i = 0; i < 3; i++)
        assert_true(wait_for(&l, "WATCHDOG=1", &more));

    /* The loop stalls: stopped, and waited for until it is (so nothing is in flight). */
    assert_int_equal(kill(pid, SIGSTOP), 0);
    int st;
    assert_int_equal(waitpid(pid, &st, WUNTRACED), pid);
    assert_true(WIFSTOPPED(st));
    drain(&l);
    /* Five watchdog timeouts (0.5 s) of silence: systemd would have killed it after one. */
    char buf[512];
    assert_int_equal(recv_msg(&l, 500, buf, sizeof buf), 0);

    /* Running again: the pings come back. */
    assert_int_equal(kill(pid, SIGCONT), 0);
    assert_true(wait_for(&l, "WATCHDOG=1", NULL));
    /* SIGHUP: RELOADING=1, then READY=1. */
    assert_int_equal(kill(pid, SIGHUP), 0);
    assert_true(wait_for(&l, "RELOADING=1", NULL));
    assert_true(wait_for(&l, "READY=1", NULL));
    /* SIGTERM: STOPPING=1, exit 0. */
    assert_int_equal(kill(pid, SIGTERM), 0);
    assert_true(wait_for(&l, "STOPPING=1", NULL));
    assert_int_equal(waitpid(pid, &st, 0), pid);
    if (!WIFEXITED(st) || WEXITSTATUS(st) != 0) {
        size_t n;
        unsigned char *log = lr_test_read(out, &n);
        print_error("%s\n", (char *)log);
        free(log);
        fail_msg("lamprig run: status %d", st);
    }
    free(out);
    free(cfg);
    listen_stop(&l);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_module_paces_and_reports),
        cmocka_unit_test(test_module_without_watchdog),
        cmocka_unit_test(test_rig_loop_pings),
        cmocka_unit_test(test_stalled_process_stops_pings),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
