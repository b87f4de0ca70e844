/* hal/: the sACN and Art-Net receivers over UDP on 127.0.0.1 (ports 15500-15519), packets
 * built byte by byte (tests/support/dmx_build.c). Merge times are the dispatch times the test
 * passes, so loss and fades are checked at exact instants. Covered: channel -> event (8-bit
 * and 16-bit), no event for an unchanged look, priority and HTP across two CIDs, sequence
 * drops, Stream_Terminated, preview, loss with hold and with a fade, bad packets counted per
 * kind with one log line each, a flood read max_packets per dispatch, Art-Net HTP of two
 * senders, ArtPoll -> ArtPollReply naming the port-addresses. */
#include <math.h>
#include <poll.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmocka.h>

#include "hal/artnet.h"
#include "hal/artnet_packet.h"
#include "hal/sacn.h"
#include "hal/sacn_packet.h"
#include "tests/support/dmx_build.h"
#include "tests/support/hal_test.h"

#define MS 1000000LL
#define S (1000 * MS)
#define T0 (1000 * S) /* an arbitrary start of the test's clock */

typedef struct rec {
    int n;
    lr_event ev[1024];
} rec;

static void rec_fn(void *user, const lr_event *ev)
{
    rec *r = user;
    if (r->n < 1024)
        r->ev[r->n++] = *ev;
}

/* The last event of control, or NULL. */
static const lr_event *last_of(const rec *r, const char *control)
{
    for (int i = r->n - 1; i >= 0; i--)
        if (strcmp(r->ev[i].control, control) == 0)
            return &r->ev[i];
    return NULL;
}

static uint64_t packets(lr_dev *d)
{
    lr_dmx_counters c;
    if (strcmp(lr_dev_kind(d), "sacn") == 0)
        lr_sacn_get_counters((const lr_sacn *)d, &c);
    else
        lr_artnet_get_counters((const lr_artnet *)d, &c);
    return c.packets;
}

/* Dispatches at the test's time t until the device has read `want` datagrams in all (loopback
 * delivery is immediate, but poll first rather than assume it). */
static void pump(lr_dev *d, int64_t t, uint64_t want)
{
    for (int guard = 0; packets(d) < want && guard < 200; guard++) {
        struct pollfd p;
        int n = lr_dev_pollfds(d, &p, 1);
        assert_int_equal(n, 1);
        poll(&p, 1, 50);
        lr_dev_dispatch(d, t);
    }
    assert_int_equal(packets(d), want);
}

static const lr_dmx_channel CH[] = {
    {.control = "dimmer", .universe = 1, .channel = 1, .home = NAN},
    {.control = "fine", .universe = 1, .channel = 3, .fine = 4, .home = 0.25},
    {.control = "u7", .universe = 7, .channel = 512, .home = NAN},
};

static lr_sacn *sacn_make(rec *r, lr_test_log *log, int port, lr_dmx_loss loss, bool unicast)
{
    lr_sacn_desc d = {.dev = {.sink = {rec_fn, r}, .log = {lr_test_log_fn, log}},
                      .bind = "127.0.0.1", .port = port, .unicast_only = unicast,
                      .channels = CH, .n_channels = 3, .loss = loss, .fade_ms = 1000,
                      .max_sources = 2};
    lr_sacn *s = NULL;
    lr_err e = {0};
    int rc = lr_sacn_create(&d, &s, &e);
    if (rc)
        fail_msg("%s", e.msg);
    assert_int_equal(lr_dev_get_state(lr_sacn_dev(s)), LR_DEV_OPEN);
    return s;
}

