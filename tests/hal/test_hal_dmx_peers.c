/* hal/: the sACN and Art-Net receivers against OLA, a console nobody on this team wrote: olad
 * (as its own user, with a fresh config folder) sends what ola_set_dmx and
 * ola_streaming_client give it, over E1.31 (multicast 239.255.0.1) and Art-Net (unicast, to
 * a node that answered its ArtPoll). OLA's E1.31 output does not work on bare loopback, so the
 * test moves itself into a network namespace of its own (unshare), creates a second one for
 * olad and joins them with a veth pair (10.155.0.1 here, 10.155.0.2 there): the fixed ports
 * 5568 and 6454 are bound only inside them. Skipped with a message when not root or when
 * olad, ola_patch, ola_set_dmx, ola_streaming_client, ip or setpriv is missing. */
#include <errno.h>
#include <math.h>
#include <sched.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "hal/artnet.h"
#include "hal/sacn.h"
#include "tests/support/hal_test.h"

#define MS 1000000LL

typedef struct peer {
    char ns[64];
    char dir[64];
    pid_t olad;
    bool ready;
    char skip_reason[160];
} peer;

typedef struct rec {
    int n;
    lr_event ev[512];
} rec;

static void rec_fn(void *user, const lr_event *ev)
{
    rec *r = user;
    if (r->n < 512)
        r->ev[r->n++] = *ev;
}

static const lr_event *last_of(const rec *r, const char *source, const char *control)
{
    for (int i = r->n - 1; i >= 0; i--)
        if (strcmp(r->ev[i].source, source) == 0 && strcmp(r->ev[i].control, control) == 0)
            return &r->ev[i];
    return NULL;
}

