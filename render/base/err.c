#include "render/base/err.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

int lr_err_set(lr_err *e, int code, const char *fmt, ...)
{
    if (e) {
        va_list ap;
        va_start(ap, fmt);
        e->code = code;
        vsnprintf(e->msg, sizeof e->msg, fmt, ap);
        va_end(ap);
    }
    return code;
}

int lr_err_prefix(lr_err *e, const char *fmt, ...)
{
    if (!e)
        return LR_OK;
    char prefix[LR_ERR_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(prefix, sizeof prefix, fmt, ap);
    va_end(ap);
    /* Shift the message right and write "prefix: " in front; truncate the tail if needed. */
    size_t cap = sizeof e->msg - 1;
    size_t plen = strlen(prefix);
    if (plen + 2 > cap)
        plen = cap - 2;
    size_t mlen = strlen(e->msg);
    if (plen + 2 + mlen > cap)
        mlen = cap - plen - 2;
    memmove(e->msg + plen + 2, e->msg, mlen);
    e->msg[plen + 2 + mlen] = '\0';
    memcpy(e->msg, prefix, plen);
    e->msg[plen] = ':';
    e->msg[plen + 1] = ' ';
    return e->code;
}

void lr_err_clear(lr_err *e)
{
    if (e) {
        e->code = LR_OK;
        e->msg[0] = '\0';
    }
}

const char *lr_status_str(int code)
{
    switch (code) {
    case LR_OK: return "ok";
    case LR_EINVAL: return "invalid argument";
    case LR_EPARSE: return "parse error";
    case LR_EIO: return "i/o error";
    case LR_ENOMEM: return "out of memory";
    case LR_ENODEV: return "no such device";
    case LR_EUNSUPPORTED: return "unsupported";
    case LR_EGL: return "GL error";
    case LR_ETIMEOUT: return "timeout";
    case LR_EPROTO: return "protocol error";
    case LR_ECANCELED: return "cancelled";
    default: return "unknown error";
    }
}