static void sacn_channels_and_merge(void **state)
{
    (void)state;
    rec r = {0};
    lr_test_log log = {0};
    lr_sacn *s = sacn_make(&r, &log, 15500, LR_DMX_HOLD, true);
    lr_dev *d = lr_sacn_dev(s);
    assert_int_equal(lr_sacn_port(s), 15500);
    int tx = lr_test_udp_socket(0);
    assert_true(tx >= 0);
    uint8_t b[700], sl[512] = {0};
    uint64_t sent = 0;

    /* Channel 1 at full, the 16-bit pair 3/4 at 0x8000. */
    sl[0] = 255, sl[2] = 0x80, sl[3] = 0x00;
    size_t n = lr_test_sacn_build(b, 1, 100, 0, 0, 0, sl, 8, 1);
    assert_int_equal(lr_test_udp_send(tx, 15500, b, n), (long)n);
    pump(d, T0, ++sent);
    assert_int_equal(r.n, 2);
    assert_string_equal(r.ev[0].source, "sacn");
    assert_int_equal(r.ev[0].kind, LR_EV_ABSOLUTE);
    assert_float_equal(last_of(&r, "dimmer")->value, 1.0, 0);
    /* (0x80 * 256 + 0) / 65535 = 32768 / 65535: exact in double, compared to 1e-12. */
    assert_float_equal(last_of(&r, "fine")->value, 32768.0 / 65535.0, 1e-12);
    assert_int_equal(last_of(&r, "dimmer")->t_ns, T0);

    /* The same look again: no events. A later sequence with channel 1 at 51: one. */
    n = lr_test_sacn_build(b, 1, 100, 1, 0, 0, sl, 8, 1);
    lr_test_udp_send(tx, 15500, b, n);
    pump(d, T0 + 10 * MS, ++sent);
    assert_int_equal(r.n, 2);
    sl[0] = 51;
    n = lr_test_sacn_build(b, 1, 100, 2, 0, 0, sl, 8, 1);
    lr_test_udp_send(tx, 15500, b, n);
    pump(d, T0 + 20 * MS, ++sent);
    assert_int_equal(r.n, 3);
    assert_float_equal(last_of(&r, "dimmer")->value, 51 / 255.0, 1e-12);

    /* A late packet (sequence 1 after 2) is dropped: channel 1 stays at 51. */
    sl[0] = 9;
    n = lr_test_sacn_build(b, 1, 100, 1, 0, 0, sl, 8, 1);
    lr_test_udp_send(tx, 15500, b, n);
    pump(d, T0 + 30 * MS, ++sent);
    assert_int_equal(r.n, 3);
    lr_dmx_counters c;
    lr_sacn_get_counters(s, &c);
    assert_int_equal(c.sequence, 1);

    /* A second CID at the same priority: HTP. At a higher priority: it wins outright. */
    sl[0] = 200;
    n = lr_test_sacn_build(b, 1, 100, 0, 0, 0, sl, 1, 2);
    lr_test_udp_send(tx, 15500, b, n);
    pump(d, T0 + 40 * MS, ++sent);
    assert_float_equal(last_of(&r, "dimmer")->value, 200 / 255.0, 1e-12);
    sl[0] = 10;
    n = lr_test_sacn_build(b, 1, 150, 1, 0, 0, sl, 1, 2);
    lr_test_udp_send(tx, 15500, b, n);
    pump(d, T0 + 50 * MS, ++sent);
    assert_float_equal(last_of(&r, "dimmer")->value, 10 / 255.0, 1e-12);
    /* A third CID exceeds max_sources 2: refused and counted. */
    sl[0] = 255;
    n = lr_test_sacn_build(b, 1, 200, 0, 0, 0, sl, 1, 3);
    lr_test_udp_send(tx, 15500, b, n);
    pump(d, T0 + 60 * MS, ++sent);
    lr_sacn_get_counters(s, &c);
    assert_int_equal(c.full, 1);
    assert_float_equal(last_of(&r, "dimmer")->value, 10 / 255.0, 1e-12);
    /* Stream_Terminated from CID 2 drops it at once: CID 1's 51 is back. */
    n = lr_test_sacn_build(b, 1, 150, 2, LR_SACN_BIT_TERMINATED, 0, sl, 1, 2);
    lr_test_udp_send(tx, 15500, b, n);
    pump(d, T0 + 70 * MS, ++sent);
    assert_float_equal(last_of(&r, "dimmer")->value, 51 / 255.0, 1e-12);
    /* Preview data is not live output. */
    sl[0] = 0;
    n = lr_test_sacn_build(b, 1, 100, 3, LR_SACN_BIT_PREVIEW, 0, sl, 8, 1);
    lr_test_udp_send(tx, 15500, b, n);
    pump(d, T0 + 80 * MS, ++sent);
    assert_float_equal(last_of(&r, "dimmer")->value, 51 / 255.0, 1e-12);
    /* A universe of 4 slots cannot carry channel 512 of universe 7 ... */
    n = lr_test_sacn_build(b, 7, 100, 0, 0, 0, sl, 4, 1);
    lr_test_udp_send(tx, 15500, b, n);
    pump(d, T0 + 90 * MS, ++sent);
    assert_null(last_of(&r, "u7"));
    /* ... a full one does; an unconfigured universe is only counted. */
    sl[511] = 255;
    n = lr_test_sacn_build(b, 7, 100, 1, 0, 0, sl, 512, 1);
    lr_test_udp_send(tx, 15500, b, n);
    n = lr_test_sacn_build(b, 9, 100, 0, 0, 0, sl, 512, 1);
    lr_test_udp_send(tx, 15500, b, n);
    sent += 2;
    pump(d, T0 + 100 * MS, sent);
    assert_float_equal(last_of(&r, "u7")->value, 1.0, 0);
    lr_sacn_get_counters(s, &c);
    assert_int_equal(c.preview, 1);
    assert_int_equal(c.terminated, 1);
    assert_int_equal(c.other, 1);
    assert_int_equal(c.bad, 0);
    close(tx);
    lr_sacn_destroy(s);
}

