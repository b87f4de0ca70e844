#include "firmware/args.h"

#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int find_spec(const lr_argspec *specs, const char *name, size_t len)
{
    for (int i = 0; specs[i].name; i++)
        if (strlen(specs[i].name) == len && strncmp(specs[i].name, name, len) == 0)
            return i;
    return -1;
}

static int is_option(const char *arg) { return arg[0] == '-' && arg[1] == '-' && arg[2] != '\0'; }

/* One more value for specs[k]: the first is value[k], every one of a repeatable option also
 * goes to multi[] in order. */
static int add_value(lr_args *out, int k, const char *v, lr_err *e)
{
    const lr_argspec *s = &out->specs[k];
    int most = s->repeat > 1 ? s->repeat : 1;
    if (out->count[k] >= most) {
        if (most == 1)
            return lr_err_set(e, LR_EINVAL, "%s given twice", s->name);
        return lr_err_set(e, LR_EINVAL, "%s: at most %d", s->name, most);
    }
    if (s->type != LR_ARG_SWITCH && !v[0])
        return lr_err_set(e, LR_EINVAL, "%s needs a value (got an empty one)", s->name);
    if (!out->count[k])
        out->value[k] = v;
    out->count[k]++;
    if (most > 1) {
        if (out->nmulti >= LR_ARGS_MULTI)
            return lr_err_set(e, LR_EINVAL, "more than %d repeated values", LR_ARGS_MULTI);
        out->multi[out->nmulti].spec = k;
        out->multi[out->nmulti++].value = v;
    }
    return LR_OK;
}

static int parse(int argc, char **argv, const lr_argspec *specs, int max_positional, int head,
                 lr_args *out, int *used, lr_err *e)
{
    memset(out, 0, sizeof *out);
    out->specs = specs;
    while (specs[out->nspecs].name) {
        if (out->nspecs >= LR_ARGS_MAX)
            return lr_err_set(e, LR_EINVAL, "internal: more than %d options", LR_ARGS_MAX);
        out->nspecs++;
    }
    int i = 0;
    for (; i < argc; i++) {
        const char *arg = argv[i];
        if (!is_option(arg)) {
            if (head)
                break;
            /* A positional argument (a lone "-" or "--" counts as one too: we have no use
             * for either, so the count check reports it). */
            if (out->npos >= max_positional || out->npos >= LR_ARGS_POS)
                return lr_err_set(e, LR_EINVAL, "unexpected argument '%s'", arg);
            out->pos[out->npos++] = arg;
            continue;
        }
        const char *eq = strchr(arg, '=');
        size_t len = eq ? (size_t)(eq - arg) : strlen(arg);
        int k = find_spec(specs, arg, len);
        if (k < 0 && head)
            break; /* not one of the head's options: the caller's to judge */
        if (k < 0)
            return lr_err_set(e, LR_EINVAL, "unknown option '%.*s'", (int)len, arg);
        const lr_argspec *s = &specs[k];
        int rc;
        if (s->type == LR_ARG_SWITCH) {
            if (eq)
                return lr_err_set(e, LR_EINVAL, "%s takes no value", s->name);
            rc = add_value(out, k, "", e);
        } else if (eq) {
            rc = add_value(out, k, eq + 1, e);
        } else if (s->flags & LR_ARG_LIST) {
            /* --capture A B C: the values run up to the next option. */
            if (i + 1 >= argc || is_option(argv[i + 1]))
                return lr_err_set(e, LR_EINVAL, "%s needs a value", s->name);
            rc = LR_OK;
            while (!rc && i + 1 < argc && !is_option(argv[i + 1]))
                rc = add_value(out, k, argv[++i], e);
        } else {
            if (i + 1 >= argc)
                return lr_err_set(e, LR_EINVAL, "%s needs a value", s->name);
            rc = add_value(out, k, argv[++i], e);
        }
        if (rc)
            return rc;
    }
    if (used)
        *used = i;
    return LR_OK;
}

int lr_args_parse(int argc, char **argv, const lr_argspec *specs, int max_positional,
                  lr_args *out, lr_err *e)
{
    return parse(argc, argv, specs, max_positional, 0, out, NULL, e);
}

int lr_args_parse_head(int argc, char **argv, const lr_argspec *specs, lr_args *out, int *used,
                       lr_err *e)
{
    return parse(argc, argv, specs, 0, 1, out, used, e);
}

