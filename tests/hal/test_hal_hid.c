/* hal/: HID report parsers on byte fixtures (PowerMate, ShuttleXpress/PRO, consumer-control
 * knobs), and the hid back end on a machine without USB devices. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "hal/hid.h"
#include "hal/hid_report.h"
#include "tests/support/hal_test.h"

typedef struct parsed {
    int rc, n;
    lr_event ev[LR_HID_MAX_EVENTS];
    lr_err e;
} parsed;

static parsed P(lr_hid_parser *p, const uint8_t *b, size_t len)
{
    parsed r;
    memset(&r, 0, sizeof r);
    r.rc = lr_hid_parse(p, b, len, r.ev, &r.n, &r.e);
    return r;
}

/* A report written as bytes: PARSE(&parser, 0x00, 0x01, ...). */
#define PARSE(p, ...) \
    P(p, (const uint8_t[]){__VA_ARGS__}, sizeof((const uint8_t[]){__VA_ARGS__}))

static void check_ev(const lr_event *ev, const char *control, lr_event_kind kind, double value)
{
    assert_string_equal(ev->control, control);
    assert_int_equal(ev->kind, kind);
    assert_float_equal(ev->value, value, 1e-12);
}

static void powermate_reports(void **state)
{
    (void)state;
    lr_hid_parser p;
    lr_hid_parser_desc d = {.proto = LR_HID_POWERMATE};
    assert_int_equal(lr_hid_parser_init(&p, &d, NULL), LR_OK);

    parsed r = PARSE(&p, 0x00, 0x01, 0x00, 0x00, 0x00, 0x00); /* one tick clockwise */
    assert_int_equal(r.rc, LR_OK);
    assert_int_equal(r.n, 1);
    check_ev(&r.ev[0], "knob", LR_EV_DELTA, 1);

    r = PARSE(&p, 0x00, 0xfd, 0x00, 0x00, 0x00, 0x00); /* 3 ticks counter-clockwise */
    assert_int_equal(r.n, 1);
    check_ev(&r.ev[0], "knob", LR_EV_DELTA, -3);

    r = PARSE(&p, 0x01, 0x00, 0x80); /* pressed, 3-byte payload (older hardware) */
    assert_int_equal(r.n, 1);
    check_ev(&r.ev[0], "button", LR_EV_PRESS, 1);

    r = PARSE(&p, 0x01, 0x02, 0x80, 0x00, 0x00, 0x00); /* turned while held: no second press */
    assert_int_equal(r.n, 1);
    check_ev(&r.ev[0], "knob", LR_EV_DELTA, 2);

    r = PARSE(&p, 0x00, 0x00); /* short: garbage, state kept */
    assert_int_equal(r.rc, LR_EPROTO);
    assert_int_equal(r.n, 0);
    assert_string_equal(r.e.msg, "powermate: short report (2 bytes, need 3)");
    assert_int_equal(p.short_reports, 1);
    assert_int_equal(p.buttons, 1);

    r = P(&p, NULL, 0);
    assert_int_equal(r.rc, LR_EPROTO);
    assert_string_equal(r.e.msg, "powermate: short report (0 bytes, need 3)");

    /* Oversized (padded to 8): parsed by its first bytes, counted. */
    r = PARSE(&p, 0x00, 0x7f, 0x00, 0x00, 0x00, 0x00, 0xaa, 0xbb);
    assert_int_equal(r.rc, LR_OK);
    assert_int_equal(r.n, 2);
    check_ev(&r.ev[0], "knob", LR_EV_DELTA, 127);
    check_ev(&r.ev[1], "button", LR_EV_RELEASE, 0);
    assert_int_equal(p.oversized_reports, 1);
    assert_int_equal(p.reports, 7);
}

