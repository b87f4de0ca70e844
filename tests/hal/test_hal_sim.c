/* hal/: sim scripts — parsing (good file; bad lines name file:line) and playback order and
 * timing through lr_dev_next_deadline. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "hal/event.h"
#include "hal/sim.h"
#include "tests/support/hal_test.h"

#define S 1000000000LL

static const char *GOOD =
    "# demo: turn the dimmer up, click a knob, press a button\r\n"
    "\n"
    "0.000  knob1          delta     +3\n"
    "0.250  dimmer         absolute  0.75   # three quarters\n"
    "   1   button1        press\n"
    "1.1    button1        release\n"
    "1.1    modbus/dimmer  absolute  5e-1\n"
    "2.5    jog            delta     -2\n"
    "4      end\n";

static void script_parses(void **state)
{
    (void)state;
    lr_sim_script *s = NULL;
    lr_err e = {0};
    assert_int_equal(lr_sim_script_parse(GOOD, "demo.sim", &s, &e), LR_OK);
    assert_int_equal(lr_sim_script_count(s), 6);
    assert_int_equal(lr_sim_script_length_ns(s), 4 * S);
    lr_event ev;
    assert_true(lr_sim_script_get(s, 0, &ev));
    assert_string_equal(ev.source, "");
    assert_string_equal(ev.control, "knob1");
    assert_int_equal(ev.kind, LR_EV_DELTA);
    assert_float_equal(ev.value, 3, 0);
    assert_int_equal(ev.t_ns, 0);
    assert_true(lr_sim_script_get(s, 1, &ev));
    assert_int_equal(ev.kind, LR_EV_ABSOLUTE);
    assert_float_equal(ev.value, 0.75, 0);
    assert_int_equal(ev.t_ns, 250000000);
    assert_true(lr_sim_script_get(s, 2, &ev));
    assert_int_equal(ev.kind, LR_EV_PRESS);
    assert_float_equal(ev.value, 1, 0); /* default for press */
    assert_true(lr_sim_script_get(s, 3, &ev));
    assert_int_equal(ev.kind, LR_EV_RELEASE);
    assert_float_equal(ev.value, 0, 0);
    assert_int_equal(ev.t_ns, 1100000000);
    assert_true(lr_sim_script_get(s, 4, &ev));
    assert_string_equal(ev.source, "modbus");
    assert_string_equal(ev.control, "dimmer");
    assert_float_equal(ev.value, 0.5, 0);
    assert_true(lr_sim_script_get(s, 5, &ev));
    assert_float_equal(ev.value, -2, 0);
    assert_false(lr_sim_script_get(s, 6, &ev));
    lr_sim_script_destroy(s);

    /* Empty and comment-only scripts are valid and empty. */
    assert_int_equal(lr_sim_script_parse("# nothing\n\n", NULL, &s, &e), LR_OK);
    assert_int_equal(lr_sim_script_count(s), 0);
    lr_sim_script_destroy(s);
}

