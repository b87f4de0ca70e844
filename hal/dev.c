#include "hal/dev_impl.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

int64_t lr_now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000LL + ts.tv_nsec;
}

const lr_opt lr_dev_opts[] = {
    [LR_DEV_OPT_NAME] = {"name", LR_OPT_STRING,
                         .help = "source name in events and logs; default: the type"},
    [LR_DEV_OPT_REQUIRED] = {"required", LR_OPT_BOOL, .dflt = 0,
                             .help = "absent at start: an error instead of retrying"},
    [LR_DEV_OPT_RETRY_MIN_MS] = {"retry_min_ms", LR_OPT_INT, 1, 3600000, 250,
                                 .help = "first reopen delay after a failure"},
    [LR_DEV_OPT_RETRY_MAX_MS] = {"retry_max_ms", LR_OPT_INT, 1, 3600000, 10000,
                                 .help = "backoff cap"},
    LR_OPT_END,
};

int lr_dev_init(lr_dev *d, const lr_dev_ops *ops, const lr_dev_desc *desc, lr_err *e)
{
    memset(d, 0, sizeof *d);
    d->ops = ops;
    const char *name = desc->name && desc->name[0] ? desc->name : ops->kind;
    if (strlen(name) >= LR_EVENT_NAME_MAX)
        return lr_err_set(e, LR_EINVAL, "%s: name '%s' is longer than %d characters", ops->kind,
                          name, LR_EVENT_NAME_MAX - 1);
    strcpy(d->name, name);
    if (strcmp(name, ops->kind) == 0)
        snprintf(d->prefix, sizeof d->prefix, "%s", ops->kind);
    else
        snprintf(d->prefix, sizeof d->prefix, "%s %s", ops->kind, name);
    if (!desc->sink.fn)
        return lr_err_set(e, LR_EINVAL, "%s: no event sink (dev.sink.fn is NULL)", d->prefix);
    const lr_opt *rmin = &lr_dev_opts[LR_DEV_OPT_RETRY_MIN_MS];
    const lr_opt *rmax = &lr_dev_opts[LR_DEV_OPT_RETRY_MAX_MS];
    if (!lr_opt_hal_ok(rmin, desc->retry_min_ms) || !lr_opt_hal_ok(rmax, desc->retry_max_ms))
        return lr_err_set(e, LR_EINVAL, "%s: retry_min_ms %d / retry_max_ms %d is not %ld..%ld",
                          d->prefix, desc->retry_min_ms, desc->retry_max_ms, rmin->lo, rmin->hi);
    d->sink = desc->sink;
    d->log = desc->log;
    lr_backoff_init(&d->backoff, desc->retry_min_ms, desc->retry_max_ms);
    d->state = LR_DEV_MISSING;
    d->retry_at = LR_NO_DEADLINE;
    return LR_OK;
}

/* Stores the state line and logs it when the state or the reason changed: once per change,
 * never once per retry. */
static void set_state(lr_dev *d, lr_dev_state state, lr_log_level level, const char *line)
{
    bool changed = !d->started || state != d->state || strcmp(line, d->status) != 0;
    d->state = state;
    d->started = true;
    if (!changed)
        return;
    snprintf(d->status, sizeof d->status, "%s", line);
    lr_log_write(&d->log, level, "%s", d->status);
}

static void failed(lr_dev *d, int code, int64_t now_ns, const char *msg)
{
    char line[LR_DEV_LINE_MAX];
    snprintf(line, sizeof line, "%s: %s; retrying with backoff", d->prefix, msg);
    d->retry_at = lr_backoff_fail(&d->backoff, now_ns);
    set_state(d, code == LR_ENODEV ? LR_DEV_MISSING : LR_DEV_RETRYING, LR_LOG_WARN, line);
}

static void opened(lr_dev *d)
{
    char line[LR_DEV_LINE_MAX];
    unsigned attempts = d->backoff.failures;
    char what[sizeof d->ident + 2] = "";
    if (d->ident[0])
        snprintf(what, sizeof what, "%s: ", d->ident);
    if (attempts && d->started)
        snprintf(line, sizeof line, "%s: %sopen (after %u failed attempt%s)", d->prefix, what,
                 attempts, attempts == 1 ? "" : "s");
    else
        snprintf(line, sizeof line, "%s: %sopen", d->prefix, what);
    if (!d->ops->open_needs_proof)
        lr_backoff_reset(&d->backoff);
    d->retry_at = LR_NO_DEADLINE;
    lr_dev_fds_changed(d);
    set_state(d, LR_DEV_OPEN, LR_LOG_INFO, line);
}

