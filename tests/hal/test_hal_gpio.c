/* hal/: quadrature decoding and button debouncing on recorded edge sequences, and the gpio back
 * end on a machine without GPIO chips. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "hal/debounce.h"
#include "hal/event.h"
#include "hal/gpio.h"
#include "hal/quad.h"
#include "tests/support/hal_test.h"

/* ---- quadrature: sampled states, ab = (A << 1) | B; clockwise is 00 10 11 01 00 ---- */

/* Feeds states, returns the sum of emitted steps and records each emitted step. */
static int feed(lr_quad *q, const unsigned *ab, int n, int *steps, int *nsteps)
{
    int sum = 0;
    *nsteps = 0;
    for (int i = 0; i < n; i++) {
        int s = lr_quad_feed(q, ab[i]);
        if (s)
            steps[(*nsteps)++] = s;
        sum += s;
    }
    return sum;
}

static void quad_clean_turns(void **state)
{
    (void)state;
    lr_quad q;
    int steps[32], ns;
    /* Three detents clockwise from rest 00, then two counter-clockwise. */
    const unsigned cw[] = {2, 3, 1, 0, 2, 3, 1, 0, 2, 3, 1, 0};
    const unsigned ccw[] = {1, 3, 2, 0, 1, 3, 2, 0};
    lr_quad_init(&q, 4, 0, false);
    assert_int_equal(feed(&q, cw, 12, steps, &ns), 3);
    assert_int_equal(ns, 3);
    /* Each step completes on the transition back into the rest state, not before. */
    lr_quad_init(&q, 4, 0, false);
    assert_int_equal(lr_quad_feed(&q, 2), 0);
    assert_int_equal(lr_quad_feed(&q, 3), 0);
    assert_int_equal(lr_quad_feed(&q, 1), 0);
    assert_int_equal(lr_quad_feed(&q, 0), 1);
    assert_int_equal(feed(&q, ccw, 8, steps, &ns), -2);
    assert_int_equal(ns, 2);
    assert_int_equal(steps[0], -1);
    assert_int_equal(q.invalid, 0);
    assert_int_equal(q.transitions, 4 + 8);
}

static void quad_bounce(void **state)
{
    (void)state;
    lr_quad q;
    int steps[32], ns;
    /* Contact A chatters at the start of a detent (00 <-> 10 five times), B chatters at the
     * end (01 <-> 00): one detent, never two, no invalid transition. */
    const unsigned rec[] = {2, 0, 2, 0, 2, 3, 1, 0, 1, 0, 1, 0};
    lr_quad_init(&q, 4, 0, false);
    assert_int_equal(feed(&q, rec, 12, steps, &ns), 1);
    assert_int_equal(ns, 1);
    assert_int_equal(q.invalid, 0);
    /* Chatter exactly at the step boundary (01 <-> 00 after the step fired) must not fire a
     * second step in either direction. */
    const unsigned edge[] = {1, 0, 1, 0, 1, 0};
    assert_int_equal(feed(&q, edge, 6, steps, &ns), 0);
    assert_int_equal(ns, 0);
}

static void quad_reversal(void **state)
{
    (void)state;
    lr_quad q;
    int steps[32], ns;
    /* Half a detent clockwise, back to rest: nothing. Then a full detent counter-clockwise. */
    const unsigned rec[] = {2, 3, 2, 0, 1, 3, 2, 0};
    lr_quad_init(&q, 4, 0, false);
    assert_int_equal(feed(&q, rec, 8, steps, &ns), -1);
    assert_int_equal(ns, 1);
    /* Detent clockwise then straight back: +1 then -1, in that order. */
    const unsigned rec2[] = {2, 3, 1, 0, 1, 3, 2, 0};
    assert_int_equal(feed(&q, rec2, 8, steps, &ns), 0);
    assert_int_equal(ns, 2);
    assert_int_equal(steps[0], 1);
    assert_int_equal(steps[1], -1);
    /* Reversal three quarters into a detent. */
    const unsigned rec3[] = {2, 3, 1, 3, 2, 0};
    assert_int_equal(feed(&q, rec3, 6, steps, &ns), 0);
    assert_int_equal(q.invalid, 0);
}

