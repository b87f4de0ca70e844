/* lamprig hal — the logging hook.
 *
 * hal/ never prints on its own: every line goes through an lr_log that the caller puts in a
 * descriptor. A zero lr_log (fn == NULL) means the documented default, one line on stderr
 * ("lamprig: warn: gpio: gpiochip0: ..."); pass lr_log_silent to drop everything.
 * Devices log once per state change (open, missing, retrying), never once per retry, and
 * rate-limit the lines a peer can cause (lr_log_limit).
 */
#ifndef LR_HAL_LOG_H
#define LR_HAL_LOG_H

#include <stdbool.h>
#include <stdint.h>

typedef enum lr_log_level {
    LR_LOG_ERROR = 0,
    LR_LOG_WARN,
    LR_LOG_INFO,
    LR_LOG_DEBUG,
} lr_log_level;

/* msg is one line without a trailing newline; it is only valid during the call. */
typedef void (*lr_log_fn)(void *user, lr_log_level level, const char *msg);

typedef struct lr_log {
    lr_log_fn fn; /* NULL: stderr */
    void *user;
} lr_log;

/* A log hook that drops every line. */
void lr_log_silent(void *user, lr_log_level level, const char *msg);

/* Formats one line and hands it to log->fn (or stderr when log or log->fn is NULL). */
void lr_log_write(const lr_log *log, lr_log_level level, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* A rate limit for one kind of line from one device (pure, no clock of its own): at most
 * `burst` lines per `window_ns`; the lines over it are counted, and the next line let through
 * says how many were dropped. Dedup by message text is not enough: a misbehaving peer varies
 * the text (its unit, its function) with every answer. */
typedef struct lr_log_limit {
    int64_t window_ns;
    int burst;
    int64_t window_start; /* INT64_MIN: no line yet */
    int used;             /* lines let through in the current window */
    unsigned dropped;     /* lines dropped since the last one let through */
} lr_log_limit;

/* burst < 1 means 1; window_ns < 1 means no limit. */
void lr_log_limit_init(lr_log_limit *l, int burst, int64_t window_ns);
/* True when a line may be written at now_ns; then *dropped (may be NULL) gets the number of
 * lines dropped since the previous one let through, and the count starts again. False: the
 * line is counted as dropped. */
bool lr_log_limit_take(lr_log_limit *l, int64_t now_ns, unsigned *dropped);

/* "error", "warn", "info", "debug". */
const char *lr_log_level_name(lr_log_level level);

#endif
