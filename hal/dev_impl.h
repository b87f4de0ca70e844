/* lamprig hal — PRIVATE to hal/: the device base every back end embeds as its first member,
 * and the table of back-end functions behind the public lr_dev interface. Not for firmware/. */
#ifndef LR_HAL_DEV_IMPL_H
#define LR_HAL_DEV_IMPL_H

#include "hal/backoff.h"
#include "hal/dev.h"
#include "render/base/err.h"

/* A state line: device prefix + an lr_err message + "; retrying with backoff". */
#define LR_DEV_LINE_MAX (LR_ERR_MSG_MAX + 4 * LR_EVENT_NAME_MAX + 64)

typedef struct lr_dev_ops {
    const char *kind;
    /* Opens the device; on failure returns an LR_E* code with a message in e (LR_ENODEV for
     * "not there", anything else for "there but failing"). Must leave nothing open on failure. */
    int (*open)(lr_dev *d, int64_t now_ns, lr_err *e);
    /* Releases what open acquired (idempotent); the configuration stays. */
    void (*close)(lr_dev *d);
    /* Only called while open. */
    int (*pollfds)(lr_dev *d, struct pollfd *fds, int max);
    void (*dispatch)(lr_dev *d, int64_t now_ns);
    int64_t (*next_deadline)(lr_dev *d);
    /* Frees the back end (after close). */
    void (*destroy)(lr_dev *d);
    /* true: a successful open is not yet a success for the reopen backoff; the back end calls
     * lr_dev_proven() once the device really worked (Modbus: a good answer). Otherwise a peer
     * that accepts a connection and closes it at once would be reopened every retry_min_ms
     * for ever, since each connect would reset the backoff. */
    bool open_needs_proof;
} lr_dev_ops;

struct lr_dev {
    const lr_dev_ops *ops;
    char name[LR_EVENT_NAME_MAX];
    char prefix[2 * LR_EVENT_NAME_MAX]; /* "gpio" or "gpio knobs": starts every log line */
    char ident[320];  /* what is opened ("gpiochip0", "tcp://10.0.0.5:502"): named in the
                       * "open" line; set by the back end, may stay empty */
    lr_event_sink sink;
    lr_log log;
    lr_dev_state state;
    bool started;
    char status[LR_DEV_LINE_MAX];
    lr_backoff backoff;
    int64_t retry_at; /* LR_NO_DEADLINE while open or done */
    unsigned fd_gen;
    int emitted;      /* events emitted during the current dispatch */
};

/* Fills the base from the common descriptor. Validates desc->sink. */
int lr_dev_init(lr_dev *d, const lr_dev_ops *ops, const lr_dev_desc *desc, lr_err *e);
/* First open attempt at create time. When it fails: with desc->required, returns the error
 * (message prefixed with the device); otherwise logs, schedules a retry and returns LR_OK. */
int lr_dev_start(lr_dev *d, bool required, int64_t now_ns, lr_err *e);
/* Back end saw its device go away or fail: closes it, logs once, schedules the reopen. */
void lr_dev_lost(lr_dev *d, int code, int64_t now_ns, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
/* The device worked (see lr_dev_ops.open_needs_proof): the next failure waits retry_min_ms
 * again. Cheap; call it on every good exchange. */
void lr_dev_proven(lr_dev *d);
/* Marks the device finished (sim script played out). */
void lr_dev_done(lr_dev *d, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* Emits one event from this device (source = device name unless given). */
void lr_dev_emit(lr_dev *d, const char *source, const char *control, lr_event_kind kind,
                 double value, int64_t t_ns);
/* Logs one line prefixed with the device ("gpio knobs: ..."). */
void lr_dev_log(lr_dev *d, lr_log_level level, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* Tells epoll users that the descriptor set changed. */
void lr_dev_fds_changed(lr_dev *d);

#endif
