/* lamprig firmware — sd_notify from the rig loop (see notify.h). */
#include "firmware/rig/notify.h"

#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <systemd/sd-daemon.h>

struct lr_notify {
    int64_t interval_ns; /* 0: no watchdog */
    int64_t next_ns;
    uint64_t pings;
};

int lr_notify_create(int64_t now_ns, lr_notify **out, lr_err *e)
{
    *out = NULL;
    lr_notify *n = calloc(1, sizeof *n);
    if (!n)
        return lr_err_set(e, LR_ENOMEM, "out of memory");
    uint64_t usec = 0;
    /* > 0: enabled for this process; 0: not asked for (or for another pid); < 0: a malformed
     * WATCHDOG_USEC/WATCHDOG_PID, which we treat as "not asked for" rather than fail a
     * service over its environment. */
    if (sd_watchdog_enabled(0, &usec) > 0 && usec > 0) {
        n->interval_ns = (int64_t)(usec / 2) * 1000;
        if (n->interval_ns <= 0)
            n->interval_ns = 1000;
        n->next_ns = now_ns; /* the first ping goes out on the first wake */
    } else {
        n->next_ns = INT64_MAX;
    }
    *out = n;
    return LR_OK;
}

void lr_notify_destroy(lr_notify *n) { free(n); }

int64_t lr_notify_interval_ns(const lr_notify *n) { return n->interval_ns; }

int64_t lr_notify_deadline(const lr_notify *n) { return n->next_ns; }

void lr_notify_tick(lr_notify *n, int64_t now_ns, const char *status)
{
    if (!n->interval_ns || now_ns < n->next_ns)
        return;
    if (status)
        sd_notifyf(0, "WATCHDOG=1\nSTATUS=%s", status);
    else
        sd_notify(0, "WATCHDOG=1");
    n->pings++;
    n->next_ns = now_ns + n->interval_ns;
}

void lr_notify_ready(lr_notify *n, const char *status)
{
    (void)n;
    if (status)
        sd_notifyf(0, "READY=1\nSTATUS=%s", status);
    else
        sd_notify(0, "READY=1");
}

void lr_notify_reloading(lr_notify *n, int64_t now_ns)
{
    (void)n;
    sd_notifyf(0, "RELOADING=1\nMONOTONIC_USEC=%lld", (long long)(now_ns / 1000));
}

void lr_notify_stopping(lr_notify *n)
{
    (void)n;
    sd_notify(0, "STOPPING=1");
}

uint64_t lr_notify_pings(const lr_notify *n) { return n->pings; }
