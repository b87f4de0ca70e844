/* hal/: Modbus master against a real libmodbus server (modbus_reply over a modbus_mapping_t)
 * running in a thread: on 127.0.0.1 (free port) and over RTU on a pseudo-terminal pair. The
 * server is the dimmer panel (unit 1) and the lamp driver (unit 2) of configs/rig/modbus-demo.
 * Also the endpoint URL parser. No timed assertions: the loop runs until a condition holds,
 * with generous guards against hangs. */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <modbus.h>
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

#include "hal/modbus.h"
#include "tests/support/hal_test.h"
#include "tests/support/modbus_rogue.h"
#include "tests/support/modbus_server.h"

/* ---- URL parsing ---- */

static void url_good(void **state)
{
    (void)state;
    lr_modbus_url u;
    lr_err e = {0};
    char buf[300];
    assert_int_equal(lr_modbus_url_parse("tcp://192.168.1.20:1502", &u, &e), LR_OK);
    assert_int_equal(u.transport, LR_MODBUS_TCP);
    assert_string_equal(u.host, "192.168.1.20");
    assert_int_equal(u.port, 1502);
    assert_int_equal(lr_modbus_url_parse("tcp://panel.local", &u, &e), LR_OK);
    assert_string_equal(u.host, "panel.local");
    assert_int_equal(u.port, 502);
    assert_int_equal(lr_modbus_url_parse("tcp://[::1]:5020/", &u, &e), LR_OK);
    assert_string_equal(u.host, "::1");
    assert_int_equal(u.port, 5020);
    lr_modbus_url_format(&u, buf, sizeof buf);
    assert_string_equal(buf, "tcp://[::1]:5020");

    assert_int_equal(lr_modbus_url_parse("rtu:/dev/ttyUSB0", &u, &e), LR_OK);
    assert_int_equal(u.transport, LR_MODBUS_RTU);
    assert_string_equal(u.device, "/dev/ttyUSB0");
    assert_int_equal(u.baud, 19200);
    assert_int_equal(u.parity, 'E');
    assert_int_equal(u.data_bits, 8);
    assert_int_equal(u.stop_bits, 1);
    assert_false(u.rs485);
    assert_int_equal(
        lr_modbus_url_parse("rtu:///dev/ttyAMA0?baud=9600&parity=n&data=8&stop=2&rs485=1", &u, &e),
        LR_OK);
    assert_string_equal(u.device, "/dev/ttyAMA0");
    assert_int_equal(u.baud, 9600);
    assert_int_equal(u.parity, 'N');
    assert_int_equal(u.stop_bits, 2);
    assert_true(u.rs485);
    lr_modbus_url_format(&u, buf, sizeof buf);
    assert_string_equal(buf, "rtu:/dev/ttyAMA0?baud=9600&parity=N&data=8&stop=2&rs485=1");
}

