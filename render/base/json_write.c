#include "render/base/json_write.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define JW_DEPTH 32

struct lr_jw {
    FILE *f;
    int depth;
    bool is_array[JW_DEPTH];
    int count[JW_DEPTH]; /* members written at each level */
    int line_items;      /* numbers on the current line of a compact array */
    lr_err err;
};

lr_jw *lr_jw_create(FILE *f)
{
    lr_jw *w = calloc(1, sizeof *w);
    if (w)
        w->f = f;
    return w;
}

static bool failed(const lr_jw *w) { return w->err.code != LR_OK; }

static void indent(lr_jw *w)
{
    fputc('\n', w->f);
    for (int i = 0; i < w->depth; i++)
        fputs("  ", w->f);
}

static void put_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
        switch (*p) {
        case '"': fputs("\\\"", f); break;
        case '\\': fputs("\\\\", f); break;
        case '\n': fputs("\\n", f); break;
        case '\t': fputs("\\t", f); break;
        case '\r': fputs("\\r", f); break;
        default:
            if (*p < 0x20)
                fprintf(f, "\\u%04x", *p);
            else
                fputc(*p, f);
        }
    }
    fputc('"', f);
}

/* Separator, newline + indentation, and the key when inside an object. */
static bool begin_value(lr_jw *w, const char *key)
{
    if (failed(w))
        return false;
    if (w->depth > 0) {
        bool in_array = w->is_array[w->depth - 1];
        if (in_array && key) {
            lr_err_set(&w->err, LR_EINVAL, "JSON writer: key '%s' inside an array", key);
            return false;
        }
        if (!in_array && !key) {
            lr_err_set(&w->err, LR_EINVAL, "JSON writer: member without a key");
            return false;
        }
        if (w->count[w->depth - 1]++ > 0)
            fputc(',', w->f);
        indent(w);
        if (key) {
            put_string(w->f, key);
            fputs(": ", w->f);
        }
    } else if (key) {
        lr_err_set(&w->err, LR_EINVAL, "JSON writer: key '%s' at the top level", key);
        return false;
    }
    return true;
}

static void open_level(lr_jw *w, const char *key, bool array)
{
    if (!begin_value(w, key))
        return;
    if (w->depth >= JW_DEPTH) {
        lr_err_set(&w->err, LR_EINVAL, "JSON writer: nesting deeper than %d", JW_DEPTH);
        return;
    }
    fputc(array ? '[' : '{', w->f);
    w->is_array[w->depth] = array;
    w->count[w->depth] = 0;
    w->depth++;
}

static void close_level(lr_jw *w, bool array)
{
    if (failed(w))
        return;
    if (w->depth == 0 || w->is_array[w->depth - 1] != array) {
        lr_err_set(&w->err, LR_EINVAL, "JSON writer: mismatched %s", array ? "']'" : "'}'");
        return;
    }
    w->depth--;
    if (w->count[w->depth] > 0)
        indent(w);
    fputc(array ? ']' : '}', w->f);
}

void lr_jw_object(lr_jw *w, const char *key) { open_level(w, key, false); }
void lr_jw_object_end(lr_jw *w) { close_level(w, false); }
void lr_jw_array(lr_jw *w, const char *key) { open_level(w, key, true); }
void lr_jw_array_end(lr_jw *w) { close_level(w, true); }

/* Shortest of %.15g..%.17g that reads back exactly. */
static void put_number(FILE *f, double v)
{
    char buf[40];
    for (int prec = 15; prec <= 17; prec++) {
        snprintf(buf, sizeof buf, "%.*g", prec, v);
        if (strtod(buf, NULL) == v)
            break;
    }
    fputs(buf, f);
}

static bool check_finite(lr_jw *w, const char *key, double v)
{
    if (failed(w))
        return false;
    if (!isfinite(v)) {
        lr_err_set(&w->err, LR_EINVAL, "field '%s': value is not finite (%g)",
                   key ? key : "(array element)", v);
        return false;
    }
    return true;
}

void lr_jw_number(lr_jw *w, const char *key, double v)
{
    if (check_finite(w, key, v) && begin_value(w, key))
        put_number(w->f, v);
}

void lr_jw_number_or_null(lr_jw *w, const char *key, double v)
{
    if (!isfinite(v))
        lr_jw_null(w, key);
    else
        lr_jw_number(w, key, v);
}

void lr_jw_null(lr_jw *w, const char *key)
{
    if (begin_value(w, key))
        fputs("null", w->f);
}

void lr_jw_int(lr_jw *w, const char *key, long v)
{
    if (begin_value(w, key))
        fprintf(w->f, "%ld", v);
}

void lr_jw_bool(lr_jw *w, const char *key, bool v)
{
    if (begin_value(w, key))
        fputs(v ? "true" : "false", w->f);
}

void lr_jw_string(lr_jw *w, const char *key, const char *s)
{
    if (begin_value(w, key))
        put_string(w->f, s ? s : "");
}

void lr_jw_numbers(lr_jw *w, const char *key, const double *v, int n)
{
    for (int i = 0; i < n; i++)
        if (!check_finite(w, key, v[i]))
            return;
    if (!begin_value(w, key))
        return;
    fputc('[', w->f);
    for (int i = 0; i < n; i++) {
        if (i > 0) {
            fputc(',', w->f);
            /* Eight numbers a line keeps 256-entry tables readable in an editor. */
            if (i % 8 == 0) {
                w->depth++;
                indent(w);
                w->depth--;
            } else {
                fputc(' ', w->f);
            }
        }
        put_number(w->f, v[i]);
    }
    fputc(']', w->f);
}

void lr_jw_matrix(lr_jw *w, const char *key, const double *m, int rows, int cols)
{
    lr_jw_array(w, key);
    for (int r = 0; r < rows; r++)
        lr_jw_numbers(w, NULL, m + (size_t)r * (size_t)cols, cols);
    lr_jw_array_end(w);
}

int lr_jw_finish(lr_jw *w, lr_err *e)
{
    int rc = LR_OK;
    if (failed(w))
        rc = lr_err_set(e, w->err.code, "%s", w->err.msg);
    else if (w->depth != 0)
        rc = lr_err_set(e, LR_EINVAL, "JSON writer: %d unclosed levels", w->depth);
    else {
        fputc('\n', w->f);
        if (ferror(w->f))
            rc = lr_err_set(e, LR_EIO, "JSON writer: stream error");
    }
    free(w);
    return rc;
}