/* Loss with hold: nothing moves; with fade: channels with a home move there over fade_ms. */
static void sacn_loss(void **state)
{
    (void)state;
    for (int fade = 0; fade < 2; fade++) {
        rec r = {0};
        lr_test_log log = {0};
        int port = 15501 + fade;
        lr_sacn *s = sacn_make(&r, &log, port, fade ? LR_DMX_FADE : LR_DMX_HOLD, true);
        lr_dev *d = lr_sacn_dev(s);
        int tx = lr_test_udp_socket(0);
        uint8_t b[700], sl[8] = {255, 0, 0xff, 0xff};
        size_t n = lr_test_sacn_build(b, 1, 100, 0, 0, 0, sl, 8, 1);
        lr_test_udp_send(tx, port, b, n);
        pump(d, T0, 1);
        /* The source is lost 2.5 s (loss_ms default) after its packet, not before. */
        assert_int_equal(lr_dev_next_deadline(d), T0 + 2500 * MS);
        lr_dev_dispatch(d, T0 + 2499 * MS);
        int before = r.n;
        lr_dev_dispatch(d, T0 + 2500 * MS);
        lr_dmx_counters c;
        lr_sacn_get_counters(s, &c);
        assert_int_equal(c.losses, 1);
        assert_int_equal(lr_test_log_count(&log, "no source left"), 1);
        if (!fade) {
            assert_int_equal(r.n, before);
            assert_int_equal(lr_dev_next_deadline(d), LR_NO_DEADLINE);
        } else {
            /* "fine" (home 0.25) fades from 1 to 0.25 over 1 s; "dimmer" (home NaN) holds.
             * Halfway: 1 + (0.25 - 1) * 0.5 = 0.625. */
            lr_dev_dispatch(d, T0 + 3000 * MS);
            assert_float_equal(last_of(&r, "fine")->value, 0.625, 1e-9);
            lr_dev_dispatch(d, T0 + 3500 * MS);
            assert_float_equal(last_of(&r, "fine")->value, 0.25, 0);
            assert_float_equal(last_of(&r, "dimmer")->value, 1.0, 0);
            assert_int_equal(lr_dev_next_deadline(d), LR_NO_DEADLINE);
        }
        /* A source back after a pause (OLA on a static look) is taken again, any sequence. */
        sl[0] = 0;
        n = lr_test_sacn_build(b, 1, 100, 0, 0, 0, sl, 8, 1);
        lr_test_udp_send(tx, port, b, n);
        pump(d, T0 + 9 * S, 2);
        assert_float_equal(last_of(&r, "dimmer")->value, 0.0, 0);
        assert_int_equal(lr_test_log_count(&log, "receiving again"), 1);
        close(tx);
        lr_sacn_destroy(s);
    }
}

/* A console that pauses often (OLA on static looks) is lost and back at every pause: the
 * loss and recovery lines are limited to 4 per minute, the losses all counted. */
