/* lamprig — JSON documents with line numbers, for every config, scene, material and
 * calibration file.
 *
 * Every file is read as strict JSON (RFC 8259), and every refusal names the file, the line and
 * the field ("configs/materials/wax.json:7: field 'sigma_a[1]': must be >= 0, got -0.2").
 * Refused while parsing, before any field is used:
 *   - words other than true, false and null ("tuesday", "nope", NaN, Infinity), single quotes,
 *     comments, keys without quotes;
 *   - trailing or doubled commas, missing ',' or ':', text after the top-level value;
 *   - numbers outside the grammar (leading zeros, "1.", ".5", "+1", hex), and numbers that
 *     overflow a double or underflow to 0 (1e999, 1e-400; subnormals such as 5e-324 are
 *     finite doubles and are kept);
 *   - unknown escapes, unpaired UTF-16 surrogates, raw control characters (a tab, a line break)
 *     in strings, malformed UTF-8, and "\u0000" (our strings are C strings);
 *   - a key given twice in one object (RFC 8259 leaves the meaning open; we refuse it and name
 *     both lines), nesting deeper than LR_JSON_MAX_DEPTH.
 * A UTF-8 byte-order mark at the start is skipped (RFC 8259 section 8.1 allows it).
 * Integers (lr_json_int) must fit a long exactly; 2^63 and beyond are errors, not casts.
 *
 * Why our own scanner and not a library: the messages need the line of every value, not only
 * of syntax errors, and the path of the field. Debian 12's JSON libraries (jansson 2.14,
 * json-c 0.16, cJSON 1.7) build trees that keep no source position per value (yyjson is not
 * in Debian 12), so a line-tracking layer over them would have to re-scan the text anyway; and
 * jsmn (used before) is a tokenizer that leaves validation to its users, which is how bare
 * words and trailing commas got through. The scanner (json_scan.c) is one non-recursive
 * pass, tested case by case in tests/base/test_json.c.
 *
 * A document is immutable after parsing; nodes are indices into it, valid until destroy.
 */
#ifndef LR_JSON_H
#define LR_JSON_H

#include <stdbool.h>
#include <stddef.h>

#include "render/base/err.h"

typedef struct lr_json lr_json;
typedef int lr_jnode; /* LR_JNONE when absent */
#define LR_JNONE (-1)

/* Deepest nesting of objects and arrays a document may have. */
#define LR_JSON_MAX_DEPTH 512

enum lr_json_type { LR_JSON_NONE, LR_JSON_OBJECT, LR_JSON_ARRAY, LR_JSON_STRING,
                    LR_JSON_NUMBER, LR_JSON_BOOL, LR_JSON_NULL };

/* Reads and parses a file (at most 16 MiB) as strict JSON (see above). The name used in
 * messages is the path. */
int lr_json_load(const char *path, lr_json **out, lr_err *e);
/* Parses text (copied); name is used in messages (a path, "--set", "<stdin>"). */
int lr_json_parse(const char *text, size_t len, const char *name, lr_json **out, lr_err *e);
void lr_json_destroy(lr_json *j);

const char *lr_json_name(const lr_json *j);
lr_jnode lr_json_root(const lr_json *j);
enum lr_json_type lr_json_type(const lr_json *j, lr_jnode n);
const char *lr_json_type_name(enum lr_json_type t);
/* 1-based line of a node (0 for LR_JNONE). */
int lr_json_line(const lr_json *j, lr_jnode n);

/* Number of elements of an array or members of an object; 0 otherwise. */
int lr_json_count(const lr_json *j, lr_jnode n);
/* i-th element of an array, or i-th member value of an object; LR_JNONE when out of range. */
lr_jnode lr_json_at(const lr_json *j, lr_jnode n, int i);
/* Key node of the i-th member of an object (a string node). */
lr_jnode lr_json_key_at(const lr_json *j, lr_jnode obj, int i);
/* Member value by key, LR_JNONE when absent or when obj is not an object. */
lr_jnode lr_json_get(const lr_json *j, lr_jnode obj, const char *key);
/* True when string node n equals s (after unescaping). */
bool lr_json_str_eq(const lr_json *j, lr_jnode n, const char *s);

/* Typed values. `field` is the name used in messages (e.g. "sigma_a" or "lights[2].pos").
 * Each returns LR_OK, or LR_EPARSE with "file:line: field 'F': expected a number, got a
 * string" style messages. Numbers are finite doubles (the parser refused overflow and
 * underflow). */
int lr_json_number(const lr_json *j, lr_jnode n, const char *field, double *out, lr_err *e);
int lr_json_int(const lr_json *j, lr_jnode n, const char *field, long *out, lr_err *e);
int lr_json_bool(const lr_json *j, lr_jnode n, const char *field, bool *out, lr_err *e);
/* Copies the unescaped string into buf (NUL-terminated); too long for cap is an error. */
int lr_json_string(const lr_json *j, lr_jnode n, const char *field, char *buf, size_t cap,
                   lr_err *e);
/* An array of exactly `count` numbers (e.g. an RGB triple or a position). */
int lr_json_numbers(const lr_json *j, lr_jnode n, const char *field, double *out, int count,
                    lr_err *e);

/* Member lookups on an object. When the key is absent: required → error naming the object's
 * line and the missing field; optional → LR_OK and *out left untouched (callers preset the
 * default). */
int lr_json_get_number(const lr_json *j, lr_jnode obj, const char *key, bool required,
                       double *out, lr_err *e);
int lr_json_get_int(const lr_json *j, lr_jnode obj, const char *key, bool required, long *out,
                    lr_err *e);
int lr_json_get_bool(const lr_json *j, lr_jnode obj, const char *key, bool required, bool *out,
                     lr_err *e);
int lr_json_get_string(const lr_json *j, lr_jnode obj, const char *key, bool required,
                       char *buf, size_t cap, lr_err *e);
int lr_json_get_numbers(const lr_json *j, lr_jnode obj, const char *key, bool required,
                        double *out, int count, lr_err *e);

/* Rejects members whose key is not in the NULL-terminated `allowed` list (catches typos in
 * hand-edited files; duplicate keys never get this far: the parser refuses them); `where`
 * names the object in messages. */
int lr_json_check_keys(const lr_json *j, lr_jnode obj, const char *where,
                       const char *const *allowed, lr_err *e);

/* Formats "NAME:LINE: field 'FIELD': MESSAGE" into e with the given code; returns code. */
int lr_json_fail(const lr_json *j, lr_jnode n, const char *field, lr_err *e, int code,
                 const char *fmt, ...) __attribute__((format(printf, 6, 7)));

#endif
