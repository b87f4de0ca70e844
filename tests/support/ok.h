/* A call that returns an lr_err code, asserted to succeed: on failure the test fails with the
 * call, its code and the error's message (plain assert_int_equal(..., LR_OK) shows only the
 * numbers, which told nothing when a CI run failed where no one could rerun it). */
#ifndef LR_TEST_OK_H
#define LR_TEST_OK_H

#define assert_lr_ok(call, err)                                                               \
    do {                                                                                      \
        int lr_rc_ = (call);                                                                  \
        if (lr_rc_ != 0)                                                                      \
            fail_msg("%s returned %d: %s", #call, lr_rc_, (err).msg);                         \
    } while (0)

#endif
