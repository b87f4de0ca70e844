#include "render/base/json.h"
#include "render/base/file.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define JSMN_STATIC
#define JSMN_STRICT
#define JSMN_PARENT_LINKS
#include <jsmn.h>

#define LR_JSON_MAX_BYTES (16u << 20)

struct lr_json {
    char *name;
    char *text;
    size_t len;
    jsmntok_t *tok;
    int *end; /* end[i]: index of the first token after token i's subtree */
    int count;
};

static int line_of_offset(const lr_json *j, size_t off)
{
    int line = 1;
    for (size_t i = 0; i < off && i < j->len; i++)
        if (j->text[i] == '\n')
            line++;
    return line;
}

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

/* Subtree ends, computed back to front so children are known before their parents
 * (no recursion: hostile nesting depth cannot overflow the stack). jsmn does not check that
 * every key has exactly one value ({"a": } tokenizes), so this also validates the shape.
 * Returns -1, or the index of the first malformed token. */
static int compute_ends(lr_json *j)
{
    for (int i = j->count - 1; i >= 0; i--) {
        const jsmntok_t *t = &j->tok[i];
        int k = i + 1;
        if (t->type == JSMN_OBJECT) {
            for (int m = 0; m < t->size; m++) {
                if (k + 1 >= j->count || j->tok[k].type != JSMN_STRING || j->tok[k].size != 1)
                    return k < j->count ? k : i;
                k = j->end[k + 1]; /* skip key, then the value's subtree */
            }
        } else if (t->type == JSMN_ARRAY) {
            for (int m = 0; m < t->size; m++) {
                if (k >= j->count)
                    return i;
                k = j->end[k];
            }
        } else if (t->type == JSMN_STRING && t->size > 1) {
            return i;
        }
        j->end[i] = k;
    }
    return -1;
}

int lr_json_parse(const char *text, size_t len, const char *name, lr_json **out, lr_err *e)
{
    *out = NULL;
    if (len > LR_JSON_MAX_BYTES)
        return lr_err_set(e, LR_EPARSE, "%s: larger than %u bytes", name, LR_JSON_MAX_BYTES);
    lr_json *j = calloc(1, sizeof *j);
    if (!j)
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory", name);
    j->name = strdup(name ? name : "<json>");
    j->text = malloc(len + 1);
    if (!j->name || !j->text) {
        lr_json_destroy(j);
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory", name);
    }
    memcpy(j->text, text, len);
    j->text[len] = '\0';
    j->len = len;

    jsmn_parser p;
    jsmn_init(&p);
    int n = jsmn_parse(&p, j->text, len, NULL, 0);
    if (n >= 0) {
        j->tok = calloc(n > 0 ? (size_t)n : 1, sizeof *j->tok);
        j->end = calloc(n > 0 ? (size_t)n : 1, sizeof *j->end);
        if (!j->tok || !j->end) {
            lr_json_destroy(j);
            return lr_err_set(e, LR_ENOMEM, "%s: out of memory", name);
        }
        jsmn_init(&p);
        n = jsmn_parse(&p, j->text, len, j->tok, (unsigned)n);
    }
    if (n < 0 || n == 0) {
        const char *why = n == JSMN_ERROR_PART ? "unexpected end of file (unclosed bracket or string)"
                          : n == 0             ? "empty document"
                                               : "invalid JSON";
        int line = line_of_offset(j, p.pos);
        lr_err_set(e, LR_EPARSE, "%s:%d: %s", j->name, line, why);
        lr_json_destroy(j);
        return LR_EPARSE;
    }
    j->count = n;
    int bad = compute_ends(j);
    if (bad >= 0) {
        lr_err_set(e, LR_EPARSE, "%s:%d: object member without a value", j->name,
                   line_of_offset(j, (size_t)j->tok[bad].start));
        lr_json_destroy(j);
        return LR_EPARSE;
    }
    if (j->end[0] != n) {
        lr_err_set(e, LR_EPARSE, "%s:%d: text after the top-level value", j->name,
                   line_of_offset(j, (size_t)j->tok[j->end[0]].start));
        lr_json_destroy(j);
        return LR_EPARSE;
    }
    *out = j;
    return LR_OK;
}

