/* lamprig — reading a whole (small) file: shaders, image files, configs. */
#ifndef LR_FILE_H
#define LR_FILE_H

#include <stddef.h>

#include "render/base/err.h"

/* Reads path into a malloc'd buffer with a NUL after the last byte (so text can be used as a
 * string; binary data may hold NULs of its own), length in *len. LR_EIO with
 * "path: <strerror>" when it cannot be opened or read. The caller frees *data. */
int lr_file_read(const char *path, char **data, size_t *len, lr_err *e);

#endif
