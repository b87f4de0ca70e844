/* lamprig calib — the envelope every calibration file shares.
 *
 * A calibration file is a JSON object {"version": 1, "kind": "...", ...}. Loading checks the
 * version first (another version is a clear error, never a guess), then the kind (so a
 * projector file given where a camera file is expected is refused), then every field: type,
 * finiteness, range and matrix size, with messages "FILE:LINE: field 'F': ...".
 *
 * Saving renders the whole document in memory, parses it back and runs the kind's own
 * validation on it, and only then replaces the file atomically (temp + fsync + rename): a
 * calibration that failed, or produced values the loader would refuse, never overwrites a
 * good file, and a crash mid-write leaves the old one intact.
 */
#ifndef LR_CALIB_CALFILE_H
#define LR_CALIB_CALFILE_H

#include <stddef.h>

#include "render/base/json_write.h"
#include "render/base/json.h"

#define LR_CALFILE_VERSION 1

/* Writes the kind-specific members of obj (after "version" and "kind"). */
typedef void (*lr_calfile_fill_fn)(lr_jw *w, const void *obj);
/* Validates a parsed document of this kind as the loader does (parse into a scratch value
 * and free it); returns an error naming the field. */
typedef int (*lr_calfile_check_fn)(const lr_json *j, lr_jnode root, lr_err *e);

int lr_calfile_save(const char *path, const char *kind, lr_calfile_fill_fn fill,
                    const void *obj, lr_calfile_check_fn check, lr_err *e);

/* Loads path, checks "version" and "kind"; on success *j (destroy with lr_json_destroy) and
 * *root (the top-level object). */
int lr_calfile_load(const char *path, const char *kind, lr_json **j, lr_jnode *root,
                    lr_err *e);
/* The same on text already in memory; name is used in messages. */
int lr_calfile_parse(const char *text, size_t len, const char *name, const char *kind,
                     lr_json **j, lr_jnode *root, lr_err *e);
/* The "kind" of a document, for tools that accept any calibration file. */
int lr_calfile_peek_kind(const char *path, char *kind, size_t cap, lr_err *e);

/* Field readers with range checks. `prefix` (may be NULL) names the enclosing object in
 * messages ("projector" gives field 'projector.fx'). All fields are required. */
int lr_calfile_number(const lr_json *j, lr_jnode obj, const char *prefix, const char *key,
                      double lo, double hi, double *out, lr_err *e);
int lr_calfile_int(const lr_json *j, lr_jnode obj, const char *prefix, const char *key,
                   long lo, long hi, long *out, lr_err *e);
/* An array of exactly n numbers, each in [lo, hi]. */
int lr_calfile_numbers(const lr_json *j, lr_jnode obj, const char *prefix, const char *key,
                       int n, double lo, double hi, double *out, lr_err *e);
/* rows arrays of cols numbers each, in [lo, hi]; out is row-major. */
int lr_calfile_matrix(const lr_json *j, lr_jnode obj, const char *prefix, const char *key,
                      int rows, int cols, double lo, double hi, double *out, lr_err *e);
/* A member that must be an array (*count elements) or an object. */
int lr_calfile_array(const lr_json *j, lr_jnode obj, const char *prefix, const char *key,
                     lr_jnode *arr, int *count, lr_err *e);
int lr_calfile_object(const lr_json *j, lr_jnode obj, const char *prefix, const char *key,
                      lr_jnode *out, lr_err *e);

#endif
