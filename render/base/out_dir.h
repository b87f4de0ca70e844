/* lamprig — an output folder given on the command line (`lamprig run --out-dir DIR`). */
#ifndef LR_OUT_DIR_H
#define LR_OUT_DIR_H

#include "render/base/err.h"

/* Makes sure path is a writable directory, creating it (not its parents) when missing, so
 * that a command refuses a bad folder at start instead of failing once per file later.
 * LR_EINVAL "path: not a directory" when it names something else (a file);
 * LR_EIO "path: <strerror>" when it cannot be created or written. */
int lr_out_dir_prepare(const char *path, lr_err *e);

#endif