static void shuttlexpress_reports(void **state)
{
    (void)state;
    lr_hid_parser p;
    lr_hid_parser_desc d = {.proto = LR_HID_SHUTTLEXPRESS};
    assert_int_equal(lr_hid_parser_init(&p, &d, NULL), LR_OK);

    /* First report: the jog counter's value is arbitrary, no motion is reported. */
    parsed r = PARSE(&p, 0x00, 0xfe, 0x00, 0x00, 0x00);
    assert_int_equal(r.rc, LR_OK);
    assert_int_equal(r.n, 0);

    /* Jog clockwise across the wrap: 0xfe -> 0xff -> 0x00 -> 0x01, +1 each. */
    r = PARSE(&p, 0x00, 0xff, 0x00, 0x00, 0x00);
    assert_int_equal(r.n, 1);
    check_ev(&r.ev[0], "jog", LR_EV_DELTA, 1);
    r = PARSE(&p, 0x00, 0x00, 0x00, 0x00, 0x00);
    assert_int_equal(r.n, 1);
    check_ev(&r.ev[0], "jog", LR_EV_DELTA, 1);
    r = PARSE(&p, 0x00, 0x01, 0x00, 0x00, 0x00);
    check_ev(&r.ev[0], "jog", LR_EV_DELTA, 1);
    /* Back across the wrap in one report (two clicks): 0x01 -> 0xff is -2. */
    r = PARSE(&p, 0x00, 0xff, 0x00, 0x00, 0x00);
    assert_int_equal(r.n, 1);
    check_ev(&r.ev[0], "jog", LR_EV_DELTA, -2);

    /* Shuttle ring positions -7..7 -> -1..1. */
    r = PARSE(&p, 0x05, 0xff, 0x00, 0x00, 0x00);
    assert_int_equal(r.n, 1);
    check_ev(&r.ev[0], "shuttle", LR_EV_ABSOLUTE, 5.0 / 7.0);
    r = PARSE(&p, 0xf9, 0xff, 0x00, 0x00, 0x00);
    check_ev(&r.ev[0], "shuttle", LR_EV_ABSOLUTE, -1.0);
    r = PARSE(&p, 0x00, 0xff, 0x00, 0x00, 0x00);
    check_ev(&r.ev[0], "shuttle", LR_EV_ABSOLUTE, 0.0);

    /* Buttons: ShuttleXpress button 1 is bit 4 of the little-endian word, button 5 bit 8. */
    r = PARSE(&p, 0x00, 0xff, 0x00, 0x10, 0x00);
    assert_int_equal(r.n, 1);
    check_ev(&r.ev[0], "button1", LR_EV_PRESS, 1);
    r = PARSE(&p, 0x00, 0xff, 0x00, 0x00, 0x01);
    assert_int_equal(r.n, 2);
    check_ev(&r.ev[0], "button1", LR_EV_RELEASE, 0);
    check_ev(&r.ev[1], "button5", LR_EV_PRESS, 1);

    /* Garbage: ring beyond 7, and a 4-byte report; neither changes the state. */
    r = PARSE(&p, 0x08, 0x00, 0x00, 0x00, 0x00);
    assert_int_equal(r.rc, LR_EPROTO);
    assert_string_equal(r.e.msg, "shuttlexpress: shuttle position 8 out of range -7..7");
    r = PARSE(&p, 0x00, 0x00, 0x00, 0x00);
    assert_int_equal(r.rc, LR_EPROTO);
    assert_string_equal(r.e.msg, "shuttlexpress: short report (4 bytes, need 5)");
    assert_int_equal(p.bad_values, 1);
    assert_int_equal(p.short_reports, 1);
    assert_int_equal(p.jog, 0xff);

    /* Oversized report (padded to 8): parsed, counted; jog 0xff -> 0x02 is +3. */
    r = PARSE(&p, 0x00, 0x02, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00);
    assert_int_equal(r.rc, LR_OK);
    assert_int_equal(r.n, 1);
    check_ev(&r.ev[0], "jog", LR_EV_DELTA, 3);
    assert_int_equal(p.oversized_reports, 1);
}

static void shuttlepro_buttons(void **state)
{
    (void)state;
    lr_hid_parser p;
    lr_hid_parser_desc d = {.proto = LR_HID_SHUTTLEPRO};
    assert_int_equal(lr_hid_parser_init(&p, &d, NULL), LR_OK);
    parsed r = PARSE(&p, 0x00, 0x00, 0x00, 0x01, 0x40); /* bits 0 and 14 */
    assert_int_equal(r.n, 2);
    check_ev(&r.ev[0], "button1", LR_EV_PRESS, 1);
    check_ev(&r.ev[1], "button15", LR_EV_PRESS, 1);
}

