/* lamprig — reading a whole (small) file: shaders, image files, configs. */
#ifndef LR_FILE_H
#define LR_FILE_H

#include <stddef.h>

#include "render/base/err.h"

/* Reads path into a malloc'd buffer with a NUL after the last byte (so text can be used as a
 * string; binary data may hold NULs of its own), length in *len. LR_EIO with
 * "path: <strerror>" when it cannot be opened or read. The caller frees *data. */
int lr_file_read(const char *path, char **data, size_t *len, lr_err *e);

/* Creates folder dir (mode 0777 less the umask) and, when missing, its parent (one level:
 * ~/.cache may not exist yet on a fresh account); an existing dir is fine. LR_EIO with
 * "WHAT: dir: <strerror>" when it cannot be made. */
int lr_dir_make(const char *dir, const char *what, lr_err *e);

#endif