static void quad_missed_edges(void **state)
{
    (void)state;
    lr_quad q;
    int steps[32], ns;
    /* A transition was missed: 10 -> 01 changes both contacts. Counted, not acted on; the
     * half-detent it leaves is dropped at the next rest, and the following detent is clean. */
    const unsigned rec[] = {2, 1, 0, 2, 3, 1, 0};
    lr_quad_init(&q, 4, 0, false);
    int sum = feed(&q, rec, 7, steps, &ns);
    assert_int_equal(q.invalid, 1);
    assert_int_equal(sum, 1);
    assert_int_equal(ns, 1);
    /* Invalid jump straight onto the rest state (11 -> 00). */
    const unsigned rec2[] = {2, 3, 0, 2, 3, 1, 0};
    sum = feed(&q, rec2, 7, steps, &ns);
    assert_int_equal(q.invalid, 2);
    assert_int_equal(sum, 1);
}

static void quad_edge_events(void **state)
{
    (void)state;
    lr_quad q;
    /* GPIO edge events: (line, level). A rises, B rises, A falls, B falls = one detent CW. */
    lr_quad_init(&q, 4, 0, false);
    assert_int_equal(lr_quad_edge(&q, 0, 1), 0);
    assert_int_equal(lr_quad_edge(&q, 1, 1), 0);
    assert_int_equal(lr_quad_edge(&q, 0, 0), 0);
    assert_int_equal(lr_quad_edge(&q, 1, 0), 1);
    /* A reported rising twice: its falling edge was lost. */
    assert_int_equal(lr_quad_edge(&q, 0, 1), 0);
    assert_int_equal(lr_quad_edge(&q, 0, 1), 0);
    assert_int_equal(q.invalid, 1);
    assert_int_equal(q.ab, 2);
}

static void quad_steps_and_reverse(void **state)
{
    (void)state;
    lr_quad q;
    int steps[32], ns;
    const unsigned cw[] = {2, 3, 1, 0, 2, 3, 1, 0};
    lr_quad_init(&q, 2, 0, false); /* half-cycle encoder: a detent at 00 and at 11 */
    assert_int_equal(feed(&q, cw, 8, steps, &ns), 4);
    lr_quad_init(&q, 1, 0, false);
    assert_int_equal(feed(&q, cw, 8, steps, &ns), 8);
    lr_quad_init(&q, 4, 0, true);
    assert_int_equal(feed(&q, cw, 8, steps, &ns), -2);
    /* Starting at rest 11 (encoders that idle with both contacts open and pull-ups). */
    const unsigned from11[] = {1, 0, 2, 3};
    lr_quad_init(&q, 0 /* default 4 */, 3, false);
    assert_int_equal(q.steps, 4);
    assert_int_equal(feed(&q, from11, 4, steps, &ns), 1);
}

/* ---- debounce: recorded edges (logical level, microseconds) ---- */

typedef struct edge {
    int level;
    int64_t t_us;
} edge;

typedef struct change {
    int dir;
    int64_t t;
} change;

/* Feeds edges, ticking whenever the debouncer's deadline passes before the next edge (as the
 * main loop would), and finally at end_us. */
static int play(lr_debounce *d, const edge *ev, int n, int64_t end_us, change *out)
{
    int nc = 0;
    int64_t t;
    for (int i = 0; i <= n; i++) {
        int64_t next = i < n ? ev[i].t_us * 1000 : end_us * 1000;
        int64_t dl = lr_debounce_deadline(d);
        if (dl <= next) {
            int c = lr_debounce_tick(d, dl, &t);
            if (c)
                out[nc++] = (change){c, t};
        }
        if (i < n) {
            int c = lr_debounce_edge(d, ev[i].level, ev[i].t_us * 1000, &t);
            if (c)
                out[nc++] = (change){c, t};
        }
    }
    return nc;
}

