/* Test support for tests/hal/test_hal_*.c: a log hook that records lines, and a miniature main
 * loop (poll over the devices' fds and deadlines) like the firmware's. */
#ifndef LR_TEST_HAL_TEST_H
#define LR_TEST_HAL_TEST_H

#include <stdbool.h>
#include <stdint.h>

#include "hal/dev.h"
#include "hal/log.h"

#define LR_TEST_LOG_LINES 256

typedef struct lr_test_log {
    int n;
    char lines[LR_TEST_LOG_LINES][768];
} lr_test_log;

/* lr_log_fn: user is an lr_test_log. */
void lr_test_log_fn(void *user, lr_log_level level, const char *msg);
/* Lines containing needle. */
int lr_test_log_count(const lr_test_log *log, const char *needle);

typedef bool (*lr_test_pred)(void *user);

/* Runs poll + dispatch over devs until pred(user) is true (checked after every dispatch) or
 * guard_ms of wall time passed (a failure guard, not a timing assertion). Returns pred's last
 * value. */
bool lr_test_run(lr_dev **devs, int n, int guard_ms, lr_test_pred pred, void *user);

#endif
