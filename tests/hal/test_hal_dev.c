/* hal/: the pieces every back end shares — backoff schedule, event ring, event kinds, log
 * hook, device state through the public interface. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "hal/backoff.h"
#include "hal/dev.h"
#include "hal/event.h"
#include "hal/log.h"
#include "hal/sim.h"
#include "tests/support/hal_test.h"

#define MS 1000000LL

static void backoff_schedule(void **state)
{
    (void)state;
    lr_backoff b;
    lr_backoff_init(&b, 100, 1000);
    const int64_t want[] = {100, 200, 400, 800, 1000, 1000};
    for (int i = 0; i < 6; i++)
        assert_int_equal(lr_backoff_fail(&b, 5000 * MS), (5000 + want[i]) * MS);
    assert_int_equal(b.failures, 6);
    lr_backoff_reset(&b);
    assert_int_equal(lr_backoff_fail(&b, 0), 100 * MS);
    /* Defaults, and a cap below the minimum. */
    lr_backoff_init(&b, 0, 0);
    assert_int_equal(b.min_ns, 250 * MS);
    assert_int_equal(b.max_ns, 10000 * MS);
    lr_backoff_init(&b, 500, 100);
    assert_int_equal(lr_backoff_fail(&b, 0), 500 * MS);
    assert_int_equal(lr_backoff_fail(&b, 0), 500 * MS);
}

static void ring_fifo_and_overflow(void **state)
{
    (void)state;
    lr_event_ring *r;
    assert_int_equal(lr_event_ring_create(3, &r, NULL), LR_OK);
    lr_event_sink sink = lr_event_ring_sink(r);
    for (int i = 0; i < 5; i++) {
        lr_event ev;
        lr_event_set(&ev, "src", "knob", LR_EV_DELTA, i, i * 10);
        sink.fn(sink.user, &ev);
    }
    /* Capacity 3: the two oldest were dropped and counted. */
    assert_int_equal(lr_event_ring_count(r), 3);
    assert_int_equal(lr_event_ring_dropped(r), 2);
    lr_event ev;
    for (int i = 2; i < 5; i++) {
        assert_true(lr_event_ring_pop(r, &ev));
        assert_float_equal(ev.value, i, 0);
        assert_int_equal(ev.t_ns, i * 10);
    }
    assert_false(lr_event_ring_pop(r, &ev));
    lr_event_ring_destroy(r);
}

static void event_names(void **state)
{
    (void)state;
    lr_event_kind k;
    assert_int_equal(lr_event_kind_parse("absolute", &k), LR_OK);
    assert_int_equal(k, LR_EV_ABSOLUTE);
    assert_int_equal(lr_event_kind_parse("Absolute", &k), LR_EPARSE);
    assert_string_equal(lr_event_kind_name(LR_EV_RELEASE), "release");
    /* Names longer than the field are cut, never overflow. */
    lr_event ev;
    lr_event_set(&ev, "a-source-name-that-is-much-longer-than-31", "c", LR_EV_PRESS, 1, 0);
    assert_int_equal(strlen(ev.source), LR_EVENT_NAME_MAX - 1);
    assert_string_equal(lr_dev_state_name(LR_DEV_RETRYING), "retrying");
    assert_string_equal(lr_log_level_name(LR_LOG_WARN), "warn");
}

static void log_hook(void **state)
{
    (void)state;
    lr_test_log cap = {0};
    lr_log log = {lr_test_log_fn, &cap};
    lr_log_write(&log, LR_LOG_INFO, "gpio: %s: %d lines", "gpiochip0", 3);
    assert_int_equal(cap.n, 1);
    assert_string_equal(cap.lines[0], "gpio: gpiochip0: 3 lines");
    lr_log silent = {lr_log_silent, NULL};
    lr_log_write(&silent, LR_LOG_ERROR, "dropped");
}

