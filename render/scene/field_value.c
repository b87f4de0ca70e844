/* Field values as text, for lr_scene_set and lr_scene_get (fields.h): the value syntax of
 * `--set`, event scripts and the control map -- numbers as in JSON (strict: no hex, nan, inf),
 * vectors "x,y,z" or "[x,y,z]", names bare, true/false. */
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "render/scene/fields.h"
#include "render/scene/scene_internal.h"

static void *at(void *rec, size_t off)
{
    return lr_field_ptr(rec, off);
}

/* ---- get and set from text --------------------------------------------------------------------- */

int lr_field_fail(lr_field_op *o, int code, const char *fmt, ...)
{
    char msg[LR_ERR_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return lr_err_set(o->e, code, "%s: %s", o->key, msg);
}

int lr_field_out(lr_field_op *o, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(o->buf, o->cap, fmt, ap);
    va_end(ap);
    if (n < 0 || (size_t)n >= o->cap)
        return lr_field_fail(o, LR_EINVAL, "value does not fit the %zu-byte buffer", o->cap);
    return LR_OK;
}

/* Shortest "%.Ng" that reads back as the same double. */
static void fmt_num(char *b, size_t cap, double v)
{
    for (int p = 6; p <= 17; p++) {
        snprintf(b, cap, "%.*g", p, v);
        if (strtod(b, NULL) == v)
            return;
    }
}

/* Parses a list value "x,y,z" or "[x,y,z]" into count numbers, as a JSON array (strict
 * numbers: no hex, nan, inf or leading '+'). */
static bool value_numbers(const lr_field_op *o, double *v, int count)
{
    char text[512];
    const char *s = o->value;
    while (*s == ' ')
        s++;
    int n = s[0] != '[' ? snprintf(text, sizeof text, "[%s]", s)
                        : snprintf(text, sizeof text, "%s", s);
    if (n < 0 || (size_t)n >= sizeof text)
        return false;
    lr_json *j = NULL;
    bool ok = lr_json_parse(text, (size_t)n, o->key, &j, NULL) == LR_OK &&
              lr_json_numbers(j, lr_json_root(j), o->key, v, count, NULL) == LR_OK;
    lr_json_destroy(j);
    return ok;
}

/* The value as one JSON number, read as the only element of an array (so "1,2" is two
 * numbers and refused here). */
static bool value_number(const lr_field_op *o, double *v)
{
    char text[512];
    int n = snprintf(text, sizeof text, "[%s]", o->value);
    lr_json *j = NULL;
    bool ok = n > 0 && (size_t)n < sizeof text &&
              lr_json_parse(text, (size_t)n, o->key, &j, NULL) == LR_OK &&
              lr_json_count(j, lr_json_root(j)) == 1 &&
              lr_json_type(j, lr_json_at(j, lr_json_root(j), 0)) == LR_JSON_NUMBER &&
              lr_json_number(j, lr_json_at(j, lr_json_root(j), 0), o->key, v, NULL) == LR_OK;
    lr_json_destroy(j);
    return ok;
}

static int out_nums(lr_field_op *o, const double *v, int n)
{
    char b[3][40];
    for (int i = 0; i < n; i++)
        fmt_num(b[i], sizeof b[i], v[i]);
    return n == 1 ? lr_field_out(o, "%s", b[0])
           : n == 2 ? lr_field_out(o, "%s,%s", b[0], b[1])
                    : lr_field_out(o, "%s,%s,%s", b[0], b[1], b[2]);
}

static int get_field(lr_field_op *o, const lr_field *f, void *rec)
{
    void *p = at(rec, f->off);
    switch (f->type) {
    case LR_FT_NUM: {
        double v = (f->flags & LR_FF_ZERO_FLAG) && *(bool *)at(rec, f->aux) ? 0.0
                                                                           : *(double *)p;
        return out_nums(o, &v, 1);
    }
    case LR_FT_INT: return lr_field_out(o, "%d", *(int *)p);
    case LR_FT_UINT: return lr_field_out(o, "%d", (int)*(unsigned *)p);
    case LR_FT_VEC3: {
        lr_vec3 x = *(lr_vec3 *)p;
        return out_nums(o, (double[3]){x.x, x.y, x.z}, 3);
    }
    case LR_FT_SCALE: {
        lr_vec3 x = *(lr_vec3 *)p;
        return x.x == x.y && x.y == x.z ? out_nums(o, &x.x, 1)
                                        : out_nums(o, (double[3]){x.x, x.y, x.z}, 3);
    }
    case LR_FT_RGB:
    case LR_FT_SIZE3: return out_nums(o, (double *)p, 3);
    case LR_FT_PAIR: return out_nums(o, (double *)p, 2);
    case LR_FT_BOOL:
        return lr_field_out(o, "%s", *(bool *)p != !!(f->flags & LR_FF_INVERT) ? "true" : "false");
    case LR_FT_ENUM: return lr_field_out(o, "%s", f->names[*(int *)p]);
    case LR_FT_ENUMB: return lr_field_out(o, "%s", f->names[*(bool *)p ? 1 : 0]);
    case LR_FT_PATH: return lr_field_out(o, "%s", (char *)p);
    default: return lr_field_fail(o, LR_EINVAL, "not a parameter");
    }
}

static int set_field(lr_field_op *o, const lr_field *f, void *rec)
{
    void *p = at(rec, f->off);
    double v[3];
    switch (f->type) {
    case LR_FT_NUM:
        if (!value_number(o, &v[0]))
            return lr_field_fail(o, LR_EPARSE, "expected a number, got '%s'", o->value);
        if (f->flags & LR_FF_ZERO_FLAG)
            *(bool *)at(rec, f->aux) = v[0] == 0.0;
        if (v[0] == 0.0 && (f->flags & LR_FF_ZERO_DEFAULT))
            v[0] = f->dflt[0];
        *(double *)p = v[0];
        return LR_OK;
    case LR_FT_INT:
    case LR_FT_UINT:
        if (!value_number(o, &v[0]))
            return lr_field_fail(o, LR_EPARSE, "expected a number, got '%s'", o->value);
        if (v[0] != floor(v[0]) || fabs(v[0]) > 1e9)
            return lr_field_fail(o, LR_EPARSE, "expected an integer, got '%s'", o->value);
        if (f->type == LR_FT_UINT) {
            if (v[0] < 0)
                return lr_field_fail(o, LR_EINVAL, "must be >= 0, got %d", (int)v[0]);
            *(unsigned *)p = (unsigned)v[0];
            return LR_OK;
        }
        if (v[0] == 0.0 && (f->flags & LR_FF_ZERO_DEFAULT))
            v[0] = f->dflt[0];
        *(int *)p = (int)v[0];
        return LR_OK;
    case LR_FT_VEC3:
    case LR_FT_RGB:
    case LR_FT_SIZE3:
        if (!value_numbers(o, v, 3))
            return lr_field_fail(o, LR_EPARSE, "expected x,y,z (three numbers), got '%s'", o->value);
        if (f->type == LR_FT_VEC3)
            *(lr_vec3 *)p = lr_v3(v[0], v[1], v[2]);
        else
            memcpy(p, v, sizeof v);
        return LR_OK;
    case LR_FT_PAIR:
        if (!value_numbers(o, v, 2))
            return lr_field_fail(o, LR_EPARSE, "expected w,h (two numbers), got '%s'", o->value);
        memcpy(p, v, 2 * sizeof(double));
        return LR_OK;
    case LR_FT_SCALE:
        if (value_number(o, &v[0]))
            v[1] = v[2] = v[0];
        else if (!value_numbers(o, v, 3))
            return lr_field_fail(o, LR_EPARSE, "expected a number or x,y,z, got '%s'", o->value);
        *(lr_vec3 *)p = lr_v3(v[0], v[1], v[2]);
        return LR_OK;
    case LR_FT_BOOL: {
        bool b;
        if (strcmp(o->value, "true") == 0)
            b = true;
        else if (strcmp(o->value, "false") == 0)
            b = false;
        else
            return lr_field_fail(o, LR_EPARSE, "expected true or false, got '%s'", o->value);
        *(bool *)p = b != !!(f->flags & LR_FF_INVERT);
        return LR_OK;
    }
    case LR_FT_ENUM:
    case LR_FT_ENUMB: {
        for (int i = 0; f->names[i]; i++)
            if (strcmp(o->value, f->names[i]) == 0) {
                if (f->type == LR_FT_ENUM)
                    *(int *)p = i;
                else
                    *(bool *)p = i == 1;
                return LR_OK;
            }
        char list[256];
        lr_field_names_text(f->names, " or ", list, sizeof list);
        return lr_field_fail(o, LR_EINVAL, "expected %s, got '%s'", list, o->value);
    }
    case LR_FT_PATH:
        if (!o->value[0] || strlen(o->value) >= LR_SCENE_PATH_MAX)
            return lr_field_fail(o, LR_EINVAL, "expected a file path");
        snprintf((char *)p, LR_SCENE_PATH_MAX, "%s", o->value);
        return LR_OK;
    default: return lr_field_fail(o, LR_EINVAL, "not a parameter");
    }
}

int lr_field_apply(lr_field_op *o, const lr_field *f, void *rec)
{
    return o->get ? get_field(o, f, rec) : set_field(o, f, rec);
}

int lr_fields_unknown(lr_field_op *o, const lr_record_desc *d, int kind, const char *field)
{
    char known[512] = "";
    size_t len = 0;
    const char *group = NULL; /* the open "prefix.{" group */
    size_t glen = 0;
    for (int i = 0; i < d->n; i++) {
        const lr_field *f = &d->fields[i];
        if (!lr_field_has(f, kind) || (f->flags & LR_FF_NO_SET) || f->type >= LR_FT_NAME)
            continue;
        const char *dot = strchr(f->key, '.');
        size_t pl = dot ? (size_t)(dot - f->key) : 0;
        bool same = group && dot && pl == glen && strncmp(f->key, group, pl) == 0;
        if (group && !same) {
            len += (size_t)snprintf(known + len, sizeof known - len, "}");
            group = NULL;
        }
        if (len >= sizeof known)
            break;
        if (same)
            len += (size_t)snprintf(known + len, sizeof known - len, ", %s", dot + 1);
        else if (dot) {
            len += (size_t)snprintf(known + len, sizeof known - len, "%s%.*s.{%s",
                                    len ? ", " : "", (int)pl, f->key, dot + 1);
            group = f->key;
            glen = pl;
        } else
            len += (size_t)snprintf(known + len, sizeof known - len, "%s%s", len ? ", " : "",
                                    f->key);
        if (len >= sizeof known)
            break;
    }
    if (group && len < sizeof known)
        snprintf(known + len, sizeof known - len, "}");
    const char *what = d->kind_what ? d->kind_what[kind] : d->what;
    return lr_field_fail(o, LR_EINVAL, "%s has no parameter '%s' (known: %s)", what, field, known);
}