static void url_bad(void **state)
{
    (void)state;
    static const struct {
        const char *url, *msg;
    } cases[] = {
        {"", "modbus URL is empty (tcp://HOST:PORT or rtu:DEVICE?...)"},
        {"udp://x:1", "modbus URL 'udp://x:1': unknown scheme (expected tcp://HOST:PORT or "
                      "rtu:DEVICE?baud=...&parity=N|E|O&data=8&stop=1)"},
        {"tcp://:502", "modbus URL 'tcp://:502': missing host (tcp://HOST:PORT)"},
        {"tcp://h:0", "modbus URL 'tcp://h:0': port '0' is not 1..65535"},
        {"tcp://h:70000", "modbus URL 'tcp://h:70000': port '70000' is not 1..65535"},
        {"tcp://h:50x", "modbus URL 'tcp://h:50x': port '50x' is not 1..65535"},
        {"tcp://h:502/unit/1", "modbus URL 'tcp://h:502/unit/1': unexpected '/unit/1' after "
                               "host:port"},
        {"tcp://[::1:502", "modbus URL 'tcp://[::1:502': missing ']' after IPv6 address"},
        {"rtu:", "modbus URL 'rtu:': missing device (rtu:DEVICE?baud=...)"},
        {"rtu:/dev/ttyS0?baud=12345", "modbus URL 'rtu:/dev/ttyS0?baud=12345': baud '12345' is "
                                      "not a standard rate (1200..921600)"},
        {"rtu:/dev/ttyS0?parity=X", "modbus URL 'rtu:/dev/ttyS0?parity=X': parity 'X' is not N, "
                                    "E or O"},
        {"rtu:/dev/ttyS0?data=9", "modbus URL 'rtu:/dev/ttyS0?data=9': data bits '9' is not 5..8"},
        {"rtu:/dev/ttyS0?stop=3", "modbus URL 'rtu:/dev/ttyS0?stop=3': stop bits '3' is not 1 "
                                  "or 2"},
        {"rtu:/dev/ttyS0?speed=9600", "modbus URL 'rtu:/dev/ttyS0?speed=9600': unknown option "
                                      "'speed' (baud, parity, data, stop, rs485)"},
        {"rtu:/dev/ttyS0?baud", "modbus URL 'rtu:/dev/ttyS0?baud': option 'baud' is not "
                                "key=value"},
        {"rtu:/dev/ttyS0?baud=9600&baud=19200", "modbus URL 'rtu:/dev/ttyS0?baud=9600&baud="
                                                "19200': option 'baud' given twice"},
        {"rtu:/dev/ttyS0?baud=9600&", "modbus URL 'rtu:/dev/ttyS0?baud=9600&': trailing '&'"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        lr_modbus_url u;
        lr_err e = {0};
        assert_int_equal(lr_modbus_url_parse(cases[i].url, &u, &e), LR_EPARSE);
        assert_string_equal(e.msg, cases[i].msg);
    }
}

/* The server (panel = unit 1, lamp driver = unit 2) is tests/support/modbus_server.c. */

/* ---- loop conditions ---- */

typedef struct cond {
    lr_modbus *m;
    lr_event_ring *ring;
    lr_test_mb_server *s;
    int n;        /* ring events wanted, or a counter threshold */
    int want;     /* driver register value */
} cond;

static bool has_events(void *u)
{
    cond *c = u;
    return (int)lr_event_ring_count(c->ring) >= c->n;
}

static bool driver_has(void *u)
{
    cond *c = u;
    return lr_modbus_output_synced(c->m) && lr_test_mb_server_reg(c->s, 2, 0) == c->want;
}

static bool link_down(void *u)
{
    return lr_dev_get_state(lr_modbus_dev(((cond *)u)->m)) != LR_DEV_OPEN;
}

static bool failures_reached(void *u)
{
    cond *c = u;
    return (int)lr_dev_failures(lr_modbus_dev(c->m)) >= c->n;
}

static bool exceptions_reached(void *u)
{
    cond *c = u;
    lr_modbus_counters k;
    lr_modbus_get_counters(c->m, &k);
    return (int)k.exceptions >= c->n && lr_event_ring_count(c->ring) >= 1;
}

static bool crc_errors_reached(void *u)
{
    cond *c = u;
    lr_modbus_counters k;
    lr_modbus_get_counters(c->m, &k);
    return (int)k.crc_errors >= c->n;
}

static bool run(lr_modbus *m, lr_test_pred p, cond *c)
{
    lr_dev *d = lr_modbus_dev(m);
    return lr_test_run(&d, 1, 20000, p, c);
}

static lr_event pop(lr_event_ring *ring)
{
    lr_event ev;
    memset(&ev, 0, sizeof ev);
    assert_true(lr_event_ring_pop(ring, &ev));
    return ev;
}

/* Drains the ring; returns the last event. */
static lr_event last(lr_event_ring *ring)
{
    lr_event ev = pop(ring);
    lr_event more;
    while (lr_event_ring_pop(ring, &more))
        ev = more;
    return ev;
}

static const lr_modbus_input PANEL = {.control = "dimmer", .unit = 1, .reg = 0, .raw_max = 1000};

/* ---- TCP ---- */

static void tcp_panel_driver_and_reconnect(void **state)
{
    (void)state;
    lr_test_mb_server *s = lr_test_mb_server_start();
    lr_test_mb_server_set_reg(s, 1, 0, 500);

    lr_event_ring *ring;
    assert_int_equal(lr_event_ring_create(0, &ring, NULL), LR_OK);
    lr_test_log log = {0};
    char url[64];
    snprintf(url, sizeof url, "tcp://127.0.0.1:%d", lr_test_mb_server_port(s));
    lr_modbus_desc desc = {
        .dev = {.sink = lr_event_ring_sink(ring), .log = {lr_test_log_fn, &log},
                .retry_min_ms = 20, .retry_max_ms = 200},
        .url = url,
        .inputs = &PANEL, .n_inputs = 1,
        .output = {.enabled = true, .unit = 2, .reg = 0, .raw_max = 255},
        .poll_ms = 10, .timeout_ms = 1000,
    };
    lr_modbus *m = NULL;
    lr_err e = {0};
    assert_int_equal(lr_modbus_create(&desc, &m, &e), LR_OK);
    lr_dev *d = lr_modbus_dev(m);
    assert_int_equal(lr_dev_get_state(d), LR_DEV_OPEN);
    struct pollfd pfd;
    assert_int_equal(lr_dev_pollfds(d, &pfd, 1), 1);

    /* The panel's position is reported once after connecting: 500 of 0..1000. */
    cond c = {.m = m, .ring = ring, .s = s, .n = 1};
    assert_true(run(m, has_events, &c));
    lr_event ev = pop(ring);
    assert_string_equal(ev.source, "modbus");
    assert_string_equal(ev.control, "dimmer");
    assert_int_equal(ev.kind, LR_EV_ABSOLUTE);
    assert_float_equal(ev.value, 0.5, 1e-12);

    /* A change on the panel becomes exactly one event with the new value. */
    lr_test_mb_server_set_reg(s, 1, 0, 250);
    assert_true(run(m, has_events, &c));
    ev = pop(ring);
    assert_float_equal(ev.value, 0.25, 1e-12);
    assert_int_equal(lr_event_ring_count(ring), 0);

    /* Level writes land in the driver's register, scaled to 0..255 and rounded. */
    assert_int_equal(lr_modbus_write_level(m, 0.5), LR_OK);
    assert_int_equal(lr_modbus_output_raw(m), 128);
    c.want = 128;
    assert_true(run(m, driver_has, &c));
    assert_int_equal(lr_modbus_write_level(m, 2.0), LR_OK); /* clamped */
    c.want = 255;
    assert_true(run(m, driver_has, &c));
    assert_int_equal(lr_modbus_write_level(m, NAN), LR_EINVAL);
    assert_int_equal(lr_modbus_write_level(m, 0.2), LR_OK);
    assert_int_equal(lr_modbus_flush(m, 10000, &e), LR_OK); /* the shutdown path */
    assert_int_equal(lr_test_mb_server_reg(s, 2, 0), 51);
    assert_int_equal(lr_test_mb_server_reg(s, 1, 0), 250); /* the panel was not written */

    lr_modbus_counters k;
    lr_modbus_get_counters(m, &k);
    assert_int_equal(k.connects, 1);
    assert_int_equal(k.writes, 3);
    assert_int_equal(k.exceptions + k.timeouts + k.crc_errors + k.bad_responses + k.io_errors, 0);

    /* The server dies: the link drops, one line is logged, reconnects back off silently. */
    lr_test_mb_server_stop(s);
    assert_true(run(m, link_down, &c));
    int lines_after_loss = lr_test_log_count(&log, "retrying with backoff");
    c.n = 4;
    assert_true(run(m, failures_reached, &c));
    assert_int_equal(lr_dev_get_state(d), LR_DEV_MISSING);
    assert_non_null(strstr(lr_dev_status(d), "cannot connect: Connection refused"));
    assert_int_equal(lr_test_log_count(&log, "retrying with backoff"), lines_after_loss + 1);
    assert_int_equal(lines_after_loss, 1);
    assert_int_equal(lr_dev_pollfds(d, &pfd, 1), 0);
    lr_modbus_get_counters(m, &k);
    assert_true(k.io_errors >= 1);

    /* It comes back (same port) with a moved dimmer and a driver that restarted at 0: the
     * master reconnects, reports the new position and resends the level. */
    lr_test_mb_server_set_reg(s, 1, 0, 900);
    lr_test_mb_server_set_reg(s, 2, 0, 0);
    lr_test_mb_server_restart(s);
    c.n = 1;
    lr_event_ring_pop(ring, &ev);
    assert_true(run(m, has_events, &c));
    ev = last(ring);
    assert_float_equal(ev.value, 0.9, 1e-12);
    c.want = 51;
    assert_true(run(m, driver_has, &c));
    lr_modbus_get_counters(m, &k);
    assert_int_equal(k.connects, 2);
    assert_int_equal(lr_test_log_count(&log, ": open (after 4 failed attempts)"), 1);
    /* The good answers reset the backoff (a connect alone does not: see the CLOSE peer). */
    assert_int_equal(lr_dev_failures(d), 0);

    lr_modbus_destroy(m);
    lr_test_mb_server_free(s);
    lr_event_ring_destroy(ring);
}

static void tcp_exceptions_are_counted_not_fatal(void **state)
{
    (void)state;
    lr_test_mb_server *s = lr_test_mb_server_start();
    lr_test_mb_server_set_reg(s, 1, 0, 1000);
    lr_event_ring *ring;
    assert_int_equal(lr_event_ring_create(0, &ring, NULL), LR_OK);
    lr_test_log log = {0};
    char url[64];
    snprintf(url, sizeof url, "tcp://127.0.0.1:%d", lr_test_mb_server_port(s));
    /* Register 50 does not exist on the panel (10 registers): illegal data address. */
    lr_modbus_input in[2] = {PANEL, {.control = "fader", .unit = 1, .reg = 50}};
    lr_modbus_desc desc = {
        .dev = {.name = "panel", .sink = lr_event_ring_sink(ring), .log = {lr_test_log_fn, &log}},
        .url = url, .inputs = in, .n_inputs = 2,
        .output = {.enabled = true, .unit = 2, .reg = 20},
        .poll_ms = 5, .timeout_ms = 1000,
    };
    lr_modbus *m = NULL;
    lr_err e = {0};
    assert_int_equal(lr_modbus_create(&desc, &m, &e), LR_OK);
    assert_int_equal(lr_modbus_write_level(m, 1.0), LR_OK);
    cond c = {.m = m, .ring = ring, .s = s, .n = 5};
    assert_true(run(m, exceptions_reached, &c));
    lr_event ev = last(ring);
    assert_string_equal(ev.source, "panel");
    assert_string_equal(ev.control, "dimmer");
    assert_float_equal(ev.value, 1.0, 0);
    assert_int_equal(lr_dev_get_state(lr_modbus_dev(m)), LR_DEV_OPEN);
    lr_modbus_counters k;
    lr_modbus_get_counters(m, &k);
    assert_int_equal(k.last_exception, 2);
    assert_int_equal(k.connects, 1);
    assert_true(k.responses >= 1);
    /* Logged once per channel, not once per poll. */
    assert_int_equal(lr_test_log_count(&log, "input 'fader' (unit 1, holding register 50): "
                                             "exception 2 (illegal data address)"),
                     1);
    assert_int_equal(lr_test_log_count(&log, "lamp driver (unit 2, holding register 20): "
                                             "exception 2 (illegal data address)"),
                     1);
    /* The rejected level is not resent every cycle, and flush says why it cannot land. */
    assert_false(lr_modbus_output_synced(m));
    assert_int_equal(lr_modbus_flush(m, 1000, &e), LR_EPROTO);
    assert_non_null(strstr(e.msg, "rejected the level (raw 255)"));
    lr_modbus_destroy(m);
    lr_test_mb_server_free(s);
    lr_event_ring_destroy(ring);
}

static void tcp_timeouts_drop_and_restore_the_link(void **state)
{
    (void)state;
    lr_test_mb_server *s = lr_test_mb_server_start();
    lr_test_mb_server_set_reg(s, 1, 0, 100);
    lr_test_mb_server_set_silent(s, true);
    lr_event_ring *ring;
    assert_int_equal(lr_event_ring_create(0, &ring, NULL), LR_OK);
    lr_test_log log = {0};
    char url[64];
    snprintf(url, sizeof url, "tcp://127.0.0.1:%d", lr_test_mb_server_port(s));
    lr_modbus_desc desc = {
        .dev = {.sink = lr_event_ring_sink(ring), .log = {lr_test_log_fn, &log},
                .retry_min_ms = 10, .retry_max_ms = 50},
        .url = url, .inputs = &PANEL, .n_inputs = 1,
        .poll_ms = 5, .timeout_ms = 30, .max_timeouts = 3,
    };
    lr_modbus *m = NULL;
    assert_int_equal(lr_modbus_create(&desc, &m, NULL), LR_OK);
    cond c = {.m = m, .ring = ring, .s = s, .n = 1};
    /* The server accepts the connection but never answers. */
    assert_true(run(m, link_down, &c));
    lr_dev *d = lr_modbus_dev(m);
    assert_int_equal(lr_dev_get_state(d), LR_DEV_RETRYING);
    assert_non_null(strstr(lr_dev_status(d), "no answer to 3 requests in a row"));
    lr_modbus_counters k;
    lr_modbus_get_counters(m, &k);
    assert_int_equal(k.timeouts, 3);
    assert_int_equal(lr_test_log_count(&log, "no answer within 30 ms"), 1);
    assert_int_equal(lr_event_ring_count(ring), 0);
    /* It answers again: reconnected, and the value arrives. */
    lr_test_mb_server_set_silent(s, false);
    assert_true(run(m, has_events, &c));
    assert_float_equal(pop(ring).value, 0.1, 1e-12);
    lr_modbus_get_counters(m, &k);
    assert_true(k.connects >= 2);
    lr_modbus_destroy(m);
    lr_test_mb_server_free(s);
    lr_event_ring_destroy(ring);
}

static void config_errors(void **state)
{
    (void)state;
    lr_event_ring *ring;
    assert_int_equal(lr_event_ring_create(0, &ring, NULL), LR_OK);
    lr_modbus_input in = {.unit = 1, .reg = 0, .base = 1};
    lr_modbus_desc desc = {.dev = {.sink = lr_event_ring_sink(ring)},
                           .url = "tcp://127.0.0.1:1", .inputs = &in, .n_inputs = 1};
    lr_modbus *m = NULL;
    lr_err e = {0};
    assert_int_equal(lr_modbus_create(&desc, &m, &e), LR_EINVAL);
    assert_string_equal(e.msg, "modbus: inputs[0].reg 0 is not 1..65536 (base 1)");
    in.base = 0;
    in.unit = 248;
    desc.url = "rtu:/dev/ttyUSB0";
    assert_int_equal(lr_modbus_create(&desc, &m, &e), LR_EINVAL);
    assert_string_equal(e.msg, "modbus: inputs[0].unit 248 is not 1..247");
    in.unit = 1;
    in.raw_min = 500;
    in.raw_max = 100;
    assert_int_equal(lr_modbus_create(&desc, &m, &e), LR_EINVAL);
    assert_string_equal(e.msg, "modbus: inputs[0]: raw range 500..100 is not within 0..65535 "
                               "and increasing");
    desc.url = "tcp:/oops";
    assert_int_equal(lr_modbus_create(&desc, &m, &e), LR_EPARSE);
    assert_non_null(strstr(e.msg, "modbus: modbus URL 'tcp:/oops': unknown scheme"));
    desc.url = "tcp://127.0.0.1:1";
    desc.n_inputs = 0;
    assert_int_equal(lr_modbus_create(&desc, &m, &e), LR_EINVAL);
    assert_string_equal(e.msg, "modbus: neither inputs nor an output configured");
    /* Nothing listens on port 1: required fails, optional retries. */
    desc.n_inputs = 1;
    in.raw_min = 0;
    in.raw_max = 0;
    desc.dev.required = true;
    assert_int_equal(lr_modbus_create(&desc, &m, &e), LR_ENODEV);
    assert_string_equal(e.msg, "modbus: tcp://127.0.0.1:1: cannot connect: Connection refused");
    lr_event_ring_destroy(ring);
}

/* ---- misbehaving TCP peers (tests/support/modbus_rogue.c) ---- */

#define MS_NS 1000000LL

static lr_modbus *rogue_master(lr_test_rogue *r, lr_event_ring *ring, lr_test_log *log,
                               const lr_modbus_input *in, int n_in, int poll_ms, char *url,
                               size_t url_cap)
{
    snprintf(url, url_cap, "tcp://127.0.0.1:%d", lr_test_rogue_port(r));
    lr_modbus_desc desc = {
        .dev = {.sink = lr_event_ring_sink(ring), .log = {lr_test_log_fn, log},
                .retry_min_ms = 10, .retry_max_ms = 10000},
        .url = url, .inputs = in, .n_inputs = n_in,
        .output = {.enabled = true, .unit = 2, .reg = 5, .raw_max = 255},
        .poll_ms = poll_ms, .timeout_ms = 100, .byte_timeout_ms = 50, .max_timeouts = 3,
    };
    lr_modbus *m = NULL;
    lr_err e = {0};
    assert_int_equal(lr_modbus_create(&desc, &m, &e), LR_OK);
    return m;
}

/* An FC 3 answer declaring 250 data bytes, one byte every 45 ms (each within byte_timeout_ms
 * 50): 11.7 s for the frame. No dispatch may wait for it: each returns in well under one
 * byte's gap, and the transaction ends at its deadline (timeout_ms 100 after the request) with
 * a timeout naming the peer and the channel. Three in a row drop the link. */
static void tcp_drip_peer_cannot_hold_the_loop(void **state)
{
    (void)state;
    lr_test_rogue *r = lr_test_rogue_start(LR_ROGUE_DRIP, 45);
    lr_event_ring *ring;
    assert_int_equal(lr_event_ring_create(0, &ring, NULL), LR_OK);
    lr_test_log log = {0};
    char url[64];
    lr_modbus *m = rogue_master(r, ring, &log, &PANEL, 1, 10, url, sizeof url);
    lr_dev *d = lr_modbus_dev(m);
    int64_t t0 = lr_now_ns(), worst = 0, first_timeout = -1;
    lr_modbus_counters k;
    while (lr_now_ns() - t0 < 600 * MS_NS) {
        struct pollfd p;
        int n = lr_dev_pollfds(d, &p, 1);
        int64_t now = lr_now_ns(), t = lr_dev_next_deadline(d);
        int wait_ms = t <= now ? 0 : t - now > 10 * MS_NS ? 10 : (int)((t - now) / MS_NS) + 1;
        poll(&p, (nfds_t)n, wait_ms);
        int64_t a = lr_now_ns();
        lr_dev_dispatch(d, a);
        int64_t b = lr_now_ns();
        worst = b - a > worst ? b - a : worst;
        lr_modbus_get_counters(m, &k);
        if (k.timeouts && first_timeout < 0)
            first_timeout = b - t0;
    }
    lr_modbus_get_counters(m, &k);
    /* 45 ms: one byte's gap; the old receive blocked for the whole 11.7 s frame. */
    assert_true(worst < 45 * MS_NS);
    /* The first request goes out at create (t0 is just after): its deadline is 100 ms on. */
    assert_true(first_timeout >= 0);
    assert_true(first_timeout <= (100 + 150) * MS_NS);
    /* 600 ms of 100 ms transactions: the link dropped after three and came back. */
    assert_true(k.timeouts >= 3);
    assert_true(k.connects >= 2);
    assert_int_equal(k.responses, 0);
    assert_int_equal(lr_event_ring_count(ring), 0);
    char want[160];
    snprintf(want, sizeof want, "%s: input 'dimmer' (unit 1, holding register 0): answer "
                                "incomplete after 100 ms", url);
    assert_true(lr_test_log_count(&log, want) >= 1);
    lr_modbus_destroy(m);
    lr_test_rogue_free(r);
    lr_event_ring_destroy(ring);
}

typedef struct late_cond {
    lr_modbus *m;
    lr_event_ring *ring;
    lr_test_rogue *r;
    int dimmer, fader; /* events seen */
    int wrong;         /* events with the other register's value */
} late_cond;

static bool late_done(void *u)
{
    late_cond *c = u;
    lr_event ev;
    while (lr_event_ring_pop(c->ring, &ev)) {
        bool dimmer = strcmp(ev.control, "dimmer") == 0;
        c->dimmer += dimmer;
        c->fader += !dimmer;
        if (fabs(ev.value - (dimmer ? 0.1 : 0.9)) > 1e-12)
            c->wrong++;
    }
    lr_modbus_counters k;
    lr_modbus_get_counters(c->m, &k);
    return c->wrong > 0 ||
           (k.stale >= 20 && lr_modbus_output_synced(c->m) && c->dimmer && c->fader);
}

/* A peer answering every request twice, the previous request's answer first (with its
 * transaction id). Register 0 (the dimmer) reads 100 of 1000, register 1 (a fader) 900: taken
 * for the current request, the late answer would make the dimmer 0.9 and the fader 0.1. The
 * master drops it by its transaction id, counts it, and takes the right one. */
static void tcp_late_answers_are_dropped(void **state)
{
    (void)state;
    lr_test_rogue *r = lr_test_rogue_start(LR_ROGUE_LATE, 0);
    lr_test_rogue_set_reg(r, 0, 100);
    lr_test_rogue_set_reg(r, 1, 900);
    lr_event_ring *ring;
    assert_int_equal(lr_event_ring_create(0, &ring, NULL), LR_OK);
    lr_test_log log = {0};
    char url[64];
    lr_modbus_input in[2] = {PANEL, {.control = "fader", .unit = 1, .reg = 1, .raw_max = 1000}};
    lr_modbus *m = rogue_master(r, ring, &log, in, 2, 2, url, sizeof url);
    /* 0.1 of 0..255 is 25.5: raw 26 (the late answer to a read would be 230 = 0.9 * 255). */
    assert_int_equal(lr_modbus_write_level(m, 0.1), LR_OK);
    late_cond c = {.m = m, .ring = ring, .r = r};
    lr_dev *d = lr_modbus_dev(m);
    assert_true(lr_test_run(&d, 1, 20000, late_done, &c));
    assert_int_equal(c.wrong, 0);
    assert_int_equal(lr_test_rogue_driver(r, 5), 26);
    lr_modbus_counters k;
    lr_modbus_get_counters(m, &k);
    assert_true(k.stale >= 20);
    /* Every answer but the first came after a late one: as many stale as answers, minus 1. */
    assert_true(k.stale + 1 >= k.responses);
    assert_int_equal(k.bad_responses + k.timeouts + k.io_errors, 0);
    assert_int_equal(k.connects, 1);
    /* Logged, but not once per stale answer. */
    assert_true(lr_test_log_count(&log, "stale answer dropped") >= 1);
    assert_true(lr_test_log_count(&log, "stale answer dropped") <= 4);
    lr_modbus_destroy(m);
    lr_test_rogue_free(r);
    lr_event_ring_destroy(ring);
}

static bool rogue_requests(void *u)
{
    cond *c = u;
    return lr_test_rogue_requests((lr_test_rogue *)c->s) >= c->n;
}

/* A peer cycling through a wrong unit, a wrong function and an exception, each with a
 * different number every time, and a good answer: 400 requests. Deduplication by text alone
 * logged a line per bad answer (and one per recovery); per kind and device the master now
 * logs at most 4 lines per 10 s: at most 6 kinds x 4 plus the open line. */
static void tcp_random_answers_do_not_flood_the_log(void **state)
{
    (void)state;
    lr_test_rogue *r = lr_test_rogue_start(LR_ROGUE_RANDOM, 0);
    lr_test_rogue_set_reg(r, 0, 250);
    lr_event_ring *ring;
    assert_int_equal(lr_event_ring_create(0, &ring, NULL), LR_OK);
    lr_test_log log = {0};
    char url[64];
    lr_modbus *m = rogue_master(r, ring, &log, &PANEL, 1, 1, url, sizeof url);
    cond c = {.m = m, .ring = ring, .s = (lr_test_mb_server *)r, .n = 400};
    assert_true(run(m, rogue_requests, &c));
    lr_modbus_counters k;
    lr_modbus_get_counters(m, &k);
    assert_true(k.bad_responses >= 150);
    assert_true(k.exceptions >= 75);
    assert_true(k.responses >= 75);
    assert_int_equal(k.connects, 1);
    assert_true(log.n <= 6 * 4 + 1);
    assert_true(lr_test_log_count(&log, "answer from unit") >= 1);
    assert_true(lr_test_log_count(&log, "answer from unit") <= 4);
    /* The good answers still arrive: 250 of 1000, reported once. */
    assert_int_equal(lr_event_ring_count(ring), 1);
    assert_float_equal(last(ring).value, 0.25, 1e-12);
    lr_modbus_destroy(m);
    lr_test_rogue_free(r);
    lr_event_ring_destroy(ring);
}

/* A peer that accepts the connection and closes it at once, for 1 s. The backoff restarts on
 * a good answer, not on a connect: retries come 10, 20, 40 ... ms apart, so after n losses
 * 10 (2^n - 1) ms have passed: at most 7 reconnects after the first connect within 1 s (the
 * old reset on connect reconnected every ~10 ms, about 90 times). */
static void tcp_accept_and_close_backs_off(void **state)
{
    (void)state;
    lr_test_rogue *r = lr_test_rogue_start(LR_ROGUE_CLOSE, 0);
    lr_event_ring *ring;
    assert_int_equal(lr_event_ring_create(0, &ring, NULL), LR_OK);
    lr_test_log log = {0};
    char url[64];
    lr_modbus *m = rogue_master(r, ring, &log, &PANEL, 1, 10, url, sizeof url);
    lr_dev *d = lr_modbus_dev(m);
    lr_test_run(&d, 1, 1000, NULL, NULL);
    lr_modbus_counters k;
    lr_modbus_get_counters(m, &k);
    assert_true(k.connects >= 3);
    assert_true(k.connects <= 8);
    assert_true(lr_test_rogue_accepted(r) <= 8);
    /* Every loss counts: the failures grow with the connects. */
    assert_true((int)lr_dev_failures(d) >= (int)k.connects - 1);
    assert_true(lr_test_log_count(&log, "connection closed by the server") >= 1);
    lr_modbus_destroy(m);
    lr_test_rogue_free(r);
    lr_event_ring_destroy(ring);
}

/* ---- RTU over a pseudo-terminal pair ---- */

static void rtu_over_pty(void **state)
{
    (void)state;
    lr_test_mb_server *s = lr_test_mb_server_start_rtu(NULL);
    lr_test_mb_server_set_reg(s, 1, 0, 300);
    lr_event_ring *ring;
    assert_int_equal(lr_event_ring_create(0, &ring, NULL), LR_OK);
    lr_test_log log = {0};
    char url[128];
    snprintf(url, sizeof url, "rtu:%s?baud=19200&parity=E&data=8&stop=1",
             lr_test_mb_server_device(s));
    /* Panel registers numbered from 1 in its manual: register 1 is address 0. */
    lr_modbus_input in[2] = {{.control = "dimmer", .unit = 1, .reg = 1, .base = 1},
                             {.control = "fader", .unit = 1, .reg = 51, .base = 1}};
    lr_modbus_desc desc = {
        .dev = {.sink = lr_event_ring_sink(ring), .log = {lr_test_log_fn, &log}},
        .url = url, .inputs = in, .n_inputs = 2,
        .output = {.enabled = true, .unit = 2, .reg = 0, .raw_max = 255, .multiple = true},
        .poll_ms = 10, .timeout_ms = 1000,
    };
    lr_modbus *m = NULL;
    lr_err e = {0};
    assert_int_equal(lr_modbus_create(&desc, &m, &e), LR_OK);
    assert_int_equal(lr_dev_get_state(lr_modbus_dev(m)), LR_DEV_OPEN);
    cond c = {.m = m, .ring = ring, .s = s, .n = 1};
    assert_true(run(m, has_events, &c));
    lr_event ev = pop(ring);
    assert_string_equal(ev.control, "dimmer");
    assert_float_equal(ev.value, 0.3, 1e-12);

    /* Write with FC 16; the level lands scaled. */
    assert_int_equal(lr_modbus_write_level(m, 1.0), LR_OK);
    c.want = 255;
    assert_true(run(m, driver_has, &c));

    /* Damaged CRCs are counted and the link carries on. */
    lr_test_mb_server_corrupt(s, 2);
    c.n = 2;
    assert_true(run(m, crc_errors_reached, &c));
    lr_test_mb_server_set_reg(s, 1, 0, 700);
    c.n = 1;
    assert_true(run(m, has_events, &c));
    assert_float_equal(last(ring).value, 0.7, 1e-12);
    lr_modbus_counters k;
    lr_modbus_get_counters(m, &k);
    assert_int_equal(k.crc_errors, 2);
    assert_true(k.exceptions >= 1); /* the fader at register 51 */
    assert_int_equal(k.last_exception, 2);
    assert_int_equal(k.connects, 1);
    assert_int_equal(lr_dev_get_state(lr_modbus_dev(m)), LR_DEV_OPEN);
    assert_true(lr_test_log_count(&log, "answer with a bad CRC") >= 1);
    lr_modbus_destroy(m);

    /* RS-485 mode needs the TIOCSRS485 ioctl, which a pty refuses: a clear error. */
    snprintf(url, sizeof url, "rtu:%s?rs485=1", lr_test_mb_server_device(s));
    desc.dev.required = true;
    assert_int_equal(lr_modbus_create(&desc, &m, &e), LR_EUNSUPPORTED);
    assert_non_null(strstr(e.msg, "rs485=1 but the port refuses RS-485 mode (TIOCSRS485)"));

    /* A missing serial port. */
    desc.url = "rtu:/dev/ttyLAMPRIG-none";
    assert_int_equal(lr_modbus_create(&desc, &m, &e), LR_ENODEV);
    assert_non_null(strstr(e.msg, "modbus: rtu:/dev/ttyLAMPRIG-none?baud=19200&parity=E&data=8&"
                                  "stop=1: cannot connect: No such file or directory"));
    lr_test_mb_server_free(s);
    lr_event_ring_destroy(ring);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(url_good),
        cmocka_unit_test(url_bad),
        cmocka_unit_test(tcp_panel_driver_and_reconnect),
        cmocka_unit_test(tcp_exceptions_are_counted_not_fatal),
        cmocka_unit_test(tcp_timeouts_drop_and_restore_the_link),
        cmocka_unit_test(config_errors),
        cmocka_unit_test(tcp_drip_peer_cannot_hold_the_loop),
        cmocka_unit_test(tcp_late_answers_are_dropped),
        cmocka_unit_test(tcp_random_answers_do_not_flood_the_log),
        cmocka_unit_test(tcp_accept_and_close_backs_off),
        cmocka_unit_test(rtu_over_pty),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