static int sh(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static int sh(const char *fmt, ...)
{
    char cmd[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(cmd, sizeof cmd, fmt, ap);
    va_end(ap);
    int st = system(cmd);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static bool have(const char *prog)
{
    return sh("command -v %s >/dev/null 2>&1", prog) == 0;
}

/* OLA's plugins: all off but E1.31 and Art-Net, bound to the veth address (a plugin probing
 * USB and serial devices would only slow the start). */
static void write_ola_config(const char *dir)
{
    static const char *const off[] = {"dummy", "espnet", "ftdidmx", "gpio", "karate", "kinet",
                                      "milinst", "opendmx", "openpixelcontrol", "osc",
                                      "pathport", "renard", "sandnet", "shownet", "spi",
                                      "stageprofi", "uartdmx", "usbdmx", "usbserial", NULL};
    char path[256];
    for (int i = 0; off[i]; i++) {
        snprintf(path, sizeof path, "%s/ola-%s.conf", dir, off[i]);
        FILE *f = fopen(path, "w");
        assert_non_null(f);
        fputs("enabled = false\n", f);
        fclose(f);
    }
    snprintf(path, sizeof path, "%s/ola-e131.conf", dir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs("enabled = true\nip = 10.155.0.2\ninput_ports = 0\noutput_ports = 1\n", f);
    fclose(f);
    snprintf(path, sizeof path, "%s/ola-artnet.conf", dir);
    f = fopen(path, "w");
    assert_non_null(f);
    fputs("enabled = true\nip = 10.155.0.2\noutput_ports = 1\n", f);
    fclose(f);
}

static int setup(void **state)
{
    static peer p;
    memset(&p, 0, sizeof p);
    *state = &p;
    const char *need[] = {"olad", "ola_patch", "ola_set_dmx", "ola_streaming_client",
                          "ola_dev_info", "ip", "setpriv", NULL};
    for (int i = 0; need[i]; i++)
        if (!have(need[i])) {
            snprintf(p.skip_reason, sizeof p.skip_reason,
                     "%s not installed (Debian ola, iproute2, util-linux): skipped", need[i]);
            return 0;
        }
    if (geteuid() != 0) {
        snprintf(p.skip_reason, sizeof p.skip_reason,
                 "not root: network namespaces and olad's user need it: skipped");
        return 0;
    }
    if (unshare(CLONE_NEWNET) != 0) {
        snprintf(p.skip_reason, sizeof p.skip_reason, "unshare(CLONE_NEWNET): %s: skipped",
                 strerror(errno));
        return 0;
    }
    snprintf(p.ns, sizeof p.ns, "lamprig-ola-%d", (int)getpid());
    if (sh("ip link set lo up && ip netns add %s && "
           "ip link add veth-lr type veth peer name veth-ola netns %s && "
           "ip addr add 10.155.0.1/24 brd + dev veth-lr && ip link set veth-lr up && "
           "ip -n %s link set lo up && ip -n %s addr add 10.155.0.2/24 brd + dev veth-ola && "
           "ip -n %s link set veth-ola up && ip -n %s route add 224.0.0.0/4 dev veth-ola",
           p.ns, p.ns, p.ns, p.ns, p.ns, p.ns) != 0) {
        snprintf(p.skip_reason, sizeof p.skip_reason, "could not set up the veth pair: skipped");
        return 0;
    }
    snprintf(p.dir, sizeof p.dir, "/tmp/lamprig-ola.XXXXXX");
    assert_non_null(mkdtemp(p.dir));
    write_ola_config(p.dir);
    assert_int_equal(sh("chown -R olad %s", p.dir), 0);
    p.olad = fork();
    assert_true(p.olad >= 0);
    if (p.olad == 0) {
        char log[128];
        snprintf(log, sizeof log, "%s/olad.log", p.dir);
        if (!freopen(log, "w", stdout) || !freopen(log, "a", stderr))
            _exit(127);
        /* setpriv execs olad itself (no forking wrapper): the pid is olad's. */
        execlp("ip", "ip", "netns", "exec", p.ns, "setpriv", "--reuid=olad", "--regid=nogroup",
               "--clear-groups", "olad", "-c", p.dir, "--no-http", "--no-register-with-dns-sd",
               "-l", "3", (char *)NULL);
        _exit(127);
    }
    /* Ready when its RPC answers (about a second). */
    for (int i = 0; i < 100 && !p.ready; i++) {
        usleep(100000);
        p.ready = sh("ip netns exec %s ola_dev_info >%s/devs 2>/dev/null", p.ns, p.dir) == 0 &&
                  sh("grep -q E1.31 %s/devs && grep -q ArtNet %s/devs", p.dir, p.dir) == 0;
    }
    return 0;
}

static int teardown(void **state)
{
    peer *p = *state;
    if (p->olad > 0) {
        kill(p->olad, SIGTERM);
        waitpid(p->olad, NULL, 0);
    }
    if (p->ns[0])
        sh("ip netns del %s 2>/dev/null", p->ns);
    if (p->dir[0])
        sh("rm -rf %s", p->dir);
    return 0;
}

/* The device number of the line naming kind in ola_dev_info's output ("Device 2: E1.31 ..."). */
static int device_number(const peer *p, const char *kind)
{
    char path[128], line[256];
    snprintf(path, sizeof path, "%s/devs", p->dir);
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    int n = -1;
    while (fgets(line, sizeof line, f))
        if (strstr(line, kind) && sscanf(line, "Device %d:", &n) == 1)
            break;
    fclose(f);
    return n;
}

typedef struct want {
    rec *r;
    double dimmer, fine;
} want;

static bool both_at(void *user)
{
    want *w = user;
    const lr_event *a = last_of(w->r, "sacn", "dimmer"), *b = last_of(w->r, "artnet", "dimmer");
    const lr_event *f = last_of(w->r, "sacn", "fine");
    return a && b && f && fabs(a->value - w->dimmer) < 1e-12 &&
           fabs(b->value - w->dimmer) < 1e-12 && fabs(f->value - w->fine) < 1e-12;
}

static void ola_drives_both(void **state)
{
    peer *p = *state;
    if (p->skip_reason[0]) {
        print_message("%s\n", p->skip_reason);
        skip();
    }
    if (!p->ready) {
        sh("cat %s/olad.log >&2", p->dir);
        fail_msg("olad did not come up in 10 s (its log above)");
    }
    rec r = {0};
    lr_test_log log = {0};
    /* OLA universe 1 is E1.31 universe 1 and Art-Net port-address 1. */
    const lr_dmx_channel ch[] = {
        {.control = "dimmer", .universe = 1, .channel = 1, .home = NAN},
        {.control = "fine", .universe = 1, .channel = 3, .fine = 4, .home = NAN},
    };
    lr_sacn_desc sd = {.dev = {.sink = {rec_fn, &r}, .log = {lr_test_log_fn, &log}},
                       .interface = "10.155.0.1", .channels = ch, .n_channels = 2};
    lr_artnet_desc ad = {.dev = {.sink = {rec_fn, &r}, .log = {lr_test_log_fn, &log}},
                         .announce = "10.155.0.255", .channels = ch, .n_channels = 1};
    lr_sacn *s;
    lr_artnet *a;
    lr_err e = {0};
    if (lr_sacn_create(&sd, &s, &e) || lr_artnet_create(&ad, &a, &e))
        fail_msg("%s", e.msg);
    assert_int_equal(lr_test_log_count(&log, "multicast groups"), 0); /* joined */
    /* Patching enables OLA's ports, and the first enabled Art-Net port makes it poll: our
     * node answers, listing port-address 1, and OLA then sends that universe to us. */
    int de = device_number(p, "E1.31"), da = device_number(p, "ArtNet");
    assert_true(de > 0 && da > 0);
    assert_int_equal(sh("ip netns exec %s ola_patch -d %d -p 0 -u 1", p->ns, de), 0);
    assert_int_equal(sh("ip netns exec %s ola_patch -d %d -p 0 -u 1", p->ns, da), 0);
    lr_dev *devs[2] = {lr_sacn_dev(s), lr_artnet_dev(a)};
    lr_test_run(devs, 2, 300, NULL, NULL); /* OLA's poll and our reply */

    /* The streaming client first: OLA merges its clients HTP and keeps a finished client's
     * values a while, so the second look must be the higher one on every channel. The
     * streaming client sends without waiting for an answer and exits: in about 2 of 5 runs
     * here its one frame reached neither receiver (no packet from olad at all). So it sends again,
     * at most 5 times, until the receivers have the look. */
    /* 51 / 255, and (0 * 256 + 1) / 65535 for the 16-bit pair 3/4. */
    want w = {&r, 51 / 255.0, 1 / 65535.0};
    bool seen = false;
    for (int k = 0; k < 5 && !seen; k++) {
        assert_int_equal(sh("ip netns exec %s ola_streaming_client -u 1 -d 51,0,0,1", p->ns),
                         0);
        seen = lr_test_run(devs, 2, 1000, both_at, &w);
    }
    if (!seen) {
        for (int i = 0; i < r.n; i++)
            print_message("event %s/%s %.9f\n", r.ev[i].source, r.ev[i].control, r.ev[i].value);
        fail_msg("ola_streaming_client did not reach both receivers in 5 tries (%d events)", r.n);
    }
    assert_int_equal(sh("ip netns exec %s ola_set_dmx -u 1 -d 255,0,128,64", p->ns), 0);
    w = (want){&r, 1.0, (128 * 256 + 64) / 65535.0};
    if (!lr_test_run(devs, 2, 5000, both_at, &w))
        fail_msg("ola_set_dmx did not reach both receivers in 5 s");
    lr_dmx_counters c;
    lr_sacn_get_counters(s, &c);
    assert_int_equal(c.bad, 0);
    assert_true(c.taken >= 2);
    lr_artnet_get_counters(a, &c);
    assert_int_equal(c.bad, 0);
    assert_true(c.polls >= 1 && c.replies >= 1);
    lr_sacn_destroy(s);
    lr_artnet_destroy(a);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(ola_drives_both),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
