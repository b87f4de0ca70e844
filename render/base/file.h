/* lamprig — reading a whole (small) file: shaders, image files, configs. */
#ifndef LR_FILE_H
#define LR_FILE_H

#include <stddef.h>
#include <stdio.h>

#include "render/base/err.h"

/* The most a whole-file read takes, by kind of file: a file over it is refused, never read
 * until memory runs out (a symlink to /dev/zero is refused as a device; a huge or growing
 * regular file by this cap). */
#define LR_FILE_MAX_TEXT ((size_t)16 << 20)   /* configs, scenes, shaders, tables, scripts */
#define LR_FILE_MAX_DATA ((size_t)256 << 20)  /* images, volumes, meshes */
#define LR_FILE_MAX_CACHE ((size_t)2 << 30)   /* on-disk caches (tens to hundreds of MB) */

/* Opens path for reading when it is a regular file (symlinks followed); returns the fd, or
 * minus an LR_E* code with "path: a FIFO, not a regular file" (a directory, a device, a
 * socket) or "path: cannot open: <strerror>". Never blocks: a FIFO is opened with O_NONBLOCK
 * and refused; the flag is cleared on the regular file returned. */
int lr_file_open_regular(const char *path, lr_err *e);

/* The same as a stdio stream ("rb") in *out, for readers that parse with stdio; returns
 * lr_file_open_regular's code and message (LR_ENOMEM when the stream cannot be made), *out
 * NULL then. The caller fcloses *out. */
int lr_file_fopen_regular(const char *path, FILE **out, lr_err *e);

/* Reads the regular file path, at most max bytes (LR_FILE_MAX_*), into a malloc'd buffer with
 * a NUL after the last byte (so text can be used as a string; binary data may hold NULs of
 * its own), length in *len. LR_EIO with "path: <strerror>" when it cannot be opened or read,
 * "path: a FIFO, not a regular file" (lr_file_open_regular), "path: larger than N bytes, the
 * most this kind of file may have". The caller frees *data. */
int lr_file_read(const char *path, size_t max, char **data, size_t *len, lr_err *e);

/* Creates folder dir (mode 0777 less the umask) and, when missing, its parent (one level:
 * ~/.cache may not exist yet on a fresh account); an existing dir is fine. LR_EIO with
 * "WHAT: dir: <strerror>" when it cannot be made. */
int lr_dir_make(const char *dir, const char *what, lr_err *e);

#endif
