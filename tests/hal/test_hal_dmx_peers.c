/* hal/: the sACN and Art-Net receivers against consoles nobody on this team wrote.
 *
 * OLA: olad (as its own user, with a fresh config folder) sends what ola_set_dmx and
 * ola_streaming_client give it, over E1.31 (multicast 239.255.0.1) and Art-Net (unicast, to a
 * node that answered its ArtPoll). QLC+: qlcplus headless (offscreen, --nogui --web) with a
 * workspace whose universe 1 goes to its E1.31 output and universe 2 to its Art-Net output,
 * driven through its web socket (the Simple Desk's "CH|address|value").
 *
 * OLA's E1.31 output does not work on bare loopback, so the test moves itself into a network
 * namespace of its own (unshare) and puts each console in another one, joined to it by a veth
 * pair (OLA 10.155.0.2, QLC+ 10.156.0.2; this side .1): the fixed ports 5568, 6454, 9010 and
 * 9999 are bound only inside them. Each test is skipped with a message when not root or when
 * its programs (olad, ola_*, qlcplus; ip, setpriv) are missing. */
#include <errno.h>
#include <poll.h>
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
#include "tests/support/console_peer.h"
#include "tests/support/dmx_build.h"
#include "tests/support/hal_test.h"

#define MS 1000000LL