static void debounce_clean(void **state)
{
    (void)state;
    lr_debounce d;
    change c[16];
    const edge rec[] = {{1, 1000}, {0, 200000}};
    lr_debounce_init(&d, 5000000, 0);
    int n = play(&d, rec, 2, 400000, c);
    assert_int_equal(n, 2);
    assert_int_equal(c[0].dir, 1);
    assert_int_equal(c[0].t, 1000000);
    assert_int_equal(c[1].dir, -1);
    assert_int_equal(c[1].t, 200000000);
}

static void debounce_bouncy_contact(void **state)
{
    (void)state;
    lr_debounce d;
    change c[16];
    /* A press that bounces for 1.5 ms, a release that bounces for 2 ms. */
    const edge rec[] = {{1, 0},      {0, 300},    {1, 600},    {0, 1100},   {1, 1500},
                        {0, 150000}, {1, 150400}, {0, 150900}, {1, 151300}, {0, 152000}};
    lr_debounce_init(&d, 5000000, 0);
    int n = play(&d, rec, 10, 300000, c);
    assert_int_equal(n, 2);
    assert_int_equal(c[0].dir, 1);
    assert_int_equal(c[0].t, 0);      /* reported at the first edge: no added latency */
    assert_int_equal(c[1].dir, -1);
    assert_int_equal(c[1].t, 150000000);
    assert_int_equal(d.ignored, 8);
    assert_int_equal(d.stable, 0);
}

static void debounce_short_tap_and_lost_edges(void **state)
{
    (void)state;
    lr_debounce d;
    change c[16];
    /* A 2 ms tap inside the 5 ms window: the press is reported at once and the release when the
     * window closes, stamped with the release edge's time. */
    const edge tap[] = {{1, 10000}, {0, 12000}};
    lr_debounce_init(&d, 5000000, 0);
    int n = play(&d, tap, 2, 100000, c);
    assert_int_equal(n, 2);
    assert_int_equal(c[1].dir, -1);
    assert_int_equal(c[1].t, 12000000);
    /* Bounce that ends in the pressed state during the window: one press only. */
    const edge settle[] = {{1, 200000}, {0, 201000}, {1, 202000}};
    n = play(&d, settle, 3, 300000, c);
    assert_int_equal(n, 1);
    assert_int_equal(c[0].dir, 1);
    /* An edge repeating the current level (its opposite was lost) changes nothing. */
    const edge dup[] = {{1, 400000}};
    n = play(&d, dup, 1, 500000, c);
    assert_int_equal(n, 0);
    assert_int_equal(d.stable, 1);
}

/* ---- the gpio back end, on a machine without /dev/gpiochip* ---- */

static const lr_gpio_encoder ENC[] = {{.name = "knob1", .line_a = "GPIO17", .line_b = "GPIO27"}};
static const lr_gpio_button BTN[] = {{.name = "button1", .line = "22"}};