static void sacn_loss_lines_limited(void **state)
{
    (void)state;
    rec r = {0};
    lr_test_log log = {0};
    lr_sacn *s = sacn_make(&r, &log, 15505, LR_DMX_HOLD, true);
    lr_dev *d = lr_sacn_dev(s);
    int tx = lr_test_udp_socket(0);
    uint8_t b[700], sl[1];
    /* Five pauses of 3 s (> the 2.5 s loss) in 15 s: 5 losses and 4 recoveries. */
    for (int k = 0; k < 5; k++) {
        sl[0] = (uint8_t)(10 * k);
        size_t n = lr_test_sacn_build(b, 1, 100, k, 0, 0, sl, 1, 1);
        lr_test_udp_send(tx, 15505, b, n);
        pump(d, T0 + k * 3 * S, (uint64_t)k + 1);
        lr_dev_dispatch(d, T0 + k * 3 * S + 2500 * MS);
    }
    lr_dmx_counters c;
    lr_sacn_get_counters(s, &c);
    assert_int_equal(c.losses, 5);
    int lines = lr_test_log_count(&log, "no source left") +
                lr_test_log_count(&log, "receiving again");
    assert_int_equal(lines, 4);
    /* A minute after the first line (at 2.5 s), the next one says how many were dropped: 9
     * lines were due, 4 let through. */
    size_t n = lr_test_sacn_build(b, 1, 100, 9, 0, 0, sl, 1, 1);
    lr_test_udp_send(tx, 15505, b, n);
    pump(d, T0 + 63 * S, 6);
    assert_int_equal(lr_test_log_count(&log, "receiving again (5 similar lines dropped)"), 1);
    close(tx);
    lr_sacn_destroy(s);
}

static void sacn_bad_packets_and_flood(void **state)
{
    (void)state;
    rec r = {0};
    lr_test_log log = {0};
    lr_sacn *s = sacn_make(&r, &log, 15503, LR_DMX_HOLD, true);
    lr_dev *d = lr_sacn_dev(s);
    int tx = lr_test_udp_socket(0);
    uint8_t b[2000], sl[512] = {0};
    uint64_t sent = 0;
    /* Three of each: short, wrong ACN id, bad priority, oversized (1500 bytes). */
    for (int k = 0; k < 3; k++) {
        size_t n = lr_test_sacn_build(b, 1, 100, 0, 0, 0, sl, 8, 1);
        lr_test_udp_send(tx, 15503, b, 60);
        b[8] = 'X';
        lr_test_udp_send(tx, 15503, b, n);
        b[8] = 'E';
        b[108] = 250;
        lr_test_udp_send(tx, 15503, b, n);
        memset(b + n, 0, 1500 - n);
        lr_test_udp_send(tx, 15503, b, 1500);
        sent += 4;
    }
    pump(d, T0, sent);
    lr_dmx_counters c;
    lr_sacn_get_counters(s, &c);
    assert_int_equal(c.bad, 12);
    assert_int_equal(c.bad_kind[LR_SACN_SHORT], 3);
    assert_int_equal(c.bad_kind[LR_SACN_ACN_ID], 3);
    assert_int_equal(c.bad_kind[LR_SACN_PRIORITY], 3);
    assert_int_equal(c.bad_kind[LR_SACN_LONG], 3);
    /* One line per kind, naming it and the sender. */
    assert_int_equal(lr_test_log_count(&log, "malformed packet"), 4);
    assert_int_equal(lr_test_log_count(&log, "(acn-id) from 127.0.0.1:"), 1);
    assert_int_equal(r.n, 0);

    /* A flood of 100 valid packets (small ones: 100 fit the default socket buffer): one
     * dispatch reads max_packets (64) of them and asks to be dispatched again at once
     * (deadline 0) so the loop's other devices get their turn. */
    for (int k = 0; k < 100; k++) {
        sl[0] = (uint8_t)k;
        size_t n = lr_test_sacn_build(b, 1, 100, k, 0, 0, sl, 1, 1);
        assert_int_equal(lr_test_udp_send(tx, 15503, b, n), (long)n);
    }
    struct pollfd p;
    lr_dev_pollfds(d, &p, 1);
    assert_int_equal(poll(&p, 1, 1000), 1);
    lr_dev_dispatch(d, T0 + S);
    assert_int_equal(packets(d), sent + 64);
    assert_int_equal(lr_dev_next_deadline(d), 0);
    pump(d, T0 + S, sent + 100);
    assert_float_equal(last_of(&r, "dimmer")->value, 99 / 255.0, 1e-12);
    close(tx);
    lr_sacn_destroy(s);
}

