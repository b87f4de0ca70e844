#include "firmware/args.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static int find_spec(const lr_argspec *specs, const char *name, size_t len)
{
    for (int i = 0; specs[i].name; i++)
        if (strlen(specs[i].name) == len && strncmp(specs[i].name, name, len) == 0)
            return i;
    return -1;
}

int lr_args_parse(int argc, char **argv, const lr_argspec *specs, int max_positional,
                  lr_args *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    out->specs = specs;
    while (specs[out->nspecs].name) {
        if (out->nspecs >= LR_ARGS_MAX)
            return lr_err_set(e, LR_EINVAL, "internal: more than %d options", LR_ARGS_MAX);
        out->nspecs++;
    }
    for (int i = 0; i < argc; i++) {
        const char *arg = argv[i];
        if (arg[0] != '-' || arg[1] != '-' || arg[2] == '\0') {
            /* A positional argument (a lone "-" or "--" counts as one too: we have no use
             * for either, so the count check reports it). */
            if (out->npos >= max_positional || out->npos >= LR_ARGS_MAX)
                return lr_err_set(e, LR_EINVAL, "unexpected argument '%s'", arg);
            out->pos[out->npos++] = arg;
            continue;
        }
        const char *eq = strchr(arg, '=');
        size_t len = eq ? (size_t)(eq - arg) : strlen(arg);
        int k = find_spec(specs, arg, len);
        if (k < 0)
            return lr_err_set(e, LR_EINVAL, "unknown option '%.*s'", (int)len, arg);
        if (out->value[k])
            return lr_err_set(e, LR_EINVAL, "%s given twice", specs[k].name);
        if (!specs[k].takes_value) {
            if (eq)
                return lr_err_set(e, LR_EINVAL, "%s takes no value", specs[k].name);
            out->value[k] = "";
        } else if (eq) {
            out->value[k] = eq + 1;
        } else {
            if (i + 1 >= argc)
                return lr_err_set(e, LR_EINVAL, "%s needs a value", specs[k].name);
            out->value[k] = argv[++i];
        }
        if (specs[k].takes_value && !out->value[k][0])
            return lr_err_set(e, LR_EINVAL, "%s needs a value (got an empty one)",
                              specs[k].name);
    }
    return LR_OK;
}

const char *lr_args_get(const lr_args *a, const char *name)
{
    int k = find_spec(a->specs, name, strlen(name));
    return k < 0 ? NULL : a->value[k];
}

int lr_args_has(const lr_args *a, const char *name) { return lr_args_get(a, name) != NULL; }

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
