/* Strict RFC 8259 scanner: the grammar, string and number checks, duplicate keys and the
 * nesting limit, with errors that name the file, the line and the path of the field.
 *
 * No recursion: open containers live on an explicit stack of LR_JSON_MAX_DEPTH levels, so
 * hostile nesting fails with a message instead of overflowing the C stack. */
#include "render/base/json_scan.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

typedef struct level {
    int tok; /* the open object or array */
    int key; /* object: the current member's key token, -1 before the first */
} level;

typedef struct keyref {
    const char *key; /* decoded, in the scratch arena */
    int tok;
} keyref;

typedef struct scan {
    const char *s;
    size_t len, pos;
    int line;
    const char *name;
    lr_err *e;
    lr_json_tok *tok;
    int count, cap;
    level lv[LR_JSON_MAX_DEPTH];
    int depth;
    bool after_comma; /* innermost container: a ',' was read and no member has begun */
    char *arena;      /* decoded keys of the object being closed */
    size_t arena_cap;
    keyref *refs;
    size_t refs_cap;
} scan;

/* ---- messages ------------------------------------------------------------------------------ */

static void append(char *buf, size_t cap, size_t *o, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static void append(char *buf, size_t cap, size_t *o, const char *fmt, ...)
{
    if (*o >= cap)
        return;
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(buf + *o, cap - *o, fmt, ap);
    va_end(ap);
    *o = n < 0 ? cap : *o + (size_t)n;
}

/* Appends the decoded key (shortened when long) to buf. */
static void append_key(const scan *sc, int k, char *buf, size_t cap, size_t *o)
{
    char key[96];
    if (lr_json_unescape(sc->s, sc->tok[k].start, sc->tok[k].end, key, sizeof key) < 0)
        memcpy(key + sizeof key - 4, "...", 4);
    append(buf, cap, o, "%s%s", *o ? "." : "", key);
}

/* The field path of the first `levels` open containers ("lights[2].pos"); the innermost one's
 * current member is left out when `last` is false. */
static void field_path(const scan *sc, int levels, bool last, char *buf, size_t cap)
{
    size_t o = 0;
    buf[0] = '\0';
    for (int i = 0; i < levels; i++) {
        if (i == levels - 1 && !last)
            break;
        const level *l = &sc->lv[i];
        const lr_json_tok *t = &sc->tok[l->tok];
        if (t->type == LR_JSON_OBJECT && l->key >= 0)
            append_key(sc, l->key, buf, cap, &o);
        else if (t->type == LR_JSON_ARRAY && t->size > 0)
            append(buf, cap, &o, "[%d]", t->size - 1);
    }
}

static int fail_path(scan *sc, int line, const char *path, const char *fmt, va_list ap)
{
    char msg[LR_ERR_MSG_MAX];
    vsnprintf(msg, sizeof msg, fmt, ap);
    if (path && path[0])
        return lr_err_set(sc->e, LR_EPARSE, "%s:%d: field '%s': %s", sc->name, line, path, msg);
    return lr_err_set(sc->e, LR_EPARSE, "%s:%d: %s", sc->name, line, msg);
}

/* An error at the current position, naming the member being read (the last one of the
 * innermost container, unless a ',' was just read and the next has not begun). */
static int fail(scan *sc, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int fail(scan *sc, const char *fmt, ...)
{
    char path[256];
    field_path(sc, sc->depth, !sc->after_comma, path, sizeof path);
    va_list ap;
    va_start(ap, fmt);
    int rc = fail_path(sc, sc->line, path, fmt, ap);
    va_end(ap);
    return rc;
}

/* An error naming no field (the whole document, or nesting too deep to name). */
static int fail_doc(scan *sc, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int fail_doc(scan *sc, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int rc = fail_path(sc, sc->line, NULL, fmt, ap);
    va_end(ap);
    return rc;
}

/* "'x'" for a printable ASCII byte, else "0x0c". */
static const char *show(unsigned char c, char buf[8])
{
    if (c > 0x20 && c < 0x7f)
        snprintf(buf, 8, "'%c'", c);
    else
        snprintf(buf, 8, "0x%02x", c);
    return buf;
}

/* A token's text for a message, cut at 40 bytes. */
#define SHOWN(n) ((int)((n) > 40 ? 40 : (n)))
#define MORE(n) ((n) > 40 ? "..." : "")

static bool names_nan_or_inf(const char *w, size_t n)
{
    if (n && (w[0] == '-' || w[0] == '+'))
        w++, n--;
    return (n == 3 && (strncasecmp(w, "nan", 3) == 0 || strncasecmp(w, "inf", 3) == 0)) ||
           (n == 8 && strncasecmp(w, "infinity", 8) == 0);
}

/* ---- tokens -------------------------------------------------------------------------------- */

static int push(scan *sc, enum lr_json_type type, size_t start, int *idx)
{
    if (sc->count == sc->cap) {
        if (sc->cap > INT_MAX / 4)
            return lr_err_set(sc->e, LR_ENOMEM, "%s: too many values", sc->name);
        int cap = sc->cap ? 2 * sc->cap : 64;
        lr_json_tok *t = realloc(sc->tok, (size_t)cap * sizeof *t);
        if (!t)
            return lr_err_set(sc->e, LR_ENOMEM, "%s: out of memory", sc->name);
        sc->tok = t;
        sc->cap = cap;
    }
    *idx = sc->count++;
    sc->tok[*idx] = (lr_json_tok){.start = (int)start, .end = (int)start, .size = 0,
                                  .next = *idx + 1, .line = sc->line, .type = type};
    return LR_OK;
}

/* ---- strings ------------------------------------------------------------------------------- */

static int hex4(const char *s, size_t avail)
{
    if (avail < 4)
        return -1;
    int v = 0;
    for (int i = 0; i < 4; i++) {
        char d = s[i];
        v <<= 4;
        if (d >= '0' && d <= '9')
            v |= d - '0';
        else if (d >= 'a' && d <= 'f')
            v |= d - 'a' + 10;
        else if (d >= 'A' && d <= 'F')
            v |= d - 'A' + 10;
        else
            return -1;
    }
    return v;
}

/* Length of the well-formed UTF-8 sequence at s (RFC 3629: no overlongs, no encoded
 * surrogates, nothing past U+10FFFF), or 0. */
static size_t utf8_len(const unsigned char *s, size_t avail)
{
    unsigned char c = s[0];
    size_t n;
    unsigned char lo = 0x80, hi = 0xBF; /* allowed range of the second byte */
    if (c >= 0xC2 && c <= 0xDF)
        n = 2;
    else if (c >= 0xE0 && c <= 0xEF)
        n = 3, lo = c == 0xE0 ? 0xA0 : 0x80, hi = c == 0xED ? 0x9F : 0xBF;
    else if (c >= 0xF0 && c <= 0xF4)
        n = 4, lo = c == 0xF0 ? 0x90 : 0x80, hi = c == 0xF4 ? 0x8F : 0xBF;
    else
        return 0;
    if (avail < n || s[1] < lo || s[1] > hi)
        return 0;
    for (size_t i = 2; i < n; i++)
        if ((s[i] & 0xC0) != 0x80)
            return 0;
    return n;
}

/* A string at sc->pos (the opening quote); pushes a STRING token. */
static int scan_string(scan *sc, int *idx)
{
    const unsigned char *s = (const unsigned char *)sc->s;
    size_t start = sc->pos + 1, p = start;
    char c8[8];
    for (;;) {
        if (p >= sc->len)
            return fail(sc, "unexpected end of file in a string (missing closing quote?)");
        unsigned char c = s[p];
        if (c == '"')
            break;
        if (c == '\\') {
            if (p + 1 >= sc->len)
                return fail(sc, "unexpected end of file in a string (missing closing quote?)");
            unsigned char x = s[p + 1];
            if (x && strchr("\"\\/bfnrt", x)) {
                p += 2;
                continue;
            }
            if (x != 'u' && x > 0x20 && x < 0x7f)
                return fail(sc, "invalid escape '\\%c' in string", x);
            if (x != 'u')
                return fail(sc, "invalid escape: '\\' then byte %s in string", show(x, c8));
            size_t avail = sc->len - (p + 2);
            int cp = hex4(sc->s + p + 2, avail);
            if (cp < 0)
                return fail(sc, "invalid escape '\\u%.*s' in string", (int)(avail < 4 ? avail : 4),
                            sc->s + p + 2);
            if (cp == 0)
                return fail(sc, "'\\u0000' in string (not supported: our strings end at NUL)");
            if (cp >= 0xD800 && cp <= 0xDBFF) {
                /* A high surrogate must be followed by an escaped low one (one code point). */
                int lo = p + 7 < sc->len && s[p + 6] == '\\' && s[p + 7] == 'u'
                             ? hex4(sc->s + p + 8, sc->len - (p + 8)) : -1;
                if (lo < 0xDC00 || lo > 0xDFFF)
                    return fail(sc, "unpaired surrogate '\\u%.4s' in string", sc->s + p + 2);
                p += 12;
                continue;
            }
            if (cp >= 0xDC00 && cp <= 0xDFFF)
                return fail(sc, "unpaired surrogate '\\u%.4s' in string", sc->s + p + 2);
            p += 6;
            continue;
        }
        if (c == '\n' || c == '\r')
            return fail(sc, "line break in string (missing closing quote?)");
        if (c < 0x20)
            return fail(sc, "control character 0x%02x in string (write it as an escape: \\t, "
                            "\\u00%02x)", c, c);
        if (c < 0x80) {
            p++;
            continue;
        }
        size_t n = utf8_len(s + p, sc->len - p);
        if (!n)
            return fail(sc, "invalid UTF-8 in string (byte 0x%02x)", c);
        p += n;
    }
    int rc = push(sc, LR_JSON_STRING, start, idx);
    if (rc)
        return rc;
    sc->tok[*idx].end = (int)p;
    sc->pos = p + 1;
    return LR_OK;
}

long lr_json_unescape(const char *text, int start, int end, char *buf, size_t cap)
{
    size_t o = 0;
    for (int i = start; i < end; i++) {
        char tmp[4];
        size_t tn = 1;
        tmp[0] = text[i];
        if (text[i] == '\\' && i + 1 < end) {
            char x = text[++i];
            switch (x) {
            case 'b': tmp[0] = '\b'; break;
            case 'f': tmp[0] = '\f'; break;
            case 'n': tmp[0] = '\n'; break;
            case 'r': tmp[0] = '\r'; break;
            case 't': tmp[0] = '\t'; break;
            case 'u': {
                long cp = hex4(text + i + 1, (size_t)(end - i - 1));
                if (cp < 0)
                    return -1; /* the scanner let no such string through */
                i += 4;
                long lo = cp >= 0xD800 && cp <= 0xDBFF && i + 6 < end && text[i + 1] == '\\'
                              ? hex4(text + i + 3, (size_t)(end - i - 3)) : -1;
                if (lo >= 0xDC00 && lo <= 0xDFFF) { /* a pair: one code point past U+FFFF */
                    cp = 0x10000 + ((cp - 0xD800) << 10) + (lo - 0xDC00);
                    i += 6;
                }
                if (cp < 0x80) {
                    tmp[0] = (char)cp;
                } else if (cp < 0x800) {
                    tmp[0] = (char)(0xC0 | (cp >> 6));
                    tmp[1] = (char)(0x80 | (cp & 0x3F));
                    tn = 2;
                } else if (cp < 0x10000) {
                    tmp[0] = (char)(0xE0 | (cp >> 12));
                    tmp[1] = (char)(0x80 | ((cp >> 6) & 0x3F));
                    tmp[2] = (char)(0x80 | (cp & 0x3F));
                    tn = 3;
                } else {
                    tmp[0] = (char)(0xF0 | (cp >> 18));
                    tmp[1] = (char)(0x80 | ((cp >> 12) & 0x3F));
                    tmp[2] = (char)(0x80 | ((cp >> 6) & 0x3F));
                    tmp[3] = (char)(0x80 | (cp & 0x3F));
                    tn = 4;
                }
                break;
            }
            default: tmp[0] = x; break; /* '"', '\\', '/' */
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

/* ---- numbers and literals ------------------------------------------------------------------ */

static bool word_char(char c)
{
    return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
           c == '+' || c == '-' || c == '.' || c == '_';
}

static bool digit(char c) { return c >= '0' && c <= '9'; }

/* A number at sc->pos: the grammar -?(0|[1-9][0-9]*)(.[0-9]+)?([eE][+-]?[0-9]+)?, then its
 * value, which must be a finite double that is not 0 unless the number is 0. */
static int scan_number(scan *sc, int *idx)
{
    const char *t = sc->s + sc->pos;
    size_t n = 0;
    while (sc->pos + n < sc->len && word_char(t[n]))
        n++;
    size_t i = 0;
    bool ok = true, nonzero = false;
    if (t[i] == '-')
        i++;
    if (i < n && t[i] == '0') {
        i++;
        if (i < n && digit(t[i]))
            return fail(sc, "leading zero in number '%.*s%s'", SHOWN(n), t, MORE(n));
    } else if (i < n && digit(t[i])) {
        while (i < n && digit(t[i]))
            nonzero |= t[i++] != '0';
    } else {
        ok = false;
    }
    if (ok && i < n && t[i] == '.') {
        ok = ++i < n && digit(t[i]);
        while (i < n && digit(t[i]))
            nonzero |= t[i++] != '0';
    }
    if (ok && i < n && (t[i] == 'e' || t[i] == 'E')) {
        i++;
        if (i < n && (t[i] == '+' || t[i] == '-'))
            i++;
        ok = i < n && digit(t[i]);
        while (i < n && digit(t[i]))
            i++;
    }
    if (!ok || i != n)
        return fail(sc, "malformed number '%.*s%s'%s", SHOWN(n), t, MORE(n),
                    names_nan_or_inf(t, n) ? " (JSON has no NaN or Infinity)" : "");
    /* strtod stops at the byte after the number: it is not a word character. */
    char *endp;
    errno = 0;
    double v = strtod(t, &endp);
    if (endp != t + n)
        return fail(sc, "malformed number '%.*s%s'", SHOWN(n), t, MORE(n));
    if (isinf(v))
        return fail(sc, "number '%.*s%s' overflows a double (largest about 1.8e308)", SHOWN(n), t,
                    MORE(n));
    /* A subnormal result (below 2.2e-308) is kept: a finite double with fewer significant
     * bits. A nonzero number that rounds to 0 is refused: it would silently read as 0. */
    if (v == 0 && nonzero)
        return fail(sc, "number '%.*s%s' underflows a double (it would read as 0; the smallest "
                        "is about 4.9e-324)", SHOWN(n), t, MORE(n));
    int rc = push(sc, LR_JSON_NUMBER, sc->pos, idx);
    if (rc)
        return rc;
    sc->pos += n;
    sc->tok[*idx].end = (int)sc->pos;
    return LR_OK;
}

/* true, false or null at sc->pos; any other bare word is an error. */
static int scan_literal(scan *sc, int *idx)
{
    const char *w = sc->s + sc->pos;
    size_t n = 0;
    while (sc->pos + n < sc->len && word_char(w[n]))
        n++;
    enum lr_json_type type;
    if (n == 4 && memcmp(w, "true", 4) == 0)
        type = LR_JSON_BOOL;
    else if (n == 5 && memcmp(w, "false", 5) == 0)
        type = LR_JSON_BOOL;
    else if (n == 4 && memcmp(w, "null", 4) == 0)
        type = LR_JSON_NULL;
    else
        return fail(sc, "invalid literal '%.*s%s'%s", SHOWN(n), w, MORE(n),
                    names_nan_or_inf(w, n) ? " (JSON has no NaN or Infinity)"
                                           : " (expected true, false or null)");
    int rc = push(sc, type, sc->pos, idx);
    if (rc)
        return rc;
    sc->pos += n;
    sc->tok[*idx].end = (int)sc->pos;
    return LR_OK;
}

/* ---- duplicate keys ------------------------------------------------------------------------ */

static int cmp_keyref(const void *a, const void *b)
{
    const keyref *x = a, *y = b;
    int c = strcmp(x->key, y->key);
    return c ? c : (x->tok > y->tok) - (x->tok < y->tok);
}

/* Object obj (the innermost open container) is complete: refuse a key given twice. Sorting
 * keeps this O(m log m) for an object of m members. */
static int check_duplicates(scan *sc, int obj)
{
    size_t m = (size_t)sc->tok[obj].size, bytes = 0;
    if (m < 2)
        return LR_OK;
    for (int k = obj + 1, i = 0; i < (int)m; i++, k = sc->tok[k + 1].next)
        bytes += (size_t)(sc->tok[k].end - sc->tok[k].start) + 1;
    if (bytes > sc->arena_cap) {
        char *a = realloc(sc->arena, bytes);
        if (!a)
            return lr_err_set(sc->e, LR_ENOMEM, "%s: out of memory", sc->name);
        sc->arena = a;
        sc->arena_cap = bytes;
    }
    if (m > sc->refs_cap) {
        keyref *r = realloc(sc->refs, m * sizeof *r);
        if (!r)
            return lr_err_set(sc->e, LR_ENOMEM, "%s: out of memory", sc->name);
        sc->refs = r;
        sc->refs_cap = m;
    }
    size_t o = 0;
    for (int k = obj + 1, i = 0; i < (int)m; i++, k = sc->tok[k + 1].next) {
        long n = lr_json_unescape(sc->s, sc->tok[k].start, sc->tok[k].end, sc->arena + o,
                                  sc->arena_cap - o);
        sc->refs[i] = (keyref){.key = sc->arena + o, .tok = k};
        o += (size_t)(n < 0 ? 0 : n) + 1;
    }
    qsort(sc->refs, m, sizeof *sc->refs, cmp_keyref);
    int first = -1, second = INT_MAX;
    for (size_t i = 0; i + 1 < m; i++)
        if (strcmp(sc->refs[i].key, sc->refs[i + 1].key) == 0 && sc->refs[i + 1].tok < second)
            first = sc->refs[i].tok, second = sc->refs[i + 1].tok;
    if (first < 0)
        return LR_OK;
    char path[256];
    field_path(sc, sc->depth - 1, true, path, sizeof path);
    size_t po = strlen(path);
    append_key(sc, second, path, sizeof path, &po);
    return lr_err_set(sc->e, LR_EPARSE, "%s:%d: field '%s': duplicate key (first on line %d)",
                      sc->name, sc->tok[second].line, path, sc->tok[first].line);
}

/* ---- the grammar --------------------------------------------------------------------------- */

static void skip_ws(scan *sc)
{
    while (sc->pos < sc->len) {
        char c = sc->s[sc->pos];
        if (c == '\n')
            sc->line++;
        else if (c != ' ' && c != '\t' && c != '\r')
            return;
        sc->pos++;
    }
}

enum state {
    VALUE,          /* a value must come */
    VALUE_OR_CLOSE, /* just after '[' */
    KEY,            /* after ',' in an object */
    KEY_OR_CLOSE,   /* just after '{' */
    AFTER_VALUE,    /* a value ended: ',' or the closing bracket, or the end of the text */
};

static int open_container(scan *sc, enum lr_json_type type, enum state *st)
{
    if (sc->depth == LR_JSON_MAX_DEPTH)
        return fail_doc(sc, "nesting deeper than %d levels", LR_JSON_MAX_DEPTH);
    int idx;
    int rc = push(sc, type, sc->pos, &idx);
    if (rc)
        return rc;
    sc->lv[sc->depth++] = (level){.tok = idx, .key = -1};
    sc->pos++;
    *st = type == LR_JSON_OBJECT ? KEY_OR_CLOSE : VALUE_OR_CLOSE;
    return LR_OK;
}

static int close_container(scan *sc)
{
    int idx = sc->lv[sc->depth - 1].tok;
    sc->pos++;
    sc->tok[idx].end = (int)sc->pos;
    sc->tok[idx].next = sc->count;
    sc->after_comma = false;
    if (sc->tok[idx].type == LR_JSON_OBJECT) {
        int rc = check_duplicates(sc, idx);
        if (rc)
            return rc;
    }
    sc->depth--;
    return LR_OK;
}

static int unexpected_eof(scan *sc)
{
    const lr_json_tok *t = &sc->tok[sc->lv[sc->depth - 1].tok];
    sc->after_comma = true; /* name the open container, not its last member */
    return fail(sc, "unexpected end of file ('%c' from line %d is not closed)",
                t->type == LR_JSON_OBJECT ? '{' : '[', t->line);
}

static int value(scan *sc, enum state *st)
{
    char b8[8];
    if (sc->pos >= sc->len) {
        if (sc->depth == 0)
            return fail_doc(sc, "empty document");
        return fail(sc, "unexpected end of file (expected a value)");
    }
    char c = sc->s[sc->pos];
    if ((c == ']' || c == '}') && sc->after_comma)
        return fail(sc, "trailing comma before '%c'", c);
    if (sc->depth > 0) {
        level *l = &sc->lv[sc->depth - 1];
        if (sc->tok[l->tok].type == LR_JSON_ARRAY)
            sc->tok[l->tok].size++;
    }
    sc->after_comma = false;
    int idx, rc;
    if (c == '{')
        return open_container(sc, LR_JSON_OBJECT, st);
    if (c == '[')
        return open_container(sc, LR_JSON_ARRAY, st);
    if (c == '"')
        rc = scan_string(sc, &idx);
    else if (c == '-' || digit(c))
        rc = scan_number(sc, &idx);
    else if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'))
        rc = scan_literal(sc, &idx);
    else if (c == ',' || c == ':' || c == ']' || c == '}')
        return fail(sc, "expected a value, got '%c'", c);
    else
        return fail(sc, "unexpected character %s%s", show((unsigned char)c, b8),
                    c == '\'' ? " (strings take double quotes)" : "");
    *st = AFTER_VALUE;
    return rc;
}

static int key(scan *sc, enum state *st)
{
    char b8[8];
    if (sc->pos >= sc->len)
        return unexpected_eof(sc);
    char c = sc->s[sc->pos];
    if (c == '}' && sc->after_comma)
        return fail(sc, "trailing comma before '}'");
    if (c != '"')
        return fail(sc, "expected a key in double quotes, got %s", show((unsigned char)c, b8));
    level *l = &sc->lv[sc->depth - 1];
    int idx;
    int rc = scan_string(sc, &idx);
    if (rc)
        return rc;
    sc->tok[l->tok].size++;
    l->key = idx;
    sc->after_comma = false;
    skip_ws(sc);
    if (sc->pos >= sc->len)
        return fail(sc, "unexpected end of file (expected ':' and a value)");
    if (sc->s[sc->pos] != ':')
        return fail(sc, "expected ':' after the key, got %s",
                    show((unsigned char)sc->s[sc->pos], b8));
    sc->pos++;
    *st = VALUE;
    return LR_OK;
}

static int after_value(scan *sc, enum state *st, bool *done)
{
    char b8[8];
    if (sc->depth == 0) {
        if (sc->pos < sc->len)
            return fail_doc(sc, "text after the top-level value");
        *done = true;
        return LR_OK;
    }
    if (sc->pos >= sc->len)
        return unexpected_eof(sc);
    bool obj = sc->tok[sc->lv[sc->depth - 1].tok].type == LR_JSON_OBJECT;
    char c = sc->s[sc->pos];
    if (c == ',') {
        sc->pos++;
        sc->after_comma = true;
        *st = obj ? KEY : VALUE;
        return LR_OK;
    }
    if (c == (obj ? '}' : ']'))
        return close_container(sc);
    return fail(sc, obj ? "expected ',' or '}' after a member, got %s"
                        : "expected ',' or ']' after an element, got %s",
                show((unsigned char)c, b8));
}

int lr_json_scan(const char *text, size_t len, const char *name, lr_json_tok **tok, int *count,
                 lr_err *e)
{
    *tok = NULL;
    *count = 0;
    if (len > (size_t)INT_MAX / 2)
        return lr_err_set(e, LR_EPARSE, "%s: too large", name);
    scan *sc = calloc(1, sizeof *sc);
    if (!sc)
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory", name);
    *sc = (scan){.s = text, .len = len, .line = 1, .name = name, .e = e};
    /* A UTF-8 byte-order mark may be ignored (RFC 8259 section 8.1). */
    if (len >= 3 && memcmp(text, "\xef\xbb\xbf", 3) == 0)
        sc->pos = 3;
    enum state st = VALUE;
    bool done = false;
    int rc = LR_OK;
    while (!rc && !done) {
        skip_ws(sc);
        switch (st) {
        case VALUE_OR_CLOSE:
            if (sc->pos < sc->len && sc->s[sc->pos] == ']') {
                rc = close_container(sc);
                st = AFTER_VALUE;
                break;
            }
            rc = value(sc, &st);
            break;
        case VALUE: rc = value(sc, &st); break;
        case KEY_OR_CLOSE:
            if (sc->pos < sc->len && sc->s[sc->pos] == '}') {
                rc = close_container(sc);
                st = AFTER_VALUE;
                break;
            }
            rc = key(sc, &st);
            break;
        case KEY: rc = key(sc, &st); break;
        case AFTER_VALUE: rc = after_value(sc, &st, &done); break;
        }
    }
    free(sc->arena);
    free(sc->refs);
    if (rc) {
        free(sc->tok);
    } else {
        *tok = sc->tok;
        *count = sc->count;
    }
    free(sc);
    return rc;
}