/* Joining the multicast groups works or, without a multicast route, is one warning. */
static void sacn_multicast_join(void **state)
{
    (void)state;
    rec r = {0};
    lr_test_log log = {0};
    lr_sacn_desc dd = {.dev = {.sink = {rec_fn, &r}, .log = {lr_test_log_fn, &log}},
                       .port = 15504, .channels = CH, .n_channels = 3};
    lr_sacn *s = NULL;
    lr_err e = {0};
    assert_int_equal(lr_sacn_create(&dd, &s, &e), LR_OK);
    assert_int_equal(lr_dev_get_state(lr_sacn_dev(s)), LR_DEV_OPEN);
    assert_true(lr_test_log_count(&log, "multicast groups") <= 1);
    /* Unicast to the any-address socket still arrives. */
    int tx = lr_test_udp_socket(0);
    uint8_t b[700], sl[1] = {128};
    size_t n = lr_test_sacn_build(b, 1, 100, 0, 0, 0, sl, 1, 1);
    lr_test_udp_send(tx, 15504, b, n);
    pump(lr_sacn_dev(s), T0, 1);
    assert_float_equal(last_of(&r, "dimmer")->value, 128 / 255.0, 1e-12);
    close(tx);
    lr_sacn_destroy(s);
    /* Bad descriptors name the field. */
    lr_dmx_channel bad = {.control = "x", .universe = 64000, .channel = 1};
    dd.channels = &bad;
    dd.n_channels = 1;
    assert_int_equal(lr_sacn_create(&dd, &s, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "universe 64000"));
    bad = (lr_dmx_channel){.control = "x", .universe = 1, .channel = 513};
    assert_int_equal(lr_sacn_create(&dd, &s, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "channel 513"));
}

