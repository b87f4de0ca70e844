#include "hal/backoff.h"

#include "hal/dev.h"

#define MS 1000000LL

void lr_backoff_init(lr_backoff *b, int min_ms, int max_ms)
{
    /* The defaults are the device descriptor's (hal/dev.c lr_dev_opts). */
    b->min_ns = (min_ms > 0 ? min_ms : lr_dev_opts[LR_DEV_OPT_RETRY_MIN_MS].dflt) * MS;
    b->max_ns = (max_ms > 0 ? max_ms : lr_dev_opts[LR_DEV_OPT_RETRY_MAX_MS].dflt) * MS;
    if (b->max_ns < b->min_ns)
        b->max_ns = b->min_ns;
    lr_backoff_reset(b);
}

int64_t lr_backoff_fail(lr_backoff *b, int64_t now_ns)
{
    int64_t delay = b->next_delay_ns;
    b->failures++;
    b->next_delay_ns = delay > b->max_ns / 2 ? b->max_ns : delay * 2;
    return now_ns + delay;
}

void lr_backoff_reset(lr_backoff *b)
{
    b->next_delay_ns = b->min_ns;
    b->failures = 0;
}
