/* Double-precision comparisons for cmocka tests. Debian 12's cmocka (1.1.5) has no
 * assert_double_equal and its assert_float_equal casts to float, which cannot check the
 * tolerances our numerics need. On failure these print both values and the tolerance. */
#ifndef LR_TEST_NEAR_H
#define LR_TEST_NEAR_H

#include <math.h>

/* |a - b| <= tol (absolute). NaN never passes. */
#define assert_near(a, b, tol)                                                                \
    do {                                                                                      \
        double lr_a_ = (a), lr_b_ = (b), lr_t_ = (tol);                                       \
        if (!(fabs(lr_a_ - lr_b_) <= lr_t_))                                                  \
            fail_msg("%s = %.17g, expected %s = %.17g within %.3g (off by %.3g)", #a, lr_a_,  \
                     #b, lr_b_, lr_t_, fabs(lr_a_ - lr_b_));                                  \
    } while (0)

/* |a - b| <= rel * |b| (relative to the expected value b). */
#define assert_near_rel(a, b, rel)                                                            \
    do {                                                                                      \
        double lr_a_ = (a), lr_b_ = (b), lr_r_ = (rel);                                       \
        if (!(fabs(lr_a_ - lr_b_) <= lr_r_ * fabs(lr_b_)))                                    \
            fail_msg("%s = %.17g, expected %s = %.17g within %.3g relative (off by %.3g)",    \
                     #a, lr_a_, #b, lr_b_, lr_r_, fabs(lr_a_ - lr_b_) / fabs(lr_b_));         \
    } while (0)

#endif
