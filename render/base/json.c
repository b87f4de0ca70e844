#include "render/base/json.h"
#include "render/base/file.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/json_scan.h"

#define LR_JSON_MAX_BYTES (16u << 20)

struct lr_json {
    char *name;
    char *text;
    size_t len;
    lr_json_tok *tok;
    int count;
};

int lr_json_fail(const lr_json *j, lr_jnode n, const char *field, lr_err *e, int code,
                 const char *fmt, ...)
{
    if (!e)
        return code;
    char msg[LR_ERR_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (field && field[0])
        return lr_err_set(e, code, "%s:%d: field '%s': %s", j->name, lr_json_line(j, n), field,
                          msg);
    return lr_err_set(e, code, "%s:%d: %s", j->name, lr_json_line(j, n), msg);
}

int lr_json_parse(const char *text, size_t len, const char *name, lr_json **out, lr_err *e)
{
    *out = NULL;
    if (!name)
        name = "<json>";
    if (len > LR_JSON_MAX_BYTES)
        return lr_err_set(e, LR_EPARSE, "%s: larger than %u bytes", name, LR_JSON_MAX_BYTES);
    lr_json *j = calloc(1, sizeof *j);
    if (!j)
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory", name);
    j->name = strdup(name);
    j->text = malloc(len + 1);
    if (!j->name || !j->text) {
        lr_json_destroy(j);
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory", name);
    }
    memcpy(j->text, text, len);
    j->text[len] = '\0';
    j->len = len;
    int rc = lr_json_scan(j->text, len, j->name, &j->tok, &j->count, e);
    if (rc) {
        lr_json_destroy(j);
        return rc;
    }
    *out = j;
    return LR_OK;
}

int lr_json_load(const char *path, lr_json **out, lr_err *e)
{
    *out = NULL;
    char *buf = NULL;
    size_t len = 0;
    int rc = lr_file_read(path, LR_FILE_MAX_TEXT, &buf, &len, e);
    if (rc)
        return rc;
    rc = lr_json_parse(buf, len, path, out, e);
    free(buf);
    return rc;
}

void lr_json_destroy(lr_json *j)
{
    if (!j)
        return;
    free(j->name);
    free(j->text);
    free(j->tok);
    free(j);
}

const char *lr_json_name(const lr_json *j) { return j->name; }
lr_jnode lr_json_root(const lr_json *j) { return j->count > 0 ? 0 : LR_JNONE; }

static bool valid(const lr_json *j, lr_jnode n) { return n >= 0 && n < j->count; }

enum lr_json_type lr_json_type(const lr_json *j, lr_jnode n)
{
    return valid(j, n) ? j->tok[n].type : LR_JSON_NONE;
}

const char *lr_json_type_name(enum lr_json_type t)
{
    static const char *const names[] = {"nothing", "an object", "an array", "a string",
                                        "a number", "a boolean", "null"};
    return (unsigned)t < sizeof names / sizeof names[0] ? names[t] : "?";
}

int lr_json_line(const lr_json *j, lr_jnode n)
{
    return valid(j, n) ? j->tok[n].line : 0;
}

int lr_json_count(const lr_json *j, lr_jnode n)
{
    enum lr_json_type t = lr_json_type(j, n);
    return (t == LR_JSON_OBJECT || t == LR_JSON_ARRAY) ? j->tok[n].size : 0;
}

lr_jnode lr_json_at(const lr_json *j, lr_jnode n, int i)
{
    enum lr_json_type t = lr_json_type(j, n);
    if ((t != LR_JSON_OBJECT && t != LR_JSON_ARRAY) || i < 0 || i >= j->tok[n].size)
        return LR_JNONE;
    int k = n + 1;
    for (int m = 0; m < i; m++)
        k = t == LR_JSON_OBJECT ? j->tok[k + 1].next : j->tok[k].next;
    return t == LR_JSON_OBJECT ? k + 1 : k;
}

lr_jnode lr_json_key_at(const lr_json *j, lr_jnode obj, int i)
{
    if (lr_json_type(j, obj) != LR_JSON_OBJECT)
        return LR_JNONE;
    lr_jnode v = lr_json_at(j, obj, i);
    return v == LR_JNONE ? LR_JNONE : v - 1;
}

/* String token n decoded into buf (cap bytes, NUL-terminated): its length, or -1 when it does
 * not fit. */
static long unescape(const lr_json *j, lr_jnode n, char *buf, size_t cap)
{
    return lr_json_unescape(j->text, j->tok[n].start, j->tok[n].end, buf, cap);
}

bool lr_json_str_eq(const lr_json *j, lr_jnode n, const char *s)
{
    if (lr_json_type(j, n) != LR_JSON_STRING)
        return false;
    char buf[256];
    long len = unescape(j, n, buf, sizeof buf);
    return len >= 0 && strcmp(buf, s) == 0;
}

lr_jnode lr_json_get(const lr_json *j, lr_jnode obj, const char *key)
{
    int count = lr_json_count(j, obj);
    if (lr_json_type(j, obj) != LR_JSON_OBJECT)
        return LR_JNONE;
    int k = obj + 1;
    for (int m = 0; m < count; m++) {
        if (lr_json_str_eq(j, k, key))
            return k + 1;
        k = j->tok[k + 1].next;
    }
    return LR_JNONE;
}

static int expect(const lr_json *j, lr_jnode n, const char *field, enum lr_json_type want,
                  lr_err *e)
{
    enum lr_json_type got = lr_json_type(j, n);
    if (got == want)
        return LR_OK;
    return lr_json_fail(j, n, field, e, LR_EPARSE, "expected %s, got %s", lr_json_type_name(want),
                        lr_json_type_name(got));
}

/* The scanner checked the grammar and that the value is a finite double that is not 0
 * unless the text is, so reading it again cannot fail. */
int lr_json_number(const lr_json *j, lr_jnode n, const char *field, double *out, lr_err *e)
{
    int rc = expect(j, n, field, LR_JSON_NUMBER, e);
    if (rc)
        return rc;
    *out = strtod(j->text + j->tok[n].start, NULL);
    return LR_OK;
}

/* Plain digits are read as an integer (exact over the whole range of long); a number with a
 * fraction or an exponent goes through a double and must be integral and below 2^53 in
 * magnitude, where every integer is exact. */
int lr_json_int(const lr_json *j, lr_jnode n, const char *field, long *out, lr_err *e)
{
    int rc = expect(j, n, field, LR_JSON_NUMBER, e);
    if (rc)
        return rc;
    const char *t = j->text + j->tok[n].start;
    int len = j->tok[n].end - j->tok[n].start;
    bool plain = true;
    for (int i = 0; i < len; i++)
        plain &= t[i] != '.' && t[i] != 'e' && t[i] != 'E';
    if (plain) {
        errno = 0;
        long v = strtol(t, NULL, 10);
        if (errno == ERANGE)
            return lr_json_fail(j, n, field, e, LR_EPARSE, "integer %.*s out of range [%ld, %ld]",
                                len, t, LONG_MIN, LONG_MAX);
        *out = v;
        return LR_OK;
    }
    double v = strtod(t, NULL);
    if (v != floor(v) || fabs(v) >= 9007199254740992.0) /* 2^53 */
        return lr_json_fail(j, n, field, e, LR_EPARSE, "expected an integer, got %.*s%s", len, t,
                            v == floor(v) ? " (with a fraction or exponent, an integer must be "
                                            "below 2^53 in magnitude)" : "");
    *out = (long)v;
    return LR_OK;
}

int lr_json_bool(const lr_json *j, lr_jnode n, const char *field, bool *out, lr_err *e)
{
    int rc = expect(j, n, field, LR_JSON_BOOL, e);
    if (rc)
        return rc;
    *out = j->text[j->tok[n].start] == 't';
    return LR_OK;
}

int lr_json_string(const lr_json *j, lr_jnode n, const char *field, char *buf, size_t cap,
                   lr_err *e)
{
    int rc = expect(j, n, field, LR_JSON_STRING, e);
    if (rc)
        return rc;
    long len = unescape(j, n, buf, cap);
    if (len == -1)
        return lr_json_fail(j, n, field, e, LR_EPARSE, "string longer than %zu bytes",
                            cap ? cap - 1 : 0);
    if (len < 0)
        return lr_json_fail(j, n, field, e, LR_EPARSE, "malformed escape in string");
    return LR_OK;
}

int lr_json_numbers(const lr_json *j, lr_jnode n, const char *field, double *out, int count,
                    lr_err *e)
{
    int rc = expect(j, n, field, LR_JSON_ARRAY, e);
    if (rc)
        return rc;
    if (lr_json_count(j, n) != count)
        return lr_json_fail(j, n, field, e, LR_EPARSE, "expected %d numbers, got %d", count,
                            lr_json_count(j, n));
    for (int i = 0; i < count; i++) {
        char sub[128];
        snprintf(sub, sizeof sub, "%s[%d]", field, i);
        rc = lr_json_number(j, lr_json_at(j, n, i), sub, &out[i], e);
        if (rc)
            return rc;
    }
    return LR_OK;
}

static int member(const lr_json *j, lr_jnode obj, const char *key, bool required, lr_jnode *v,
                  lr_err *e)
{
    int rc = expect(j, obj, "", LR_JSON_OBJECT, e);
    if (rc)
        return rc;
    *v = lr_json_get(j, obj, key);
    if (*v == LR_JNONE && required)
        return lr_json_fail(j, obj, key, e, LR_EPARSE, "missing (required)");
    return LR_OK;
}

int lr_json_get_number(const lr_json *j, lr_jnode obj, const char *key, bool required,
                       double *out, lr_err *e)
{
    lr_jnode v;
    int rc = member(j, obj, key, required, &v, e);
    if (rc || v == LR_JNONE)
        return rc;
    return lr_json_number(j, v, key, out, e);
}

int lr_json_get_int(const lr_json *j, lr_jnode obj, const char *key, bool required, long *out,
                    lr_err *e)
{
    lr_jnode v;
    int rc = member(j, obj, key, required, &v, e);
    if (rc || v == LR_JNONE)
        return rc;
    return lr_json_int(j, v, key, out, e);
}

int lr_json_get_bool(const lr_json *j, lr_jnode obj, const char *key, bool required, bool *out,
                     lr_err *e)
{
    lr_jnode v;
    int rc = member(j, obj, key, required, &v, e);
    if (rc || v == LR_JNONE)
        return rc;
    return lr_json_bool(j, v, key, out, e);
}

int lr_json_get_string(const lr_json *j, lr_jnode obj, const char *key, bool required,
                       char *buf, size_t cap, lr_err *e)
{
    lr_jnode v;
    int rc = member(j, obj, key, required, &v, e);
    if (rc || v == LR_JNONE)
        return rc;
    return lr_json_string(j, v, key, buf, cap, e);
}

int lr_json_get_numbers(const lr_json *j, lr_jnode obj, const char *key, bool required,
                        double *out, int count, lr_err *e)
{
    lr_jnode v;
    int rc = member(j, obj, key, required, &v, e);
    if (rc || v == LR_JNONE)
        return rc;
    return lr_json_numbers(j, v, key, out, count, e);
}

int lr_json_check_keys(const lr_json *j, lr_jnode obj, const char *where,
                       const char *const *allowed, lr_err *e)
{
    int rc = expect(j, obj, where, LR_JSON_OBJECT, e);
    if (rc)
        return rc;
    int count = lr_json_count(j, obj);
    for (int m = 0; m < count; m++) {
        lr_jnode k = lr_json_key_at(j, obj, m);
        char key[128];
        if (unescape(j, k, key, sizeof key) < 0)
            return lr_json_fail(j, k, where, e, LR_EPARSE, "malformed or overlong key");
        bool ok = false;
        for (const char *const *a = allowed; *a && !ok; a++)
            ok = strcmp(*a, key) == 0;
        if (!ok)
            return lr_json_fail(j, k, key, e, LR_EPARSE, "unknown field in %s", where);
    }
    return LR_OK;
}
