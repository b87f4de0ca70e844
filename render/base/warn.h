/* lamprig — warnings that are not errors (a mesh repaired, a field ignored).
 *
 * Library code never prints: it hands each warning, one line without a trailing newline, to
 * the sink its caller passed. A zero-initialised sink (fn == NULL) discards warnings.
 */
#ifndef LR_WARN_H
#define LR_WARN_H

typedef void (*lr_warn_fn)(void *user, const char *msg);

typedef struct lr_warn_sink {
    lr_warn_fn fn;
    void *user;
} lr_warn_sink;

/* Formats one warning (truncated to LR_ERR_MSG_MAX) and passes it to sink->fn; sink may be
 * NULL. */
void lr_warn(const lr_warn_sink *sink, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* A sink function for programs (library code never passes it itself): writes
 * "PROGRAM: warning: MSG" and a newline to stderr, PROGRAM the user pointer (a string that
 * outlives the sink, e.g. "lamprig-bench"). {lr_warn_stderr, "lamprig-cpuref"} is a sink. */
void lr_warn_stderr(void *program, const char *msg);

#endif
