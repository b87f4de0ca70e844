/* hal/: the OSC input (liblo) on 127.0.0.1 (ports 15520-15529): messages sent with liblo's
 * client in this process, then with liblo's own `oscsend` program as a peer this project did
 * not write (skipped with a message when it is not installed). Covered: dimmer and
 * control/NAME as absolute events with the sent value, int/double accepted, scene by name and
 * by index at (k + 0.5) / n, every kind of bad message counted with one log line per kind
 * (including a datagram liblo cannot parse), max_packets per dispatch. */
#include <lo/lo.h>
#include <math.h>
#include <poll.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "hal/osc.h"
#include "tests/support/cli.h"
#include "tests/support/dmx_build.h"
#include "tests/support/hal_test.h"

typedef struct rec {
    int n;
    lr_event ev[256];
} rec;

static void rec_fn(void *user, const lr_event *ev)
{
    rec *r = user;
    if (r->n < 256)
        r->ev[r->n++] = *ev;
}

static uint64_t messages(lr_osc *o)
{
    lr_osc_counters c;
    lr_osc_get_counters(o, &c);
    return c.messages;
}

static void pump(lr_osc *o, uint64_t want)
{
    lr_dev *d = lr_osc_dev(o);
    for (int guard = 0; messages(o) < want && guard < 100; guard++) {
        struct pollfd p;
        assert_int_equal(lr_dev_pollfds(d, &p, 1), 1);
        poll(&p, 1, 50);
        lr_dev_dispatch(d, lr_now_ns());
    }
    assert_int_equal(messages(o), want);
}

static const char *const SCENES[] = {"candle", "marble", "wax"};

static lr_osc *make(rec *r, lr_test_log *log, int port)
{
    lr_osc_desc d = {.dev = {.sink = {rec_fn, r}, .log = {lr_test_log_fn, log}}, .port = port,
                     .scenes = SCENES, .n_scenes = 3, .max_packets = 4};
    lr_osc *o = NULL;
    lr_err e = {0};
    if (lr_osc_create(&d, &o, &e))
        fail_msg("%s", e.msg);
    assert_int_equal(lr_dev_get_state(lr_osc_dev(o)), LR_DEV_OPEN);
    return o;
}

