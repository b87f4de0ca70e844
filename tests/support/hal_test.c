#include "tests/support/hal_test.h"

#include <poll.h>
#include <stdio.h>
#include <string.h>

void lr_test_log_fn(void *user, lr_log_level level, const char *msg)
{
    lr_test_log *log = user;
    (void)level;
    if (log->n < LR_TEST_LOG_LINES)
        snprintf(log->lines[log->n++], sizeof log->lines[0], "%s", msg);
}

int lr_test_log_count(const lr_test_log *log, const char *needle)
{
    int c = 0;
    for (int i = 0; i < log->n; i++)
        if (strstr(log->lines[i], needle))
            c++;
    return c;
}

bool lr_test_run(lr_dev **devs, int n, int guard_ms, lr_test_pred pred, void *user)
{
    int64_t end = lr_now_ns() + (int64_t)guard_ms * 1000000;
    if (pred && pred(user))
        return true;
    for (;;) {
        struct pollfd fds[64];
        int nf = 0;
        int64_t now = lr_now_ns();
        int64_t t = end;
        for (int i = 0; i < n; i++) {
            int k = lr_dev_pollfds(devs[i], fds + nf, 64 - nf);
            nf += k < 64 - nf ? k : 64 - nf;
            int64_t d = lr_dev_next_deadline(devs[i]);
            if (d < t)
                t = d;
        }
        int timeout = t <= now ? 0 : (int)((t - now + 999999) / 1000000);
        poll(fds, (nfds_t)nf, timeout);
        now = lr_now_ns();
        for (int i = 0; i < n; i++)
            lr_dev_dispatch(devs[i], now);
        if (pred && pred(user))
            return true;
        if (now >= end)
            return false;
    }
}
