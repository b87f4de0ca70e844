/* lamprig — whether a folder can take the files a cache will write there.
 *
 * A full or read-only disk must cost a cache, never the program: Mesa's on-disk shader cache
 * maps its index file and dies with SIGBUS when the page it touches cannot be allocated
 * (render/gl/shader_cache.h), and our own caches would fail on every start. Callers check
 * first and run without the cache, with one warning. */
#ifndef LR_DIR_CHECK_H
#define LR_DIR_CHECK_H

#include <stdint.h>

#include "render/base/err.h"

/* Whether files can be written in folder dir, or, when it does not exist yet, in its nearest
 * existing ancestor (where it would be made): that folder is a directory, its file system is
 * mounted read-write, it has at least min_free bytes free for this user (statvfs f_bavail),
 * and a probe file of 4 KiB can be created and written there (removed at once; root passes
 * permission bits, not a read-only mount or a full tmpfs). LR_OK, else LR_EIO with
 * "DIR: reason" naming the folder checked: "not a folder", "read-only file system",
 * "N kB free, under M kB", or the probe's strerror. */
int lr_dir_check_writable(const char *dir, uint64_t min_free, lr_err *e);

#endif