static void bad_lines_name_file_and_line(void **state)
{
    (void)state;
    static const struct {
        const char *text, *msg;
    } cases[] = {
        {"0 knob1 delta 1\n0.5 knob1 dleta 1\n",
         "x.sim:2: unknown kind 'dleta' (expected delta, absolute, press or release)"},
        {"1 a press\n# c\n0.5 b press\n", "x.sim:3: time 0.5 goes back (previous event at 1 s)"},
        {"0 dimmer absolute\n", "x.sim:1: absolute needs a value"},
        {"0 knob1 delta +1 extra\n", "x.sim:1: too many fields (time control kind [value])"},
        {"0 knob1 delta nan\n", "x.sim:1: value 'nan' is not a finite number"},
        {"0 knob1 delta 1x\n", "x.sim:1: value '1x' is not a finite number"},
        {"-1 knob1 delta 1\n", "x.sim:1: time '-1' is not a number of seconds >= 0"},
        {"soon knob1 delta 1\n", "x.sim:1: time 'soon' is not a number of seconds >= 0"},
        {"0 kn$b delta 1\n", "x.sim:1: control 'kn$b' is not 1..31 characters of [A-Za-z0-9_.-]"},
        {"0 /knob delta 1\n", "x.sim:1: source '' is not 1..31 characters of [A-Za-z0-9_.-]"},
        {"0 knob1\n", "x.sim:1: expected 'time control kind [value]'"},
        {"1 end\n2 knob1 delta 1\n", "x.sim:2: event after the 'end' line"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        lr_sim_script *s = NULL;
        lr_err e = {0};
        assert_int_equal(lr_sim_script_parse(cases[i].text, "x.sim", &s, &e), LR_EPARSE);
        assert_null(s);
        assert_string_equal(e.msg, cases[i].msg);
    }
}

static void garbage_scripts(void **state)
{
    (void)state;
    /* Random lines built from script-like tokens and junk: parsed or rejected with file:line,
     * never anything else. */
    static const char *const tok[] = {"0", "0.5", "1e3", "-1", "nan", "knob1", "a/b", "/",
                                      "delta", "absolute", "press", "release", "end", "+3",
                                      "#", "\t", "x\x01y", "99999999999", "", "1.5e-9"};
    uint32_t x = 88172645u;
    int ok = 0, bad = 0;
    for (int i = 0; i < 3000; i++) {
        char text[512] = "";
        int lines = 1 + (int)(x % 4);
        for (int l = 0; l < lines; l++) {
            int ntok = (int)((x >> 8) % 6);
            for (int t = 0; t < ntok; t++) {
                x ^= x << 13;
                x ^= x >> 17;
                x ^= x << 5;
                strcat(text, tok[x % (sizeof tok / sizeof tok[0])]);
                strcat(text, " ");
            }
            strcat(text, "\n");
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
        }
        lr_sim_script *s = NULL;
        lr_err e = {0};
        int rc = lr_sim_script_parse(text, "fuzz.sim", &s, &e);
        if (rc == LR_OK) {
            ok++;
            assert_non_null(s);
            lr_sim_script_destroy(s);
        } else {
            bad++;
            assert_int_equal(rc, LR_EPARSE);
            assert_null(s);
            assert_memory_equal(e.msg, "fuzz.sim:", 9);
        }
    }
    assert_true(ok > 0 && bad > 0);
}

static void load_file_errors(void **state)
{
    (void)state;
    lr_err e = {0};
    lr_sim_script *s;
    assert_int_equal(lr_sim_script_load("/nonexistent/demo.sim", &s, &e), LR_EIO);
    assert_string_equal(e.msg, "/nonexistent/demo.sim: cannot open: No such file or directory");

    char path[] = "/tmp/lamprig-sim-XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    const char *text = "0 knob1 delta 1\n1 knob1 delta 1\n2 knob1 spin 1\n";
    assert_int_equal(write(fd, text, strlen(text)), (ssize_t)strlen(text));
    close(fd);
    lr_event_ring *ring;
    assert_int_equal(lr_event_ring_create(0, &ring, NULL), LR_OK);
    lr_sim_desc d = {.dev = {.sink = lr_event_ring_sink(ring)}, .path = path};
    lr_sim *sim = NULL;
    assert_int_equal(lr_sim_create(&d, &sim, &e), LR_EPARSE);
    assert_null(sim);
    char want[128];
    snprintf(want, sizeof want, "%s:3: unknown kind 'spin'", path);
    assert_non_null(strstr(e.msg, want));
    unlink(path);
    lr_event_ring_destroy(ring);
}

static void playback_by_deadlines(void **state)
{
    (void)state;
    lr_event_ring *ring;
    lr_test_log log = {0};
    assert_int_equal(lr_event_ring_create(0, &ring, NULL), LR_OK);
    const int64_t t0 = 1000 * S; /* a fixed clock: the test drives time itself */
    lr_sim_desc d = {.dev = {.name = "demo", .sink = lr_event_ring_sink(ring),
                             .log = {lr_test_log_fn, &log}},
                     .text = GOOD, .start_ns = t0};
    lr_sim *sim = NULL;
    lr_err e = {0};
    assert_int_equal(lr_sim_create(&d, &sim, &e), LR_OK);
    lr_dev *dev = lr_sim_dev(sim);
    struct pollfd fds[2];
    assert_int_equal(lr_dev_pollfds(dev, fds, 2), 0); /* a timer device: no fd */
    assert_int_equal(lr_dev_get_state(dev), LR_DEV_OPEN);

    /* The first event is due at t0; before that nothing happens. */
    assert_int_equal(lr_dev_next_deadline(dev), t0);
    assert_int_equal(lr_dev_dispatch(dev, t0 - 1), 0);
    assert_int_equal(lr_dev_dispatch(dev, t0), 1);
    assert_int_equal(lr_dev_next_deadline(dev), t0 + 250000000);
    assert_int_equal(lr_dev_dispatch(dev, t0 + 249999999), 0);
    assert_int_equal(lr_dev_dispatch(dev, t0 + 250000000), 1);
    assert_int_equal(lr_dev_next_deadline(dev), t0 + 1 * S);

    /* A loop that wakes up late gets every due event, in script order, stamped with the
     * scripted times (not the wake-up time). */
    assert_int_equal(lr_dev_dispatch(dev, t0 + 2 * S), 3);
    assert_int_equal(lr_dev_next_deadline(dev), t0 + 2500000000LL);
    assert_int_equal(lr_dev_dispatch(dev, t0 + 3 * S), 1);

    static const struct {
        const char *source, *control;
        lr_event_kind kind;
        double value;
        int64_t t;
    } want[] = {
        {"demo", "knob1", LR_EV_DELTA, 3, 0},
        {"demo", "dimmer", LR_EV_ABSOLUTE, 0.75, 250000000},
        {"demo", "button1", LR_EV_PRESS, 1, 1000000000},
        {"demo", "button1", LR_EV_RELEASE, 0, 1100000000},
        {"modbus", "dimmer", LR_EV_ABSOLUTE, 0.5, 1100000000},
        {"demo", "jog", LR_EV_DELTA, -2, 2500000000LL},
    };
    assert_int_equal(lr_event_ring_count(ring), 6);
    for (int i = 0; i < 6; i++) {
        lr_event ev;
        assert_true(lr_event_ring_pop(ring, &ev));
        assert_string_equal(ev.source, want[i].source);
        assert_string_equal(ev.control, want[i].control);
        assert_int_equal(ev.kind, want[i].kind);
        assert_float_equal(ev.value, want[i].value, 0);
        assert_int_equal(ev.t_ns, t0 + want[i].t);
    }
    /* Played out: done, no deadline, one log line saying so. */
    assert_int_equal(lr_dev_get_state(dev), LR_DEV_DONE);
    assert_int_equal(lr_dev_next_deadline(dev), LR_NO_DEADLINE);
    assert_int_equal(lr_sim_played(sim), 6);
    assert_int_equal(lr_test_log_count(&log, "sim demo: script finished (6 events)"), 1);
    lr_sim_destroy(sim);
    lr_event_ring_destroy(ring);
}

static void playback_loops(void **state)
{
    (void)state;
    lr_event_ring *ring;
    assert_int_equal(lr_event_ring_create(0, &ring, NULL), LR_OK);
    const int64_t t0 = 5 * S;
    lr_sim_desc d = {.dev = {.sink = lr_event_ring_sink(ring), .log = {lr_log_silent, NULL}},
                     .text = "0.5 a press\n1 a release\n2 end\n", .start_ns = t0, .loop = true};
    lr_sim *sim = NULL;
    assert_int_equal(lr_sim_create(&d, &sim, NULL), LR_OK);
    lr_dev *dev = lr_sim_dev(sim);
    assert_int_equal(lr_dev_dispatch(dev, t0 + 1 * S), 2);
    /* The second round starts at t0 + 2 s (the `end` time). */
    assert_int_equal(lr_dev_next_deadline(dev), t0 + 2500000000LL);
    assert_int_equal(lr_dev_dispatch(dev, t0 + 4500000000LL), 3);
    lr_event ev;
    for (int i = 0; i < 5; i++)
        assert_true(lr_event_ring_pop(ring, &ev));
    assert_int_equal(ev.t_ns, t0 + 4500000000LL);
    assert_int_equal(ev.kind, LR_EV_PRESS);
    assert_int_equal(lr_dev_get_state(dev), LR_DEV_OPEN);
    lr_sim_destroy(sim);
    lr_event_ring_destroy(ring);
}

static bool ring_has(void *user)
{
    return lr_event_ring_count(user) >= 2;
}

static void playback_in_a_real_loop(void **state)
{
    (void)state;
    /* With the real clock: the mini main loop sleeps in poll() until each deadline. */
    lr_event_ring *ring;
    assert_int_equal(lr_event_ring_create(0, &ring, NULL), LR_OK);
    lr_sim_desc d = {.dev = {.sink = lr_event_ring_sink(ring), .log = {lr_log_silent, NULL}},
                     .text = "0.01 a delta 1\n0.02 b delta -1\n"};
    lr_sim *sim = NULL;
    assert_int_equal(lr_sim_create(&d, &sim, NULL), LR_OK);
    lr_dev *dev = lr_sim_dev(sim);
    int64_t start = lr_now_ns();
    assert_true(lr_test_run(&dev, 1, 10000, ring_has, ring));
    lr_event a, b;
    assert_true(lr_event_ring_pop(ring, &a));
    assert_true(lr_event_ring_pop(ring, &b));
    assert_string_equal(a.control, "a");
    assert_string_equal(b.control, "b");
    assert_int_equal(b.t_ns - a.t_ns, 10000000); /* scripted spacing, whatever the wake-ups */
    assert_true(lr_now_ns() >= b.t_ns);          /* never played early */
    assert_true(a.t_ns >= start - S);
    lr_sim_destroy(sim);
    lr_event_ring_destroy(ring);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(script_parses),
        cmocka_unit_test(bad_lines_name_file_and_line),
        cmocka_unit_test(garbage_scripts),
        cmocka_unit_test(load_file_errors),
        cmocka_unit_test(playback_by_deadlines),
        cmocka_unit_test(playback_loops),
        cmocka_unit_test(playback_in_a_real_loop),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
