#include "hal/log.h"

#include <stdarg.h>
#include <stdio.h>

void lr_log_silent(void *user, lr_log_level level, const char *msg)
{
    (void)user;
    (void)level;
    (void)msg;
}

const char *lr_log_level_name(lr_log_level level)
{
    switch (level) {
    case LR_LOG_ERROR: return "error";
    case LR_LOG_WARN: return "warn";
    case LR_LOG_INFO: return "info";
    case LR_LOG_DEBUG: return "debug";
    }
    return "?";
}

void lr_log_write(const lr_log *log, lr_log_level level, const char *fmt, ...)
{
    char line[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    if (log && log->fn) {
        log->fn(log->user, level, line);
        return;
    }
    /* The documented default: one line on stderr, so that a rig without a configured hook
     * still says why a device is missing. */
    fprintf(stderr, "lamprig: %s: %s\n", lr_log_level_name(level), line);
}

void lr_log_limit_init(lr_log_limit *l, int burst, int64_t window_ns)
{
    l->window_ns = window_ns;
    l->burst = burst < 1 ? 1 : burst;
    l->window_start = INT64_MIN;
    l->used = 0;
    l->dropped = 0;
}

bool lr_log_limit_take(lr_log_limit *l, int64_t now_ns, unsigned *dropped)
{
    if (l->window_ns > 0) {
        if (l->window_start == INT64_MIN || now_ns - l->window_start >= l->window_ns) {
            l->window_start = now_ns;
            l->used = 0;
        }
        if (l->used >= l->burst) {
            l->dropped++;
            return false;
        }
        l->used++;
    }
    if (dropped)
        *dropped = l->dropped;
    l->dropped = 0;
    return true;
}