static void consumer_array_reports(void **state)
{
    (void)state;
    lr_hid_parser p;
    lr_hid_parser_desc d = {.proto = LR_HID_CONSUMER, .report_id = 1};
    assert_int_equal(lr_hid_parser_init(&p, &d, NULL), LR_OK);

    /* A detent clockwise: Volume Increment down, then up. */
    parsed r = PARSE(&p, 0x01, 0xe9, 0x00);
    assert_int_equal(r.n, 1);
    check_ev(&r.ev[0], "volume", LR_EV_DELTA, 1);
    r = PARSE(&p, 0x01, 0x00, 0x00);
    assert_int_equal(r.n, 0);
    r = PARSE(&p, 0x01, 0xea, 0x00);
    check_ev(&r.ev[0], "volume", LR_EV_DELTA, -1);
    r = PARSE(&p, 0x01, 0x00, 0x00);
    /* The knob's push: Mute press and release. */
    r = PARSE(&p, 0x01, 0xe2, 0x00);
    assert_int_equal(r.n, 1);
    check_ev(&r.ev[0], "mute", LR_EV_PRESS, 1);
    r = PARSE(&p, 0x01, 0x00, 0x00);
    assert_int_equal(r.n, 1);
    check_ev(&r.ev[0], "mute", LR_EV_RELEASE, 0);

    /* Another report of the composite device (keyboard, ID 2): ignored, not garbage. */
    r = PARSE(&p, 0x02, 0xe9, 0x00);
    assert_int_equal(r.rc, LR_OK);
    assert_int_equal(r.n, 0);
    assert_int_equal(p.ignored_reports, 1);

    /* Only the report ID: short. */
    r = PARSE(&p, 0x01);
    assert_int_equal(r.rc, LR_EPROTO);
    assert_string_equal(r.e.msg, "consumer: short report (0 bytes, need 2)");

    /* Oversized (padded to 20 bytes after the ID): two usages down and zero slots. */
    r = PARSE(&p, 0x01, 0xe9, 0x00, 0xcd, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
              0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00);
    assert_int_equal(r.rc, LR_OK);
    assert_int_equal(r.n, 2);
    check_ev(&r.ev[0], "volume", LR_EV_DELTA, 1);
    check_ev(&r.ev[1], "play", LR_EV_PRESS, 1);
    assert_int_equal(p.oversized_reports, 1);
    /* Play released, an unnamed usage (Scan Next Track 0xB5) pressed. */
    r = PARSE(&p, 0x01, 0xb5, 0x00);
    assert_int_equal(r.n, 2);
    check_ev(&r.ev[0], "play", LR_EV_RELEASE, 0);
    check_ev(&r.ev[1], "cc_0b5", LR_EV_PRESS, 1);
}

static void consumer_bitmap_reports(void **state)
{
    (void)state;
    lr_hid_parser p;
    lr_hid_parser_desc d = {.proto = LR_HID_CONSUMER, .cc_layout = LR_HID_CC_BITMAP,
                            .cc_bitmap = {0xcd, 0xb5, 0xb6, 0xe9, 0xea, 0xe2}};
    assert_int_equal(lr_hid_parser_init(&p, &d, NULL), LR_OK);
    parsed r = PARSE(&p, 0x08); /* bit 3: Volume Up */
    assert_int_equal(r.n, 1);
    check_ev(&r.ev[0], "volume", LR_EV_DELTA, 1);
    r = PARSE(&p, 0x30); /* Volume Up released; Volume Down and Mute */
    assert_int_equal(r.n, 2);
    check_ev(&r.ev[0], "volume", LR_EV_DELTA, -1);
    check_ev(&r.ev[1], "mute", LR_EV_PRESS, 1);
    r = P(&p, NULL, 0);
    assert_int_equal(r.rc, LR_EPROTO);

    lr_hid_parser_desc empty = {.proto = LR_HID_CONSUMER, .cc_layout = LR_HID_CC_BITMAP};
    lr_err e = {0};
    assert_int_equal(lr_hid_parser_init(&p, &empty, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "bitmap layout needs cc_bitmap"));
}

static uint32_t rnd(uint32_t *x)
{
    *x ^= *x << 13;
    *x ^= *x >> 17;
    *x ^= *x << 5;
    return *x;
}