const lr_argspec *lr_args_missing(const lr_args *a)
{
    for (int k = 0; k < a->nspecs; k++)
        if ((a->specs[k].flags & LR_ARG_REQUIRED) && !a->value[k])
            return &a->specs[k];
    return NULL;
}

const lr_argspec *lr_args_spec(const lr_args *a, const char *name)
{
    int k = find_spec(a->specs, name, strlen(name));
    return k < 0 ? NULL : &a->specs[k];
}

const char *lr_args_get(const lr_args *a, const char *name)
{
    int k = find_spec(a->specs, name, strlen(name));
    return k < 0 ? NULL : a->value[k];
}

int lr_args_has(const lr_args *a, const char *name) { return lr_args_get(a, name) != NULL; }

int lr_args_values(const lr_args *a, const char *name, const char **out, int cap)
{
    int k = find_spec(a->specs, name, strlen(name)), n = 0;
    if (k < 0 || !a->value[k])
        return 0;
    if (a->specs[k].repeat <= 1) {
        if (cap > 0)
            out[0] = a->value[k];
        return 1;
    }
    for (int i = 0; i < a->nmulti && n < cap; i++)
        if (a->multi[i].spec == k)
            out[n++] = a->multi[i].value;
    return n;
}

const char *lr_args_metavar(const lr_argspec *s)
{
    if (s->metavar)
        return s->metavar;
    switch (s->type) {
    case LR_ARG_SWITCH:
        return "";
    case LR_ARG_PATH:
        return "FILE";
    case LR_ARG_INT:
        return "N";
    case LR_ARG_NUMBER:
        return "X";
    case LR_ARG_NUMBERS:
        return "X1,X2,...";
    case LR_ARG_TRIPLE:
        return "X,Y,Z";
    case LR_ARG_SIZE:
        return "WxH";
    case LR_ARG_CHOICE:
        return s->choices;
    default:
        return "VALUE";
    }
}

/* ---- ranges --------------------------------------------------------------------------- */

/* A bound as typed: whole numbers in full (1000000, not 1e+06), others with %g. */
static void bound_text(double v, char *buf, size_t cap)
{
    if (v == floor(v) && fabs(v) < 1e15)
        snprintf(buf, cap, "%.0f", v);
    else
        snprintf(buf, cap, "%g", v);
}

static int has_range(const lr_argspec *s)
{
    return s->min != 0 || s->max != 0 || (s->flags & (LR_ARG_ABOVE_MIN | LR_ARG_FLOOR));
}

static int in_range(const lr_argspec *s, double v)
{
    if (!has_range(s))
        return 1;
    if ((s->flags & LR_ARG_ABOVE_MIN) ? !(v > s->min) : !(v >= s->min))
        return 0;
    return s->max <= s->min || v <= s->max;
}

/* "> 0", ">= 1", "in 1..255", "> 0 and <= 1000000". */
static void range_text(const lr_argspec *s, char *buf, size_t cap)
{
    char lo[32], hi[32];
    bound_text(s->min, lo, sizeof lo);
    bound_text(s->max, hi, sizeof hi);
    int above = (s->flags & LR_ARG_ABOVE_MIN) != 0;
    if (s->max <= s->min)
        snprintf(buf, cap, "%s %s", above ? ">" : ">=", lo);
    else if (above)
        snprintf(buf, cap, "> %s and <= %s", lo, hi);
    else
        snprintf(buf, cap, "in %s..%s", lo, hi);
}

static int whole_text(const lr_argspec *s, const char *text, double *v, lr_err *e)
{
    int rc = lr_args_number(s->name, text, v, e);
    if (rc)
        return rc;
    if (*v != floor(*v) || !in_range(s, *v)) {
        char r[96] = "";
        if (has_range(s))
            range_text(s, r, sizeof r);
        return lr_err_set(e, LR_EINVAL, "%s %s: must be a whole number%s%s", s->name, text,
                          r[0] ? " " : "", r);
    }
    return LR_OK;
}

/* The spec of `name` and its value; 0 when absent (nothing to read). */
static const lr_argspec *given(const lr_args *a, const char *name, const char **v)
{
    int k = find_spec(a->specs, name, strlen(name));
    *v = k < 0 ? NULL : a->value[k];
    return *v ? &a->specs[k] : NULL;
}

