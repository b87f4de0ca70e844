/* Control mapping pieces: dimmer curves, fades, encoder acceleration. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "firmware/control/accel.h"
#include "firmware/control/curve.h"
#include "firmware/control/fade.h"
#include "tests/support/near.h"

#define MS 1000000LL

static void test_curve_values(void **state)
{
    (void)state;
    /* Closed forms at x = 0.5: square 1/4, smoothstep 1/2, log10(5.5). */
    assert_near(lr_curve_apply(LR_CURVE_LINEAR, 0.5), 0.5, 1e-15);
    assert_near(lr_curve_apply(LR_CURVE_SQUARE, 0.5), 0.25, 1e-15);
    assert_near(lr_curve_apply(LR_CURVE_SCURVE, 0.5), 0.5, 1e-15);
    assert_near(lr_curve_apply(LR_CURVE_SCURVE, 0.25), 0.15625, 1e-15);
    assert_near(lr_curve_apply(LR_CURVE_LOG, 0.5), log10(5.5), 1e-15);
    for (int c = LR_CURVE_LINEAR; c <= LR_CURVE_WARM_DIM; c++) {
        /* End points are exact: a dimmer at its stops is off / full whatever the curve. */
        assert_true(lr_curve_apply((enum lr_curve)c, 0.0) == 0.0);
        assert_near(lr_curve_apply((enum lr_curve)c, 1.0), 1.0, 1e-15);
        /* Out-of-range and NaN input are clamped, never propagated. */
        assert_true(lr_curve_apply((enum lr_curve)c, -3.0) == 0.0);
        assert_true(lr_curve_apply((enum lr_curve)c, NAN) == 0.0);
        assert_near(lr_curve_apply((enum lr_curve)c, 7.0), 1.0, 1e-15);
        /* Strictly increasing and invertible on a fine grid; the inverse is closed-form, so
         * the round trip is exact to a few ulps (1e-12 leaves room for asin/sin). */
        double prev = -1.0;
        for (int i = 0; i <= 1000; i++) {
            double x = i / 1000.0;
            double y = lr_curve_apply((enum lr_curve)c, x);
            assert_true(y > prev);
            prev = y;
            assert_near(lr_curve_invert((enum lr_curve)c, y), x, 1e-12);
        }
    }
}

static void test_curve_names(void **state)
{
    (void)state;
    enum lr_curve c;
    assert_int_equal(lr_curve_parse("s-curve", &c), 0);
    assert_int_equal(c, LR_CURVE_SCURVE);
    assert_string_equal(lr_curve_name(LR_CURVE_LOG), "log");
    assert_int_equal(lr_curve_parse("cubic", &c), -1);
}

static void test_fade(void **state)
{
    (void)state;
    lr_fade f;
    lr_fade_init(&f, 0.2);
    assert_near(lr_fade_value(&f, 5 * MS), 0.2, 0);
    lr_fade_to(&f, 1.0, 1000 * MS, 2.0); /* 0.2 -> 1.0 over 2 s from t = 1 s */
    assert_true(lr_fade_active(&f, 1500 * MS));
    assert_near(lr_fade_value(&f, 1000 * MS), 0.2, 1e-15);
    assert_near(lr_fade_value(&f, 2000 * MS), 0.6, 1e-12); /* half way */
    assert_near(lr_fade_value(&f, 9000 * MS), 1.0, 0);
    assert_true(lr_fade_end_ns(&f) == 3000 * MS);
    /* Retarget mid-fade: continuous at the instant of the change. */
    double at = lr_fade_value(&f, 2500 * MS); /* 0.8 */
    lr_fade_to(&f, 0.0, 2500 * MS, 1.0);
    assert_near(lr_fade_value(&f, 2500 * MS), at, 1e-15);
    assert_near(lr_fade_value(&f, 3000 * MS), at / 2, 1e-12);
    /* Zero duration jumps; a clock before the start gives the start value. */
    lr_fade_to(&f, 0.5, 4000 * MS, 0.0);
    assert_false(lr_fade_active(&f, 4000 * MS));
    assert_near(lr_fade_value(&f, 4000 * MS), 0.5, 0);
    lr_fade_to(&f, 1.0, 5000 * MS, 1.0);
    assert_near(lr_fade_value(&f, 4000 * MS), 0.5, 0);
}

static void test_accel(void **state)
{
    (void)state;
    lr_accel a;
    lr_accel_init(&a, 1.0, 5.0, 4.0);
    /* Slow turning (2 detents/s < rate0): every delta passes unchanged. */
    int64_t t = 0;
    for (int i = 0; i < 5; i++, t += 500 * MS)
        assert_near(lr_accel_apply(&a, (i & 1) ? -1.0 : 1.0, t), (i & 1) ? -1.0 : 1.0, 0);
    /* A fast spin: 1 detent per 20 ms = 50 detents/s -> factor 1 + (50-5)/5 = 10, capped at 4;
     * after the first event (no rate yet) the smoothed rate is 50/s from the second on. */
    t += 1000 * MS;
    assert_near(lr_accel_apply(&a, 1.0, t), 1.0, 0); /* after a pause: unaccelerated */
    t += 20 * MS;
    assert_near(lr_accel_apply(&a, 1.0, t), 4.0, 1e-12);
    t += 20 * MS;
    assert_near(lr_accel_apply(&a, -1.0, t), -4.0, 1e-12); /* sign kept */
    /* Moderate: 1 detent per 100 ms = 10/s smoothed from a fresh start: factor 1 + 5/5 = 2. */
    lr_accel_init(&a, 1.0, 5.0, 4.0);
    assert_near(lr_accel_apply(&a, 1.0, 0), 1.0, 0);
    assert_near(lr_accel_apply(&a, 1.0, 100 * MS), 2.0, 1e-12);
    /* Garbage deltas never propagate. */
    assert_near(lr_accel_apply(&a, NAN, 200 * MS), 0.0, 0);
    /* gain 0 = no acceleration at any speed. */
    lr_accel_init(&a, 0.0, 5.0, 4.0);
    lr_accel_apply(&a, 1.0, 0);
    assert_near(lr_accel_apply(&a, 1.0, 1 * MS), 1.0, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_curve_values),
        cmocka_unit_test(test_curve_names),
        cmocka_unit_test(test_fade),
        cmocka_unit_test(test_accel),
    };
    return cmocka_run_group_tests_name("control", tests, NULL, NULL);
}
