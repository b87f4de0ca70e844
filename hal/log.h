/* lamprig hal — the logging hook.
 *
 * hal/ never prints on its own: every line goes through an lr_log that the caller puts in a
 * descriptor. A zero lr_log (fn == NULL) means the documented default, one line on stderr
 * ("lamprig: warn: gpio: gpiochip0: ..."); pass lr_log_silent to drop everything.
 * Devices log once per state change (open, missing, retrying), never once per retry.
 */
#ifndef LR_HAL_LOG_H
#define LR_HAL_LOG_H

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

/* "error", "warn", "info", "debug". */
const char *lr_log_level_name(lr_log_level level);

#endif
