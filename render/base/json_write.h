/* lamprig — writing JSON documents (render/base/json.h reads them).
 *
 * A small streaming writer: objects and arrays nest, members are keyed, commas and
 * indentation are automatic, numbers are written with the fewest digits that read back to
 * the same double (so a saved calibration reloads bit-identical). Errors (a NaN or an
 * infinity, mismatched nesting, a stream error) are sticky: later calls do nothing and
 * lr_jw_finish reports the first one with the key it concerned.
 */
#ifndef LR_BASE_JSON_WRITE_H
#define LR_BASE_JSON_WRITE_H

#include <stdbool.h>
#include <stdio.h>

#include "render/base/err.h"

typedef struct lr_jw lr_jw;

/* Writes to f (not closed by the writer). NULL when out of memory. */
lr_jw *lr_jw_create(FILE *f);
/* Checks that every object/array was closed and nothing failed; frees w. */
int lr_jw_finish(lr_jw *w, lr_err *e);

/* `key` names the member inside an object; pass NULL inside arrays and at the top level. */
void lr_jw_object(lr_jw *w, const char *key);
void lr_jw_object_end(lr_jw *w);
void lr_jw_array(lr_jw *w, const char *key);
void lr_jw_array_end(lr_jw *w);
void lr_jw_number(lr_jw *w, const char *key, double v);
/* A measurement that may be missing (NaN/Inf, e.g. a median of no samples) as null; plain
 * lr_jw_number treats a non-finite value as an error. */
void lr_jw_number_or_null(lr_jw *w, const char *key, double v);
void lr_jw_null(lr_jw *w, const char *key);
void lr_jw_int(lr_jw *w, const char *key, long v);
void lr_jw_bool(lr_jw *w, const char *key, bool v);
void lr_jw_string(lr_jw *w, const char *key, const char *s);
/* An array of n numbers, written compactly (several per line). */
void lr_jw_numbers(lr_jw *w, const char *key, const double *v, int n);
/* rows x cols row-major matrix as an array of row arrays. */
void lr_jw_matrix(lr_jw *w, const char *key, const double *m, int rows, int cols);

#endif
