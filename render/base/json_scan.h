/* lamprig — the strict JSON scanner behind lr_json (internal to render/base).
 *
 * One pass over the text checks it against RFC 8259 and lays it out as a flat token array in
 * document order: an object is followed by its members as key, value subtree, key, value...;
 * an array by its elements. Each token records where it is (byte offsets and 1-based line)
 * and where its subtree ends, so lookups and messages never re-scan the text.
 */
#ifndef LR_JSON_SCAN_H
#define LR_JSON_SCAN_H

#include <stddef.h>

#include "render/base/err.h"
#include "render/base/json.h"

typedef struct lr_json_tok {
    int start, end;          /* byte offsets; a string's exclude its quotes */
    int size;                /* members of an object, elements of an array, else 0 */
    int next;                /* index of the first token after this token's subtree */
    int line;                /* 1-based line of the token's first byte */
    enum lr_json_type type;
} lr_json_tok;

/* Scans text[0, len) (text[len] must be '\0'). On success returns LR_OK with *tok (malloc'd,
 * *count >= 1 entries, token 0 the top-level value). Otherwise LR_EPARSE (or LR_ENOMEM) with
 * "NAME:LINE: field 'PATH': what is wrong" in e, and *tok NULL. */
int lr_json_scan(const char *text, size_t len, const char *name, lr_json_tok **tok, int *count,
                 lr_err *e);

/* Decodes the escapes of the string text[start, end) (already validated by the scanner) into
 * buf as UTF-8, NUL-terminated. Returns the decoded length, or -1 when it does not fit in cap
 * bytes. The decoded form is never longer than the escaped one. */
long lr_json_unescape(const char *text, int start, int end, char *buf, size_t cap);

#endif