static void osc_messages(void **state)
{
    (void)state;
    rec r = {0};
    lr_test_log log = {0};
    lr_osc *o = make(&r, &log, 15520);
    lo_address to = lo_address_new("127.0.0.1", "15520");
    assert_int_equal(lo_send(to, "/lamprig/dimmer", "f", 0.75f), 24);
    lo_send(to, "/lamprig/control/shade", "d", 0.125);
    lo_send(to, "/lamprig/control/knob2", "i", 1);
    lo_send(to, "/lamprig/scene", "s", "wax");
    lo_send(to, "/lamprig/scene", "i", 1);
    pump(o, 5);
    assert_int_equal(r.n, 5);
    assert_string_equal(r.ev[0].source, "osc");
    assert_string_equal(r.ev[0].control, "dimmer");
    assert_int_equal(r.ev[0].kind, LR_EV_ABSOLUTE);
    assert_float_equal(r.ev[0].value, 0.75, 0); /* 0.75 is exact in float */
    assert_string_equal(r.ev[1].control, "shade");
    assert_float_equal(r.ev[1].value, 0.125, 0);
    assert_string_equal(r.ev[2].control, "knob2");
    assert_float_equal(r.ev[2].value, 1, 0);
    /* "wax" is scene 2 of 3: (2 + 0.5) / 3; index 1: 1.5 / 3; floor(x * 3) gives 2 and 1. */
    assert_string_equal(r.ev[3].control, "scene");
    assert_float_equal(r.ev[3].value, 2.5 / 3, 1e-15);
    assert_int_equal((int)floor(r.ev[3].value * 3), 2);
    assert_float_equal(r.ev[4].value, 1.5 / 3, 1e-15);

    /* Bad ones, two of each kind: one log line per kind. */
    for (int k = 0; k < 2; k++) {
        lo_send(to, "/other/dimmer", "f", 0.5f);           /* address */
        lo_send(to, "/lamprig/dimmer", "s", "full");       /* types */
        lo_send(to, "/lamprig/dimmer", "ff", 0.5f, 0.5f);  /* types */
        lo_send(to, "/lamprig/dimmer", "f", (float)NAN);   /* value */
        lo_send(to, "/lamprig/control/bad name", "f", 1.f); /* value: a space in the name */
        lo_send(to, "/lamprig/scene", "s", "nowhere");     /* scene */
        lo_send(to, "/lamprig/scene", "i", 3);             /* scene: index out of range */
    }
    /* Not OSC at all (an sACN packet to the OSC port): liblo drops it. */
    int tx = lr_test_udp_socket(0);
    uint8_t b[700], sl[1] = {1};
    size_t n = lr_test_sacn_build(b, 1, 100, 0, 0, 0, sl, 1, 1);
    lr_test_udp_send(tx, 15520, b, n);
    lr_test_udp_send(tx, 15520, "garbage", 7);
    close(tx);
    pump(o, 5 + 14 + 2);
    assert_int_equal(r.n, 5);
    lr_osc_counters c;
    lr_osc_get_counters(o, &c);
    assert_int_equal(c.bad_kind[LR_OSC_BAD_ADDRESS], 2);
    assert_int_equal(c.bad_kind[LR_OSC_BAD_TYPES], 4);
    assert_int_equal(c.bad_kind[LR_OSC_BAD_VALUE], 4);
    assert_int_equal(c.bad_kind[LR_OSC_BAD_SCENE], 4);
    assert_int_equal(c.bad_kind[LR_OSC_BAD_PACKET], 2);
    assert_int_equal(c.bad, 16);
    assert_int_equal(lr_test_log_count(&log, "dropped; later ones"), 5);
    assert_int_equal(lr_test_log_count(&log, "unknown address: /other/dimmer"), 1);

    /* max_packets 4: a burst of 10 takes three dispatches, the first asking for more. */
    for (int k = 0; k < 10; k++)
        lo_send(to, "/lamprig/dimmer", "f", k / 10.0f);
    struct pollfd p;
    lr_dev_pollfds(lr_osc_dev(o), &p, 1);
    assert_int_equal(poll(&p, 1, 1000), 1);
    usleep(20000); /* let the whole burst land in the socket */
    lr_dev_dispatch(lr_osc_dev(o), lr_now_ns());
    assert_int_equal(messages(o), 21 + 4);
    assert_int_equal(lr_dev_next_deadline(lr_osc_dev(o)), 0);
    pump(o, 31);
    assert_float_equal(r.ev[r.n - 1].value, 0.9f, 0);
    lo_address_free(to);
    lr_osc_destroy(o);

    /* The port in use: the device retries, naming it. */
    lr_osc *o1 = make(&r, &log, 15521);
    lr_osc_desc d2 = {.dev = {.sink = {rec_fn, &r}, .log = {lr_test_log_fn, &log}},
                      .port = 15521};
    lr_osc *o2 = NULL;
    lr_err e = {0};
    assert_int_equal(lr_osc_create(&d2, &o2, &e), LR_OK);
    assert_int_equal(lr_dev_get_state(lr_osc_dev(o2)), LR_DEV_RETRYING);
    assert_non_null(strstr(lr_dev_status(lr_osc_dev(o2)), "UDP port 15521"));
    lr_osc_destroy(o2);
    lr_osc_destroy(o1);
    /* A bad prefix is refused at create. */
    d2.prefix = "lamprig/";
    assert_int_equal(lr_osc_create(&d2, &o2, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "prefix"));
}

/* liblo's own command-line sender as the peer. */
static void osc_from_oscsend(void **state)
{
    (void)state;
    if (system("command -v oscsend >/dev/null 2>&1") != 0) {
        print_message("oscsend not installed (Debian liblo-tools): skipped\n");
        skip();
    }
    rec r = {0};
    lr_test_log log = {0};
    lr_osc *o = make(&r, &log, 15522);
    char dir[] = "/tmp/lamprig-osc.XXXXXX";
    assert_non_null(mkdtemp(dir));
    assert_int_equal(lr_test_run_cli(dir, "oscsend 127.0.0.1 15522 /lamprig/dimmer f 0.5"), 0);
    assert_int_equal(lr_test_run_cli(dir, "oscsend 127.0.0.1 15522 /lamprig/scene s marble"), 0);
    pump(o, 2);
    assert_int_equal(r.n, 2);
    assert_string_equal(r.ev[0].control, "dimmer");
    assert_float_equal(r.ev[0].value, 0.5, 0);
    assert_float_equal(r.ev[1].value, 1.5 / 3, 1e-15);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    assert_int_equal(system(cmd), 0);
    lr_osc_destroy(o);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(osc_messages),
        cmocka_unit_test(osc_from_oscsend),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