static void gpio_missing_chip(void **state)
{
    (void)state;
    lr_test_log log = {0};
    lr_event_ring *ring;
    assert_int_equal(lr_event_ring_create(0, &ring, NULL), LR_OK);
    lr_gpio_desc desc = {
        .dev = {.sink = lr_event_ring_sink(ring), .log = {lr_test_log_fn, &log},
                .retry_min_ms = 10, .retry_max_ms = 40},
        .chip = "gpiochip0",
        .encoders = ENC, .n_encoders = 1,
        .buttons = BTN, .n_buttons = 1,
    };
    lr_err e = {0};

    /* Required: create fails and says which chip. */
    desc.dev.required = true;
    lr_gpio *g = NULL;
    assert_int_equal(lr_gpio_create(&desc, &g, &e), LR_ENODEV);
    assert_null(g);
    assert_non_null(strstr(e.msg, "gpio: gpiochip0: cannot open chip"));

    /* Optional (the default): the rig keeps running; one log line, then silent retries with
     * exponential backoff. */
    desc.dev.required = false;
    assert_int_equal(lr_gpio_create(&desc, &g, &e), LR_OK);
    lr_dev *d = lr_gpio_dev(g);
    assert_int_equal(lr_dev_get_state(d), LR_DEV_MISSING);
    assert_string_equal(lr_dev_kind(d), "gpio");
    assert_non_null(strstr(lr_dev_status(d), "gpio: gpiochip0: cannot open chip: "));
    assert_non_null(strstr(lr_dev_status(d), "retrying with backoff"));
    assert_int_equal(log.n, 1);
    struct pollfd fds[4];
    assert_int_equal(lr_dev_pollfds(d, fds, 4), 0);

    int64_t t = lr_dev_next_deadline(d);
    int64_t prev_gap = 0;
    for (int i = 0; i < 5; i++) {
        int64_t before = t;
        assert_int_equal(lr_dev_dispatch(d, before), 0);
        t = lr_dev_next_deadline(d);
        int64_t gap = t - before;
        /* 10 ms, 20, 40, then capped at 40. */
        assert_true(gap >= prev_gap);
        assert_true(gap <= 40000000);
        prev_gap = gap;
    }
    assert_int_equal(prev_gap, 40000000);
    assert_int_equal(lr_dev_failures(d), 6);
    assert_int_equal(log.n, 1); /* once per state change, not per retry */

    /* A hint that the device may be back makes the next dispatch retry at once. */
    int64_t now = lr_now_ns();
    lr_dev_retry_now(d, now);
    assert_true(lr_dev_next_deadline(d) <= now);
    assert_int_equal(lr_event_ring_count(ring), 0);
    lr_gpio_destroy(g);
    lr_event_ring_destroy(ring);
}

static void gpio_bad_config(void **state)
{
    (void)state;
    lr_event_ring *ring;
    assert_int_equal(lr_event_ring_create(0, &ring, NULL), LR_OK);
    lr_gpio_encoder enc = {.name = "knob1", .line_a = "5", .line_b = "6", .steps_per_detent = 3};
    lr_gpio_button btn[2] = {{.name = "b1", .line = "7"}, {.name = "b2", .line = "6"}};
    lr_gpio_desc desc = {.dev = {.sink = lr_event_ring_sink(ring), .log = {lr_log_silent, NULL}},
                         .encoders = &enc, .n_encoders = 1};
    lr_err e = {0};
    lr_gpio *g = NULL;
    assert_int_equal(lr_gpio_create(&desc, &g, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "encoders[0].steps_per_detent 3"));
    enc.steps_per_detent = 4;
    desc.buttons = btn;
    desc.n_buttons = 2;
    assert_int_equal(lr_gpio_create(&desc, &g, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "line '6' used by both knob1.b and b2"));
    btn[1].line = "8";
    btn[1].name = "knob1";
    assert_int_equal(lr_gpio_create(&desc, &g, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "buttons[1]: control name 'knob1' used twice"));
    lr_gpio_desc nosink = {.encoders = &enc, .n_encoders = 1};
    assert_int_equal(lr_gpio_create(&nosink, &g, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "no event sink"));
    lr_event_ring_destroy(ring);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(quad_clean_turns),
        cmocka_unit_test(quad_bounce),
        cmocka_unit_test(quad_reversal),
        cmocka_unit_test(quad_missed_edges),
        cmocka_unit_test(quad_edge_events),
        cmocka_unit_test(quad_steps_and_reverse),
        cmocka_unit_test(debounce_clean),
        cmocka_unit_test(debounce_bouncy_contact),
        cmocka_unit_test(debounce_short_tap_and_lost_edges),
        cmocka_unit_test(gpio_missing_chip),
        cmocka_unit_test(gpio_bad_config),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
