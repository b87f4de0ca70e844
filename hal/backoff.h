/* lamprig hal — exponential backoff for reopening devices (pure, no clock of its own).
 *
 * The first retry comes min_ns after a failure, each further one twice as late, capped at
 * max_ns; a success resets it. Deterministic (no jitter): one rig talks to its own devices,
 * there is no thundering herd to spread out, and tests can assert the schedule.
 */
#ifndef LR_HAL_BACKOFF_H
#define LR_HAL_BACKOFF_H

#include <stdint.h>

typedef struct lr_backoff {
    int64_t min_ns, max_ns;
    int64_t next_delay_ns; /* delay the next failure will get */
    unsigned failures;     /* consecutive failures since the last reset */
} lr_backoff;

/* min_ms 0 means 250 ms, max_ms 0 means 10 s (lr_dev_opts' defaults); max is raised to min when smaller. */
void lr_backoff_init(lr_backoff *b, int min_ms, int max_ms);
/* Records a failure at now_ns; returns the time of the next attempt. */
int64_t lr_backoff_fail(lr_backoff *b, int64_t now_ns);
/* Records a success: the next failure waits min_ns again. */
void lr_backoff_reset(lr_backoff *b);

#endif