int lr_json_load(const char *path, lr_json **out, lr_err *e)
{
    *out = NULL;
    char *buf = NULL;
    size_t len = 0;
    int rc = lr_file_read(path, &buf, &len, e);
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
    free(j->end);
    free(j);
}

const char *lr_json_name(const lr_json *j) { return j->name; }
lr_jnode lr_json_root(const lr_json *j) { return j->count > 0 ? 0 : LR_JNONE; }

static bool valid(const lr_json *j, lr_jnode n) { return n >= 0 && n < j->count; }

enum lr_json_type lr_json_type(const lr_json *j, lr_jnode n)
{
    if (!valid(j, n))
        return LR_JSON_NONE;
    const jsmntok_t *t = &j->tok[n];
    switch (t->type) {
    case JSMN_OBJECT: return LR_JSON_OBJECT;
    case JSMN_ARRAY: return LR_JSON_ARRAY;
    case JSMN_STRING: return LR_JSON_STRING;
    case JSMN_PRIMITIVE: {
        char c = j->text[t->start];
        if (c == 't' || c == 'f')
            return LR_JSON_BOOL;
        if (c == 'n')
            return LR_JSON_NULL;
        return LR_JSON_NUMBER;
    }
    default: return LR_JSON_NONE;
    }
}

const char *lr_json_type_name(enum lr_json_type t)
{
    static const char *const names[] = {"nothing", "an object", "an array", "a string",
                                        "a number", "a boolean", "null"};
    return (unsigned)t < sizeof names / sizeof names[0] ? names[t] : "?";
}

int lr_json_line(const lr_json *j, lr_jnode n)
{
    return valid(j, n) ? line_of_offset(j, (size_t)j->tok[n].start) : 0;
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
        k = t == LR_JSON_OBJECT ? j->end[k + 1] : j->end[k];
    return t == LR_JSON_OBJECT ? k + 1 : k;
}

lr_jnode lr_json_key_at(const lr_json *j, lr_jnode obj, int i)
{
    if (lr_json_type(j, obj) != LR_JSON_OBJECT)
        return LR_JNONE;
    lr_jnode v = lr_json_at(j, obj, i);
    return v == LR_JNONE ? LR_JNONE : v - 1;
}

/* Unescapes string token n into buf (cap bytes, NUL-terminated). Returns the unescaped
 * length, -1 when it does not fit, -2 on a malformed escape. */
