/* hal/: the usb back end (libusb hotplug / re-enumeration) on a machine with no USB devices. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "hal/usb.h"
#include "tests/support/hal_test.h"

static const lr_usb_watch WATCH[] = {
    {.name = "powermate", .vid = 0x077d, .pid = 0x0410, .read_reports = true},
    {.name = "shuttle", .vid = 0x0b33, .pid = 0x0020},
};

static void count_sink(void *user, const lr_event *ev)
{
    (void)ev;
    (*(int *)user)++;
}

/* libusb itself may be unusable in a sandbox (no netlink, no usbfs): then the device is
 * MISSING with a message naming libusb; otherwise it is OPEN and each watch says it is not
 * present. Either way the message is asserted. */
static void check_missing(lr_usb *u, lr_test_log *log, bool hotplug)
{
    lr_dev *d = lr_usb_dev(u);
    if (lr_dev_get_state(d) != LR_DEV_OPEN) {
        assert_int_equal(lr_dev_get_state(d), LR_DEV_MISSING);
        assert_non_null(strstr(lr_dev_status(d), "usb: cannot initialise libusb: "));
        return;
    }
    if (!hotplug)
        assert_false(lr_usb_uses_hotplug(u)); /* no_hotplug forces re-enumeration */
    assert_false(lr_usb_present(u, 0));
    assert_false(lr_usb_present(u, 1));
    assert_false(lr_usb_reading(u, 0));
    assert_non_null(strstr(lr_usb_watch_status(u, 0),
                           "usb: powermate (077d:0410): not present; waiting for it to be "
                           "plugged in"));
    assert_non_null(strstr(lr_usb_watch_status(u, 1), "usb: shuttle (0b33:0020): not present"));
    assert_int_equal(lr_test_log_count(log, "powermate (077d:0410): not present"), 1);
    /* libusb's own descriptors are exposed to the loop. */
    struct pollfd fds[16];
    int n = lr_dev_pollfds(d, fds, 16);
    assert_true(n >= 1);
    for (int i = 0; i < n; i++)
        assert_true(fds[i].fd >= 0);
}

static void usb_nothing_plugged_in(void **state)
{
    (void)state;
    int events = 0;
    lr_test_log log = {0};
    lr_usb_desc desc = {
        .dev = {.sink = {count_sink, &events}, .log = {lr_test_log_fn, &log}},
        .watch = WATCH, .n_watch = 2, .rescan_ms = 5, .no_hotplug = true,
    };
    lr_err e = {0};
    lr_usb *u = NULL;

    /* Re-enumeration: the deadline is the next rescan; several rescans log nothing new. */
    assert_int_equal(lr_usb_create(&desc, &u, &e), LR_OK);
    check_missing(u, &log, false);
    lr_dev *d = lr_usb_dev(u);
    if (lr_dev_get_state(d) == LR_DEV_OPEN) {
        int64_t t = lr_dev_next_deadline(d);
        assert_true(t != LR_NO_DEADLINE);
        assert_true(t <= lr_now_ns() + 5000000);
        for (int i = 0; i < 5; i++)
            assert_int_equal(lr_dev_dispatch(d, lr_dev_next_deadline(d)), 0);
        assert_int_equal(lr_test_log_count(&log, "not present"), 2);
    }
    assert_int_equal(events, 0);
    lr_usb_destroy(u);

    /* Hotplug (when libusb has it): no rescan deadline; same messages. */
    log.n = 0;
    desc.no_hotplug = false;
    assert_int_equal(lr_usb_create(&desc, &u, &e), LR_OK);
    check_missing(u, &log, true);
    if (lr_dev_get_state(lr_usb_dev(u)) == LR_DEV_OPEN && lr_usb_uses_hotplug(u))
        assert_int_equal(lr_dev_next_deadline(lr_usb_dev(u)), LR_NO_DEADLINE);
    assert_int_equal(lr_dev_dispatch(lr_usb_dev(u), lr_now_ns()), 0);
    lr_usb_destroy(u);
}

static void usb_required_device_absent(void **state)
{
    (void)state;
    int events = 0;
    lr_usb_desc desc = {
        .dev = {.sink = {count_sink, &events}, .log = {lr_log_silent, NULL}, .required = true},
        .watch = WATCH, .n_watch = 1, .no_hotplug = true,
    };
    lr_err e = {0};
    lr_usb *u = NULL;
    int rc = lr_usb_create(&desc, &u, &e);
    assert_int_equal(rc, LR_ENODEV);
    assert_null(u);
    assert_true(strstr(e.msg, "usb: powermate (077d:0410): not present") ||
                strstr(e.msg, "usb: cannot initialise libusb"));
}

static void usb_bad_config(void **state)
{
    (void)state;
    int events = 0;
    lr_usb_watch w[2] = {{.name = "knob", .vid = 0x077d, .pid = 0x0410},
                         {.name = "knob", .vid = 0x0b33, .pid = 0x0020}};
    lr_usb_desc desc = {.dev = {.sink = {count_sink, &events}, .log = {lr_log_silent, NULL}},
                        .watch = w, .n_watch = 2};
    lr_err e = {0};
    lr_usb *u = NULL;
    assert_int_equal(lr_usb_create(&desc, &u, &e), LR_EINVAL);
    assert_string_equal(e.msg, "usb: watch[1].name 'knob' used twice");
    w[1].name = "other";
    w[1].pid = 0;
    assert_int_equal(lr_usb_create(&desc, &u, &e), LR_EINVAL);
    assert_string_equal(e.msg, "usb: watch[1] (other): vid and pid are required");
    desc.n_watch = 0;
    assert_int_equal(lr_usb_create(&desc, &u, &e), LR_EINVAL);
    assert_string_equal(e.msg, "usb: n_watch 0 is not 1..16");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(usb_nothing_plugged_in),
        cmocka_unit_test(usb_required_device_absent),
        cmocka_unit_test(usb_bad_config),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