/* At most burst lines per window; the first line of a new window reports the dropped ones. */
static void log_rate_limit(void **state)
{
    (void)state;
    lr_log_limit l;
    unsigned dropped = 99;
    lr_log_limit_init(&l, 2, 1000 * MS);
    assert_true(lr_log_limit_take(&l, 5000 * MS, &dropped));
    assert_int_equal(dropped, 0);
    assert_true(lr_log_limit_take(&l, 5001 * MS, &dropped));
    for (int i = 0; i < 5; i++)
        assert_false(lr_log_limit_take(&l, (5002 + 100 * i) * MS, &dropped));
    assert_false(lr_log_limit_take(&l, 5999 * MS, &dropped));
    assert_true(lr_log_limit_take(&l, 6000 * MS, &dropped));
    assert_int_equal(dropped, 6);
    assert_true(lr_log_limit_take(&l, 6001 * MS, &dropped));
    assert_int_equal(dropped, 0);
    /* No window: no limit. */
    lr_log_limit_init(&l, 1, 0);
    for (int i = 0; i < 10; i++)
        assert_true(lr_log_limit_take(&l, 0, NULL));
}

static void device_interface(void **state)
{
    (void)state;
    /* Through the public interface only, with the simplest back end. */
    lr_event_ring *r;
    assert_int_equal(lr_event_ring_create(0, &r, NULL), LR_OK);
    lr_test_log cap = {0};
    lr_sim_desc d = {.dev = {.name = "demo", .sink = lr_event_ring_sink(r),
                             .log = {lr_test_log_fn, &cap}},
                     .text = "0.1 k delta 1\n", .start_ns = 1000 * MS};
    lr_sim *s;
    assert_int_equal(lr_sim_create(&d, &s, NULL), LR_OK);
    lr_dev *dev = lr_sim_dev(s);
    assert_string_equal(lr_dev_name(dev), "demo");
    assert_string_equal(lr_dev_kind(dev), "sim");
    assert_string_equal(lr_dev_status(dev), "sim demo: script (1 events): open");
    assert_string_equal(cap.lines[0], "sim demo: script (1 events): open");
    unsigned gen = lr_dev_fd_generation(dev);
    assert_true(gen >= 1); /* opened once */
    /* Retry hints do nothing to an open device. */
    lr_dev_retry_now(dev, 0);
    assert_int_equal(lr_dev_next_deadline(dev), 1100 * MS);
    assert_int_equal(lr_dev_dispatch(dev, 1099 * MS), 0);
    assert_int_equal(lr_dev_get_state(dev), LR_DEV_OPEN);
    /* The last event played: done at once, nothing more to wait for. */
    assert_int_equal(lr_dev_dispatch(dev, 1100 * MS), 1);
    assert_int_equal(lr_dev_get_state(dev), LR_DEV_DONE);
    assert_int_equal(lr_dev_next_deadline(dev), LR_NO_DEADLINE);
    assert_int_equal(lr_dev_dispatch(dev, 1200 * MS), 0);
    assert_int_equal(lr_dev_fd_generation(dev), gen);
    assert_int_equal(lr_dev_failures(dev), 0);
    lr_dev_destroy(dev); /* destroys the sim behind it */
    lr_dev_destroy(NULL);
    lr_event_ring_destroy(r);

    /* A name longer than an event field is refused, naming the limit. */
    lr_err e = {0};
    d.dev.name = "a-device-name-that-is-far-too-long-for-events";
    assert_int_equal(lr_sim_create(&d, &s, &e), LR_EINVAL);
    assert_string_equal(e.msg, "sim: name 'a-device-name-that-is-far-too-long-for-events' is "
                               "longer than 31 characters");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(backoff_schedule),
        cmocka_unit_test(log_rate_limit),
        cmocka_unit_test(ring_fifo_and_overflow),
        cmocka_unit_test(event_names),
        cmocka_unit_test(log_hook),
        cmocka_unit_test(device_interface),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