static long unescape(const lr_json *j, lr_jnode n, char *buf, size_t cap)
{
    const jsmntok_t *t = &j->tok[n];
    size_t o = 0;
    for (int i = t->start; i < t->end; i++) {
        unsigned char c = (unsigned char)j->text[i];
        char tmp[4];
        size_t tn = 1;
        tmp[0] = (char)c;
        if (c == '\\') {
            if (++i >= t->end)
                return -2;
            switch (j->text[i]) {
            case '"': tmp[0] = '"'; break;
            case '\\': tmp[0] = '\\'; break;
            case '/': tmp[0] = '/'; break;
            case 'b': tmp[0] = '\b'; break;
            case 'f': tmp[0] = '\f'; break;
            case 'n': tmp[0] = '\n'; break;
            case 'r': tmp[0] = '\r'; break;
            case 't': tmp[0] = '\t'; break;
            case 'u': {
                if (i + 4 >= t->end)
                    return -2;
                unsigned cp = 0;
                for (int h = 1; h <= 4; h++) {
                    char d = j->text[i + h];
                    cp <<= 4;
                    if (d >= '0' && d <= '9') cp |= (unsigned)(d - '0');
                    else if (d >= 'a' && d <= 'f') cp |= (unsigned)(d - 'a' + 10);
                    else if (d >= 'A' && d <= 'F') cp |= (unsigned)(d - 'A' + 10);
                    else return -2;
                }
                i += 4;
                if (cp == 0 || (cp >= 0xD800 && cp <= 0xDFFF))
                    return -2; /* NUL and surrogates have no place in our files */
                if (cp < 0x80) {
                    tmp[0] = (char)cp;
                } else if (cp < 0x800) {
                    tmp[0] = (char)(0xC0 | (cp >> 6));
                    tmp[1] = (char)(0x80 | (cp & 0x3F));
                    tn = 2;
                } else {
                    tmp[0] = (char)(0xE0 | (cp >> 12));
                    tmp[1] = (char)(0x80 | ((cp >> 6) & 0x3F));
                    tmp[2] = (char)(0x80 | (cp & 0x3F));
                    tn = 3;
                }
                break;
            }
            default: return -2;
            }
        }
        if (o + tn + 1 > cap)
            return -1;
        memcpy(buf + o, tmp, tn);
        o += tn;
    }
    if (cap)
        buf[o] = '\0';
    return (long)o;
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
        k = j->end[k + 1];
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

/* JSON number grammar: -?(0|[1-9][0-9]*)(.[0-9]+)?([eE][+-]?[0-9]+)? */
static bool is_json_number(const char *s)
{
    if (*s == '-')
        s++;
    if (*s == '0')
        s++;
    else if (*s >= '1' && *s <= '9')
        while (*s >= '0' && *s <= '9')
            s++;
    else
        return false;
    if (*s == '.') {
        s++;
        if (!(*s >= '0' && *s <= '9'))
            return false;
        while (*s >= '0' && *s <= '9')
            s++;
    }
    if (*s == 'e' || *s == 'E') {
        s++;
        if (*s == '+' || *s == '-')
            s++;
        if (!(*s >= '0' && *s <= '9'))
            return false;
        while (*s >= '0' && *s <= '9')
            s++;
    }
    return *s == '\0';
}

int lr_json_number(const lr_json *j, lr_jnode n, const char *field, double *out, lr_err *e)
{
    int rc = expect(j, n, field, LR_JSON_NUMBER, e);
    if (rc)
        return rc;
    const jsmntok_t *t = &j->tok[n];
    char buf[64];
    int len = t->end - t->start;
    if (len <= 0 || len >= (int)sizeof buf)
        return lr_json_fail(j, n, field, e, LR_EPARSE, "malformed number");
    memcpy(buf, j->text + t->start, (size_t)len);
    buf[len] = '\0';
    /* strtod accepts more than JSON (hex, "inf", "nan", a leading '+'): check the grammar. */
    if (!is_json_number(buf))
        return lr_json_fail(j, n, field, e, LR_EPARSE, "malformed number '%s'", buf);
    char *endp;
    errno = 0;
    double v = strtod(buf, &endp);
    if (*endp != '\0')
        return lr_json_fail(j, n, field, e, LR_EPARSE, "malformed number '%s'", buf);
    if (errno == ERANGE && fabs(v) > 1.0)
        return lr_json_fail(j, n, field, e, LR_EPARSE, "number '%s' out of range", buf);
    if (!isfinite(v))
        return lr_json_fail(j, n, field, e, LR_EPARSE, "number '%s' is not finite", buf);
    *out = v;
    return LR_OK;
}

int lr_json_int(const lr_json *j, lr_jnode n, const char *field, long *out, lr_err *e)
{
    double v;
    int rc = lr_json_number(j, n, field, &v, e);
    if (rc)
        return rc;
    if (v != floor(v) || v < (double)LONG_MIN || v > (double)LONG_MAX)
        return lr_json_fail(j, n, field, e, LR_EPARSE, "expected an integer, got %g", v);
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
        for (int p = 0; p < m; p++)
            if (lr_json_str_eq(j, lr_json_key_at(j, obj, p), key))
                return lr_json_fail(j, k, key, e, LR_EPARSE, "duplicate field in %s", where);
    }
    return LR_OK;
}
