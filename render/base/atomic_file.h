/* lamprig — atomic file replacement: write a temp file in the same directory, fsync, rename.
 * A crash or a failed write leaves the previous file intact (calibrations, presets, images). */
#ifndef LR_ATOMIC_FILE_H
#define LR_ATOMIC_FILE_H

#include <stddef.h>
#include <stdio.h>
#include <sys/types.h>

#include "render/base/err.h"

typedef struct lr_atomic_file lr_atomic_file;

/* Modes asked for, before the process's umask takes its bits (render/base/umask.h), as
 * open(2) would: data files (images, meshes, tables, caches) 0666, so 0644 under the usual
 * umask 022; calibrations and the rig's state 0640: the service's group may read them, other
 * users not, whatever the umask leaves. */
#define LR_FILE_MODE_DATA 0666
#define LR_FILE_MODE_PRIVATE 0640

/* Opens a temp file beside `path` for writing; write through lr_atomic_file_stream(). The
 * file gets LR_FILE_MODE_DATA less the umask (_mode: `mode` less the umask). */
int lr_atomic_file_open(const char *path, lr_atomic_file **out, lr_err *e);
int lr_atomic_file_open_mode(const char *path, mode_t mode, lr_atomic_file **out, lr_err *e);
FILE *lr_atomic_file_stream(lr_atomic_file *f);
/* Flushes, fsyncs and renames over `path`. Always frees f; on failure the temp is removed
 * and the old file is untouched. */
int lr_atomic_file_commit(lr_atomic_file *f, lr_err *e);
/* Discards the temp file (on an error path); frees f. */
void lr_atomic_file_abort(lr_atomic_file *f);

/* Checks, before the work that produces it, that `path` can be written atomically: it is not
 * a directory, and a temp file can be created beside it (created and removed at once). So a
 * command refuses `--out DIR` or `--out missing/dir/f.png` at start, not after rendering.
 * LR_EINVAL "path: is a directory", LR_EIO "path: cannot create a file beside it: ...". */
int lr_atomic_file_check(const char *path, lr_err *e);

/* Whole-buffer convenience. */
int lr_atomic_write(const char *path, const void *data, size_t len, lr_err *e);
int lr_atomic_write_mode(const char *path, const void *data, size_t len, mode_t mode, lr_err *e);

#endif