static void artnet_merge_and_poll(void **state)
{
    (void)state;
    rec r = {0};
    lr_test_log log = {0};
    const lr_dmx_channel ch[] = {
        {.control = "dimmer", .universe = 0, .channel = 1, .home = NAN},
        {.control = "far", .universe = 0x0123, .channel = 2, .home = NAN},
        {.control = "next", .universe = 0x0124, .channel = 1, .home = NAN},
    };
    lr_artnet_desc dd = {.dev = {.sink = {rec_fn, &r}, .log = {lr_test_log_fn, &log}},
                         .bind = "127.0.0.1", .port = 15510, .announce = "",
                         .channels = ch, .n_channels = 3};
    lr_artnet *a = NULL;
    lr_err e = {0};
    if (lr_artnet_create(&dd, &a, &e))
        fail_msg("%s", e.msg);
    lr_dev *d = lr_artnet_dev(a);
    int tx1 = lr_test_udp_socket(0), tx2 = lr_test_udp_socket(0), tx3 = lr_test_udp_socket(0);
    uint8_t b[600], sl[512] = {0};
    uint64_t sent = 0;
    sl[0] = 100;
    size_t n = lr_test_artdmx_build(b, 0, sl, 2);
    lr_test_udp_send(tx1, 15510, b, n);
    pump(d, T0, ++sent);
    assert_float_equal(last_of(&r, "dimmer")->value, 100 / 255.0, 1e-12);
    /* HTP of two senders: 60 from the second does not lower it, 220 raises it. */
    sl[0] = 60;
    n = lr_test_artdmx_build(b, 0, sl, 2);
    lr_test_udp_send(tx2, 15510, b, n);
    pump(d, T0 + S, ++sent);
    assert_float_equal(last_of(&r, "dimmer")->value, 100 / 255.0, 1e-12);
    sl[0] = 220;
    n = lr_test_artdmx_build(b, 0, sl, 2);
    lr_test_udp_send(tx3, 15510, b, n); /* a third sender: refused */
    pump(d, T0 + S, ++sent);
    assert_float_equal(last_of(&r, "dimmer")->value, 100 / 255.0, 1e-12);
    lr_test_udp_send(tx2, 15510, b, n);
    pump(d, T0 + 2 * S, ++sent);
    assert_float_equal(last_of(&r, "dimmer")->value, 220 / 255.0, 1e-12);
    /* Net 1 / Sub-Net 2 / Universe 3, channel 2. */
    sl[1] = 255;
    n = lr_test_artdmx_build(b, 0x0123, sl, 2);
    lr_test_udp_send(tx1, 15510, b, n);
    pump(d, T0 + 2 * S, ++sent);
    assert_float_equal(last_of(&r, "far")->value, 1.0, 0);
    /* Malformed: odd length, old ProtVer; counted and logged once per kind. */
    n = lr_test_artdmx_build(b, 0, sl, 3);
    lr_test_udp_send(tx1, 15510, b, n);
    lr_test_udp_send(tx1, 15510, b, n);
    n = lr_test_artdmx_build(b, 0, sl, 2);
    b[11] = 13;
    lr_test_udp_send(tx1, 15510, b, n);
    sent += 3;
    pump(d, T0 + 2 * S, sent);
    lr_dmx_counters c;
    lr_artnet_get_counters(a, &c);
    assert_int_equal(c.full, 1);
    assert_int_equal(c.bad_kind[LR_ARTNET_LENGTH], 2);
    assert_int_equal(c.bad_kind[LR_ARTNET_PROT_VERSION], 1);
    assert_int_equal(lr_test_log_count(&log, "malformed packet"), 2);

    /* ArtPoll -> ArtPollReply back to the poller, one per Net/Sub-Net group: port-address 0
     * (net 0, sub-net 0) and 0x0123 + 0x0124 (net 1, sub-net 2, universes 3 and 4). */
    n = lr_test_artpoll_build(b);
    lr_test_udp_send(tx3, 15510, b, n);
    pump(d, T0 + 3 * S, ++sent);
    int got = 0;
    bool saw0 = false, saw12 = false;
    for (;;) {
        struct pollfd p = {.fd = tx3, .events = POLLIN};
        if (poll(&p, 1, got < 2 ? 1000 : 50) != 1)
            break;
        uint8_t rep[600];
        ssize_t rn = recv(tx3, rep, sizeof rep, 0);
        assert_int_equal(rn, LR_ARTNET_POLL_REPLY_LEN);
        got++;
        assert_int_equal(rep[8] | rep[9] << 8, LR_ARTNET_OP_POLL_REPLY);
        assert_memory_equal(rep + 10, "\x7f\x00\x00\x01", 4); /* bound to 127.0.0.1 */
        if (rep[18] == 0 && rep[19] == 0) {
            saw0 = rep[173] == 1 && rep[190] == 0 && rep[182] == 0x80;
        } else if (rep[18] == 1 && rep[19] == 2) {
            saw12 = rep[173] == 2 && rep[190] == 3 && rep[191] == 4 && rep[183] == 0x00;
        }
    }
    assert_int_equal(got, 2);
    assert_true(saw0);
    assert_true(saw12);
    lr_artnet_get_counters(a, &c);
    assert_int_equal(c.polls, 1);
    assert_int_equal(c.replies, 2);
    /* A flood of ArtPolls from the same poller within a second: left unanswered (the reply
     * limit, hal/reply_limit.h), counted; another poller is still answered; the first one
     * again a second later. */
    n = lr_test_artpoll_build(b);
    for (int k = 0; k < 50; k++)
        lr_test_udp_send(tx3, 15510, b, n);
    sent += 50;
    pump(d, T0 + 3 * S + S / 2, sent);
    lr_test_udp_send(tx2, 15510, b, n);
    pump(d, T0 + 3 * S + S / 2, ++sent);
    lr_artnet_get_counters(a, &c);
    assert_int_equal(c.polls_limited, 50);
    assert_int_equal(c.polls, 2);
    assert_int_equal(c.replies, 4);
    lr_test_udp_send(tx3, 15510, b, n);
    pump(d, T0 + 4 * S + S / 10, ++sent);
    lr_artnet_get_counters(a, &c);
    assert_int_equal(c.polls, 3);
    assert_int_equal(c.polls_limited, 50);
    for (int k = 0; k < 2; k++) { /* drain tx2's and tx3's replies */
        int fd = k ? tx3 : tx2;
        struct pollfd p = {.fd = fd, .events = POLLIN};
        while (poll(&p, 1, 50) == 1) {
            uint8_t rep[600];
            if (recv(fd, rep, sizeof rep, 0) <= 0)
                break;
        }
    }
    /* The 10 s merge timeout: both senders of port-address 0 gone at 12 s, hold. */
    lr_dev_dispatch(d, T0 + 12 * S);
    lr_artnet_get_counters(a, &c);
    assert_true(c.losses >= 1);
    assert_float_equal(last_of(&r, "dimmer")->value, 220 / 255.0, 1e-12);
    close(tx1);
    close(tx2);
    close(tx3);
    lr_artnet_destroy(a);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(sacn_channels_and_merge),
        cmocka_unit_test(sacn_loss),
        cmocka_unit_test(sacn_loss_lines_limited),
        cmocka_unit_test(sacn_bad_packets_and_flood),
        cmocka_unit_test(sacn_multicast_join),
        cmocka_unit_test(artnet_merge_and_poll),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