/* The whole number given to `name`, at most `limit` in magnitude; *given false when absent. */
static int whole_arg(const lr_args *a, const char *name, double limit, double *out, bool *given_,
                     lr_err *e)
{
    const char *v;
    const lr_argspec *s = given(a, name, &v);
    *given_ = s != NULL;
    if (!s)
        return LR_OK;
    int rc = whole_text(s, v, out, e);
    if (rc)
        return rc;
    if (fabs(*out) > limit)
        return lr_err_set(e, LR_EINVAL, "%s %s: out of range", name, v);
    return LR_OK;
}

int lr_args_int(const lr_args *a, const char *name, int *out, lr_err *e)
{
    double d;
    bool got;
    int rc = whole_arg(a, name, 2147483647.0, &d, &got, e);
    if (!rc && got)
        *out = (int)d;
    return rc;
}

int lr_args_int64(const lr_args *a, const char *name, long long *out, lr_err *e)
{
    /* Above 2^53 a double no longer holds every whole number: "9007199254740993" would read
     * as its neighbour. */
    double d;
    bool got;
    int rc = whole_arg(a, name, 9007199254740992.0, &d, &got, e);
    if (!rc && got)
        *out = (long long)d;
    return rc;
}

int lr_args_double(const lr_args *a, const char *name, double *out, lr_err *e)
{
    const char *v;
    const lr_argspec *s = given(a, name, &v);
    if (!s)
        return LR_OK;
    double d;
    int rc = lr_args_number(name, v, &d, e);
    if (rc)
        return rc;
    if (!in_range(s, d)) {
        char r[96];
        range_text(s, r, sizeof r);
        return lr_err_set(e, LR_EINVAL, "%s %s: must be %s", name, v, r);
    }
    *out = d;
    return LR_OK;
}

int lr_args_list(const lr_args *a, const char *name, double *out, int cap, int *count,
                 lr_err *e)
{
    const char *v;
    const lr_argspec *s = given(a, name, &v);
    if (!s)
        return LR_OK;
    int lo = s->type == LR_ARG_TRIPLE ? 3 : 1, hi = s->type == LR_ARG_TRIPLE ? 3 : cap;
    int n = 0;
    int rc = lr_args_numbers(name, v, out, lo, hi, &n, e);
    if (rc)
        return rc;
    for (int i = 0; i < n; i++)
        if (!in_range(s, out[i])) {
            char r[96];
            range_text(s, r, sizeof r);
            return lr_err_set(e, LR_EINVAL, "%s %s: item %d must be %s", name, v, i + 1, r);
        }
    *count = n;
    return LR_OK;
}

int lr_args_size(const lr_args *a, const char *name, int *w, int *h, lr_err *e)
{
    const char *v;
    const lr_argspec *s = given(a, name, &v);
    if (!s)
        return LR_OK;
    /* Two decimal whole numbers around one 'x', each in the range (at least 1). */
    char r[96];
    lr_argspec each = *s;
    if (!has_range(&each))
        each.min = 1;
    range_text(&each, r, sizeof r);
    const char *x = strchr(v, 'x');
    int dims[2];
    for (int k = 0; k < 2; k++) {
        const char *p = k ? (x ? x + 1 : "") : v;
        size_t len = k ? strlen(p) : (x ? (size_t)(x - v) : 0);
        char *end = NULL;
        errno = 0;
        long d = len && p[0] >= '0' && p[0] <= '9' ? strtol(p, &end, 10) : -1;
        if (d < 0 || end != p + len || errno || !in_range(&each, (double)d) || d > 1000000)
            return lr_err_set(e, LR_EINVAL, "%s %s: expected WIDTHxHEIGHT, each a whole number %s",
                              name, v, r);
        dims[k] = (int)d;
    }
    *w = dims[0];
    *h = dims[1];
    return LR_OK;
}

