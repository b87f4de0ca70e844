#include "render/base/warn.h"

#include <stdarg.h>
#include <stdio.h>

#include "render/base/err.h"

void lr_warn(const lr_warn_sink *sink, const char *fmt, ...)
{
    if (!sink || !sink->fn)
        return;
    char msg[LR_ERR_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    sink->fn(sink->user, msg);
}

void lr_warn_stderr(void *program, const char *msg)
{
    fprintf(stderr, "%s: warning: %s\n", program ? (const char *)program : "lamprig", msg);
}