static void garbage_never_breaks_a_parser(void **state)
{
    (void)state;
    /* Random reports of 0..80 bytes into every parser: only LR_OK or LR_EPROTO, bounded event
     * counts, values inside each control's range, and every garbage report counted. */
    const lr_hid_parser_desc descs[] = {
        {.proto = LR_HID_POWERMATE},
        {.proto = LR_HID_SHUTTLEXPRESS},
        {.proto = LR_HID_SHUTTLEPRO},
        {.proto = LR_HID_CONSUMER, .report_id = 1},
        {.proto = LR_HID_CONSUMER, .cc_layout = LR_HID_CC_BITMAP, .cc_bitmap = {0xe9, 0xea, 0xe2}},
    };
    uint32_t x = 2463534242u;
    for (size_t k = 0; k < sizeof descs / sizeof descs[0]; k++) {
        lr_hid_parser p;
        assert_int_equal(lr_hid_parser_init(&p, &descs[k], NULL), LR_OK);
        int garbage = 0;
        for (int i = 0; i < 20000; i++) {
            uint8_t buf[80];
            size_t len = rnd(&x) % (sizeof buf + 1);
            for (size_t j = 0; j < len; j++)
                buf[j] = (uint8_t)rnd(&x);
            if (descs[k].report_id && len && (rnd(&x) & 1))
                buf[0] = descs[k].report_id; /* mostly our report, sometimes another */
            parsed r = P(&p, buf, len);
            assert_true(r.rc == LR_OK || r.rc == LR_EPROTO);
            assert_true(r.n >= 0 && r.n <= LR_HID_MAX_EVENTS);
            if (r.rc != LR_OK) {
                garbage++;
                assert_int_equal(r.n, 0);
                assert_true(strlen(r.e.msg) > 0);
            }
            for (int j = 0; j < r.n; j++) {
                const lr_event *ev = &r.ev[j];
                assert_true(ev->control[0] != '\0');
                if (ev->kind == LR_EV_DELTA)
                    assert_true(ev->value >= -128 && ev->value <= 127 && ev->value != 0);
                else if (ev->kind == LR_EV_ABSOLUTE)
                    assert_true(ev->value >= -1 && ev->value <= 1);
                else
                    assert_float_equal(ev->value, ev->kind == LR_EV_PRESS ? 1 : 0, 0);
            }
        }
        assert_int_equal(garbage, (int)(p.short_reports + p.bad_values));
        assert_true(garbage > 0);
    }
}

static void proto_by_ids(void **state)
{
    (void)state;
    assert_int_equal(lr_hid_proto_for(0x077d, 0x0410), LR_HID_POWERMATE);
    assert_int_equal(lr_hid_proto_for(0x0b33, 0x0020), LR_HID_SHUTTLEXPRESS);
    assert_int_equal(lr_hid_proto_for(0x0b33, 0x0030), LR_HID_SHUTTLEPRO);
    assert_int_equal(lr_hid_proto_for(0x1234, 0x5678), LR_HID_CONSUMER);
}

static void noop_sink(void *user, const lr_event *ev)
{
    (void)ev;
    (*(int *)user)++;
}

static void hid_device_missing(void **state)
{
    (void)state;
    lr_test_log log = {0};
    int events = 0;
    lr_hid_desc desc = {
        .dev = {.sink = {noop_sink, &events}, .log = {lr_test_log_fn, &log}, .required = true},
        .vid = 0x077d, .pid = 0x0410,
    };
    lr_err e = {0};
    lr_hid *h = NULL;
    assert_int_equal(lr_hid_create(&desc, &h, &e), LR_ENODEV);
    assert_null(h);
    assert_non_null(strstr(e.msg, "hid: 077d:0410 (powermate): not present"));

    desc.dev.required = false;
    desc.dev.name = "knob";
    desc.serial = "PM123";
    assert_int_equal(lr_hid_create(&desc, &h, &e), LR_OK);
    lr_dev *d = lr_hid_dev(h);
    assert_int_equal(lr_dev_get_state(d), LR_DEV_MISSING);
    assert_non_null(strstr(lr_dev_status(d), "hid knob: 077d:0410 (powermate, serial PM123): "
                                             "not present"));
    assert_int_equal(log.n, 1);
    assert_string_equal(log.lines[0], lr_dev_status(d));
    assert_int_equal(events, 0);
    lr_hid_destroy(h);

    desc.vid = 0;
    assert_int_equal(lr_hid_create(&desc, &h, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "vid and pid are required"));
    lr_hid_library_exit();
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(powermate_reports),
        cmocka_unit_test(shuttlexpress_reports),
        cmocka_unit_test(shuttlepro_buttons),
        cmocka_unit_test(consumer_array_reports),
        cmocka_unit_test(consumer_bitmap_reports),
        cmocka_unit_test(garbage_never_breaks_a_parser),
        cmocka_unit_test(proto_by_ids),
        cmocka_unit_test(hid_device_missing),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