typedef struct peer {
    lr_test_peer c; /* the console: olad or qlcplus (tests/support/console_peer.h) */
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

static int peer_setup(void **state)
{
    *state = calloc(1, sizeof(peer));
    return *state ? 0 : -1;
}

/* Runs after a failed assertion too: no console or namespace is left behind. */
static int peer_teardown(void **state)
{
    lr_test_peer_stop(&((peer *)*state)->c);
    free(*state);
    return 0;
}

static void ola_drives_both(void **state)
{
    char why[160];
    peer *p = *state;
    const char *need[] = {"olad", "ola_patch", "ola_set_dmx", "ola_streaming_client",
                          "ola_dev_info", NULL};
    for (int i = 0; need[i]; i++)
        if (!lr_test_have(need[i])) {
            print_message("%s not installed (Debian ola): skipped\n", need[i]);
            skip();
        }
    if (!lr_test_netns_ok(why, sizeof why) || !lr_test_peer_ns(&p->c, "ola", "10.155.0", why, sizeof why)) {
        print_message("%s\n", why);
        skip();
    }
    if (!lr_test_olad_start(&p->c, "10.155.0.2")) {
        lr_test_sh("cat %s/olad.log >&2", p->c.dir);
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
    int de = lr_test_olad_device(&p->c, "E1.31"), da = lr_test_olad_device(&p->c, "ArtNet");
    assert_true(de > 0 && da > 0);
    assert_int_equal(lr_test_sh("ip netns exec %s ola_patch -d %d -p 0 -u 1", p->c.ns, de), 0);
    assert_int_equal(lr_test_sh("ip netns exec %s ola_patch -d %d -p 0 -u 1", p->c.ns, da), 0);
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
        assert_int_equal(lr_test_sh("ip netns exec %s ola_streaming_client -u 1 -d 51,0,0,1", p->c.ns),
                         0);
        seen = lr_test_run(devs, 2, 1000, both_at, &w);
    }
    if (!seen) {
        for (int i = 0; i < r.n; i++)
            print_message("event %s/%s %.9f\n", r.ev[i].source, r.ev[i].control, r.ev[i].value);
        fail_msg("ola_streaming_client did not reach both receivers in 5 tries (%d events)", r.n);
    }
    assert_int_equal(lr_test_sh("ip netns exec %s ola_set_dmx -u 1 -d 255,0,128,64", p->c.ns), 0);
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

/* ---- QLC+ ---- */

/* Universe 1 (ID 0) to QLC+'s E1.31 output, universe 2 (ID 1) to its Art-Net output, each on
 * line 0: the namespace's only interface with an address (its loopback stays down, so no
 * 127.0.0.1 line comes first). QLC+'s defaults then send E1.31 universe 1 by multicast and
 * Art-Net universe 1 (its universe index) by broadcast to 10.156.0.255. */
static const char WORKSPACE[] =
    "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<!DOCTYPE Workspace>\n"
    "<Workspace xmlns=\"http://www.qlcplus.org/Workspace\" CurrentWindow=\"SimpleDesk\">\n"
    " <Creator><Name>Q Light Controller Plus</Name><Version>4.12.6</Version>"
    "<Author>lamprig tests</Author></Creator>\n"
    " <Engine>\n  <InputOutputMap>\n   <BeatGenerator BeatType=\"Disabled\" BPM=\"0\"/>\n"
    "   <Universe Name=\"Universe 1\" ID=\"0\"><Output Plugin=\"E1.31\" Line=\"0\"/></Universe>\n"
    "   <Universe Name=\"Universe 2\" ID=\"1\"><Output Plugin=\"ArtNet\" Line=\"0\"/></Universe>\n"
    "  </InputOutputMap>\n </Engine>\n</Workspace>\n";

static void qlcplus_drives_both(void **state)
{
    char why[160];
    peer *p = *state;
    if (!lr_test_have("qlcplus")) {
        print_message("qlcplus not installed (Debian qlcplus): skipped\n");
        skip();
    }
    if (!lr_test_netns_ok(why, sizeof why) || !lr_test_peer_ns(&p->c, "qlc", "10.156.0", why, sizeof why)) {
        print_message("%s\n", why);
        skip();
    }
    lr_test_qlc_start(&p->c, WORKSPACE);
    rec r = {0};
    lr_test_log log = {0};
    const lr_dmx_channel ch[] = {
        {.control = "dimmer", .universe = 1, .channel = 1, .home = NAN},
        {.control = "fine", .universe = 1, .channel = 3, .fine = 4, .home = NAN},
    };
    lr_sacn_desc sd = {.dev = {.sink = {rec_fn, &r}, .log = {lr_test_log_fn, &log}},
                       .interface = "10.156.0.1", .channels = ch, .n_channels = 2};
    lr_artnet_desc ad = {.dev = {.sink = {rec_fn, &r}, .log = {lr_test_log_fn, &log}},
                         .announce = "none", .channels = ch, .n_channels = 1};
    lr_sacn *s;
    lr_artnet *a;
    lr_err e = {0};
    if (lr_sacn_create(&sd, &s, &e) || lr_artnet_create(&ad, &a, &e))
        fail_msg("%s", e.msg);
    /* Its web server answers within a few seconds of the start. */
    int fd = -1;
    for (int i = 0; i < 150 && fd < 0; i++) {
        usleep(100000);
        fd = lr_test_qlc_ws_open("10.156.0.2");
    }
    if (fd < 0) {
        lr_test_sh("cat %s/qlcplus.log >&2", p->c.dir);
        fail_msg("QLC+'s web socket did not answer in 15 s (its log above)");
    }
    /* Simple Desk absolute addresses: universe 1 is 1..512, universe 2 is 513..1024. */
    lr_test_qlc_ws_text(fd, "CH|1|255");
    lr_test_qlc_ws_text(fd, "CH|3|128");
    lr_test_qlc_ws_text(fd, "CH|4|64");
    lr_test_qlc_ws_text(fd, "CH|513|255");
    lr_dev *devs[2] = {lr_sacn_dev(s), lr_artnet_dev(a)};
    want w = {&r, 1.0, (128 * 256 + 64) / 65535.0};
    if (!lr_test_run(devs, 2, 5000, both_at, &w)) {
        for (int i = 0; i < r.n; i++)
            print_message("event %s/%s %.9f\n", r.ev[i].source, r.ev[i].control, r.ev[i].value);
        fail_msg("QLC+'s Simple Desk did not reach both receivers in 5 s (%d events)", r.n);
    }
    /* A fader down: the second look replaces the first (QLC+ streams its universes
     * continuously, about 50 packets a second measured here, so sACN sees it at once). */
    lr_test_qlc_ws_text(fd, "CH|1|51");
    lr_test_qlc_ws_text(fd, "CH|513|51");
    w.dimmer = 51 / 255.0;
    if (!lr_test_run(devs, 2, 5000, both_at, &w))
        fail_msg("QLC+'s second look did not reach both receivers in 5 s");
    close(fd);
    lr_dmx_counters c;
    lr_sacn_get_counters(s, &c);
    assert_int_equal(c.bad, 0);
    assert_true(c.taken >= 2);
    lr_artnet_get_counters(a, &c);
    assert_int_equal(c.bad, 0);
    lr_sacn_destroy(s);
    lr_artnet_destroy(a);
}

/* A rig started before its network: no multicast route, so the join fails (one warning) and
 * unicast works; once an interface with a route is up, the retry 5 s later joins (one line).
 * Runs in the test's own namespace, which has only its loopback until the test adds one. */
static void multicast_join_retry(void **state)
{
    (void)state;
    char why[160];
    if (!lr_test_netns_ok(why, sizeof why)) {
        print_message("%s\n", why);
        skip();
    }
    lr_test_sh("ip route del 224.0.0.0/4 2>/dev/null; ip link del lrv0 2>/dev/null");
    rec r = {0};
    lr_test_log log = {0};
    const lr_dmx_channel ch[] = {{.control = "dimmer", .universe = 7, .channel = 1, .home = NAN}};
    lr_sacn_desc sd = {.dev = {.sink = {rec_fn, &r}, .log = {lr_test_log_fn, &log}},
                       .port = 15540, .channels = ch, .n_channels = 1};
    lr_sacn *s;
    lr_err e = {0};
    if (lr_sacn_create(&sd, &s, &e))
        fail_msg("%s", e.msg);
    lr_dev *d = lr_sacn_dev(s);
    assert_int_equal(lr_dev_get_state(d), LR_DEV_OPEN);
    assert_int_equal(lr_test_log_count(&log, "joined 0 of 1 multicast groups"), 1);
    int64_t retry = lr_dev_next_deadline(d);
    int64_t now = lr_now_ns();
    /* 5 s from the open, which was just before `now`. */
    assert_true(retry > now + 4900 * MS && retry <= now + 5000 * MS);
    lr_dev_dispatch(d, retry - 1);
    assert_int_equal(lr_test_log_count(&log, "multicast groups"), 1); /* no retry yet */
    /* The network comes up: a veth pair (no dummy module in every kernel) with a route. */
    assert_int_equal(lr_test_sh("ip link add lrv0 type veth peer name lrv1 && "
                        "ip addr add 10.157.0.1/24 dev lrv0 && ip link set lrv0 up && "
                        "ip link set lrv1 up && ip route add 224.0.0.0/4 dev lrv0"), 0);
    lr_dev_dispatch(d, retry);
    assert_int_equal(lr_test_log_count(&log, "joined all 1 multicast groups"), 1);
    assert_int_equal(lr_dev_next_deadline(d), LR_NO_DEADLINE);
    lr_sacn_destroy(s);
    lr_test_sh("ip link del lrv0");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(ola_drives_both, peer_setup, peer_teardown),
        cmocka_unit_test_setup_teardown(qlcplus_drives_both, peer_setup, peer_teardown),
        cmocka_unit_test(multicast_join_retry),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
