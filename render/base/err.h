/* lamprig — error reporting shared by every module.
 *
 * Functions return 0 (LR_OK) on success or one of the positive LR_E* codes, and, when the
 * caller passed a non-NULL lr_err, a one-line message naming what failed: the file, line and
 * field for bad input, the device for hardware, the shader file and line for GL.
 */
#ifndef LR_ERR_H
#define LR_ERR_H

#include <stddef.h>

enum lr_status {
    LR_OK = 0,
    LR_EINVAL,      /* bad argument or value (NaN, negative, out of range) */
    LR_EPARSE,      /* malformed file or text */
    LR_EIO,         /* read/write failure */
    LR_ENOMEM,      /* allocation failure */
    LR_ENODEV,      /* device or display not present */
    LR_EUNSUPPORTED,/* missing capability (GL extension, device feature) */
    LR_EGL,         /* EGL/GLES failure, shader compile/link error */
    LR_ETIMEOUT,    /* device did not answer in time */
    LR_EPROTO,      /* device answered garbage (bad CRC, exception, short report) */
    LR_ECANCELED,   /* long work stopped early on request (render/base/cancel.h) */
};

#define LR_ERR_MSG_MAX 512

typedef struct lr_err {
    int code;
    char msg[LR_ERR_MSG_MAX];
} lr_err;

/* Records code and a printf-style message in e (which may be NULL); returns code so that
 * callers can write `return lr_err_set(e, LR_EINVAL, "...")`. */
int lr_err_set(lr_err *e, int code, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

/* Prepends "context: " to the message already in e (e.g. the file being loaded); returns
 * e->code (or LR_OK when e is NULL). */
int lr_err_prefix(lr_err *e, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

void lr_err_clear(lr_err *e);

/* Short name of a status code, e.g. "invalid argument". */
const char *lr_status_str(int code);

#endif
