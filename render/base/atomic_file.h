/* lamprig — files that are either entirely the old version or entirely the new one.
 *
 * Output goes to a temporary file in the destination's directory (so rename stays within one
 * file system, where it is atomic); commit flushes it to disk, renames it over the
 * destination and syncs the directory. A crash or power cut at any point leaves the previous
 * file intact, which is what a rig that runs unattended for days needs for its calibration
 * and its images alike.
 *
 *     lr_atomic_file *af;
 *     if (lr_atomic_open(path, &af, e)) return e->code;
 *     fprintf(lr_atomic_stream(af), ...);
 *     return lr_atomic_commit(af, e);   // or lr_atomic_abort(af) to keep the old file
 */
#ifndef LR_ATOMIC_FILE_H
#define LR_ATOMIC_FILE_H

#include <stdio.h>

#include "render/base/err.h"

typedef struct lr_atomic_file lr_atomic_file;

/* Creates "<path>.tmp-XXXXXX" next to path. LR_EIO names the directory on failure. */
int lr_atomic_open(const char *path, lr_atomic_file **out, lr_err *e);
/* The stream to write to (binary mode). */
FILE *lr_atomic_stream(lr_atomic_file *af);
/* Flushes, fsyncs, closes and renames over the destination; on any failure removes the
 * temporary file and leaves the destination as it was (LR_EIO naming path). Frees af. */
int lr_atomic_commit(lr_atomic_file *af, lr_err *e);
/* Closes and removes the temporary file; the destination is untouched. Frees af; NULL ok. */
void lr_atomic_abort(lr_atomic_file *af);

#endif