int lr_args_choice(const lr_args *a, const char *name, int *index, lr_err *e)
{
    const char *v;
    const lr_argspec *s = given(a, name, &v);
    if (!s)
        return LR_OK;
    const char *c = s->choices ? s->choices : "";
    size_t vlen = strlen(v);
    for (int i = 0; *c; i++) {
        size_t len = strcspn(c, "|");
        if (len == vlen && strncmp(c, v, len) == 0) {
            *index = i;
            return LR_OK;
        }
        c += len + (c[len] == '|');
    }
    /* "chessboard, circles or acircles" */
    char list[256] = "";
    size_t n = 0;
    for (const char *p = s->choices ? s->choices : ""; *p && n + 8 < sizeof list;) {
        size_t len = strcspn(p, "|");
        const char *sep = n == 0 ? "" : p[len] ? ", " : " or ";
        n += (size_t)snprintf(list + n, sizeof list - n, "%s%.*s", sep, (int)len, p);
        p += len + (p[len] == '|');
    }
    return lr_err_set(e, LR_EINVAL, "%s '%s': expected %s", name, v, list);
}

/* ---- numbers -------------------------------------------------------------------------- */
/* Decimal grammar only: strtod alone would also take "nan", "inf", "0x1p3" and leading
 * spaces, none of which belongs on our command lines. */
static int parse_number(const char *flag, const char *s, size_t len, double *out, lr_err *e)
{
    char buf[64];
    if (len == 0)
        return lr_err_set(e, LR_EINVAL, "%s: empty number", flag);
    if (len >= sizeof buf)
        return lr_err_set(e, LR_EINVAL, "%s: '%.*s...' is not a number", flag, 16, s);
    memcpy(buf, s, len);
    buf[len] = '\0';
    for (size_t i = 0; i < len; i++) {
        char c = buf[i];
        if (!((c >= '0' && c <= '9') || c == '.' || c == 'e' || c == 'E' || c == '+' ||
              c == '-'))
            return lr_err_set(e, LR_EINVAL, "%s: '%s' is not a finite decimal number", flag,
                              buf);
    }
    char *end;
    errno = 0;
    double v = strtod(buf, &end);
    if (end == buf || *end != '\0')
        return lr_err_set(e, LR_EINVAL, "%s: '%s' is not a number", flag, buf);
    if ((errno == ERANGE && fabs(v) > 1.0) || !isfinite(v))
        return lr_err_set(e, LR_EINVAL, "%s: '%s' is out of range", flag, buf);
    *out = v;
    return LR_OK;
}

int lr_args_number(const char *flag, const char *text, double *out, lr_err *e)
{
    if (strchr(text, ','))
        return lr_err_set(e, LR_EINVAL, "%s: expected one number, got the list '%s'", flag,
                          text);
    return parse_number(flag, text, strlen(text), out, e);
}

int lr_args_numbers(const char *flag, const char *text, double *out, int min, int max,
                    int *count, lr_err *e)
{
    int items = 1;
    for (const char *c = text; *c; c++)
        items += *c == ',';
    if (items < min || items > max) {
        if (min == max)
            return lr_err_set(e, LR_EINVAL, "%s: expected %d comma-separated numbers, got %d",
                              flag, min, items);
        return lr_err_set(e, LR_EINVAL, "%s: expected %d to %d comma-separated numbers, got %d",
                          flag, min, max, items);
    }
    const char *p = text;
    for (int n = 0; n < items; n++) {
        const char *comma = strchr(p, ',');
        size_t len = comma ? (size_t)(comma - p) : strlen(p);
        if (len == 0)
            return lr_err_set(e, LR_EINVAL, "%s: item %d of '%s' is empty", flag, n + 1, text);
        int rc = parse_number(flag, p, len, &out[n], e);
        if (rc)
            return rc;
        p = comma ? comma + 1 : p + len;
    }
    *count = items;
    return LR_OK;
}

int lr_args_triple(const char *flag, const char *text, double out[3], lr_err *e)
{
    int n = 0;
    return lr_args_numbers(flag, text, out, 3, 3, &n, e);
}

int lr_args_times(const char *s, double *t, int cap)
{
    int n = 0;
    while (*s) {
        if (n >= cap)
            return -1;
        char *end;
        double a = strtod(s, &end);
        if (end == s)
            return -1;
        if (*end == '/') {
            const char *d = end + 1;
            double b = strtod(d, &end);
            if (end == d || !(b > 0))
                return -1;
            a /= b;
        }
        if (!(a > 0) || !isfinite(a))
            return -1;
        t[n++] = a;
        if (*end == ',')
            end++;
        else if (*end != '\0')
            return -1;
        s = end;
    }
    return n;
}