int lr_dev_start(lr_dev *d, bool required, int64_t now_ns, lr_err *e)
{
    lr_err oe = {0};
    int rc = d->ops->open(d, now_ns, &oe);
    if (rc == LR_OK) {
        opened(d);
        return LR_OK;
    }
    if (required)
        return lr_err_set(e, rc, "%s: %s", d->prefix, oe.msg);
    failed(d, rc, now_ns, oe.msg);
    return LR_OK;
}

void lr_dev_lost(lr_dev *d, int code, int64_t now_ns, const char *fmt, ...)
{
    char msg[LR_ERR_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    d->ops->close(d);
    lr_dev_fds_changed(d);
    failed(d, code, now_ns, msg);
}

void lr_dev_proven(lr_dev *d)
{
    if (d->state == LR_DEV_OPEN)
        lr_backoff_reset(&d->backoff);
}

void lr_dev_done(lr_dev *d, const char *fmt, ...)
{
    char msg[LR_ERR_MSG_MAX], line[LR_DEV_LINE_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    snprintf(line, sizeof line, "%s: %s", d->prefix, msg);
    d->retry_at = LR_NO_DEADLINE;
    set_state(d, LR_DEV_DONE, LR_LOG_INFO, line);
}

void lr_dev_emit(lr_dev *d, const char *source, const char *control, lr_event_kind kind,
                 double value, int64_t t_ns)
{
    lr_event ev;
    lr_event_set(&ev, source && source[0] ? source : d->name, control, kind, value, t_ns);
    d->sink.fn(d->sink.user, &ev);
    d->emitted++;
}

void lr_dev_log(lr_dev *d, lr_log_level level, const char *fmt, ...)
{
    char msg[LR_ERR_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    lr_log_write(&d->log, level, "%s: %s", d->prefix, msg);
}

void lr_dev_fds_changed(lr_dev *d) { d->fd_gen++; }

int lr_dev_pollfds(lr_dev *d, struct pollfd *fds, int max)
{
    if (d->state != LR_DEV_OPEN)
        return 0;
    return d->ops->pollfds(d, fds, max);
}

int lr_dev_dispatch(lr_dev *d, int64_t now_ns)
{
    d->emitted = 0;
    if ((d->state == LR_DEV_MISSING || d->state == LR_DEV_RETRYING) && now_ns >= d->retry_at) {
        lr_err oe = {0};
        int rc = d->ops->open(d, now_ns, &oe);
        if (rc == LR_OK)
            opened(d);
        else
            failed(d, rc, now_ns, oe.msg);
    }
    if (d->state == LR_DEV_OPEN)
        d->ops->dispatch(d, now_ns);
    return d->emitted;
}

int64_t lr_dev_next_deadline(lr_dev *d)
{
    switch (d->state) {
    case LR_DEV_OPEN: return d->ops->next_deadline(d);
    case LR_DEV_MISSING:
    case LR_DEV_RETRYING: return d->retry_at;
    case LR_DEV_DONE: break;
    }
    return LR_NO_DEADLINE;
}

void lr_dev_retry_now(lr_dev *d, int64_t now_ns)
{
    if (d->state != LR_DEV_MISSING && d->state != LR_DEV_RETRYING)
        return;
    lr_backoff_reset(&d->backoff);
    d->retry_at = now_ns;
}

lr_dev_state lr_dev_get_state(const lr_dev *d) { return d->state; }

const char *lr_dev_state_name(lr_dev_state s)
{
    switch (s) {
    case LR_DEV_OPEN: return "open";
    case LR_DEV_MISSING: return "missing";
    case LR_DEV_RETRYING: return "retrying";
    case LR_DEV_DONE: return "done";
    }
    return "?";
}

const char *lr_dev_name(const lr_dev *d) { return d->name; }
const char *lr_dev_kind(const lr_dev *d) { return d->ops->kind; }
const char *lr_dev_status(const lr_dev *d) { return d->status; }
unsigned lr_dev_fd_generation(const lr_dev *d) { return d->fd_gen; }
unsigned lr_dev_failures(const lr_dev *d) { return d->backoff.failures; }

void lr_dev_destroy(lr_dev *d)
{
    if (!d)
        return;
    d->ops->close(d);
    d->ops->destroy(d);
}
