/* The engine behind the scene's field tables (fields.h): defaults, keys, reading JSON, range
 * checks. Values as text (lr_scene_set/get) are field_value.c; the tables are field_tables.c. */
#include "render/scene/fields.h"

#include <math.h>
#include <string.h>

#include "render/scene/scene_internal.h"

/* Coordinates beyond a kilometre are a typo (mm), and keep float positions meaningful. */
#define MAX_COORD 1e6

bool lr_field_has(const lr_field *f, int kind)
{
    return !f->kinds || (f->kinds & (1u << kind));
}

const lr_field *lr_field_find(const lr_record_desc *d, int kind, const char *key)
{
    for (int i = 0; i < d->n; i++)
        if (lr_field_has(&d->fields[i], kind) && strcmp(d->fields[i].key, key) == 0)
            return &d->fields[i];
    return NULL;
}

static int kind_of(const lr_record_desc *d, const void *rec)
{
    return d->kind_of ? d->kind_of(rec) : 0;
}

static void *at(void *rec, size_t off)
{
    return lr_field_ptr(rec, off);
}

/* ---- defaults -------------------------------------------------------------------------------- */

void lr_fields_defaults(const lr_record_desc *d, void *rec)
{
    for (int i = 0; i < d->n; i++) {
        const lr_field *f = &d->fields[i];
        void *p = at(rec, f->off);
        switch (f->type) {
        case LR_FT_NUM: *(double *)p = f->dflt[0]; break;
        case LR_FT_INT: *(int *)p = (int)f->dflt[0]; break;
        case LR_FT_UINT: *(unsigned *)p = (unsigned)f->dflt[0]; break;
        case LR_FT_VEC3:
        case LR_FT_SCALE: *(lr_vec3 *)p = lr_v3(f->dflt[0], f->dflt[1], f->dflt[2]); break;
        case LR_FT_RGB:
        case LR_FT_SIZE3: memcpy(p, f->dflt, 3 * sizeof(double)); break;
        case LR_FT_PAIR: memcpy(p, f->dflt, 2 * sizeof(double)); break;
        case LR_FT_BOOL: *(bool *)p = (f->dflt[0] != 0.0) != !!(f->flags & LR_FF_INVERT); break;
        case LR_FT_ENUM: *(int *)p = (int)f->dflt[0]; break;
        case LR_FT_ENUMB: *(bool *)p = f->dflt[0] != 0.0; break;
        case LR_FT_PATH:
        case LR_FT_NAME:
        case LR_FT_TYPE:
        case LR_FT_OBJECT: break;
        }
    }
}

/* ---- keys ------------------------------------------------------------------------------------ */

/* The first component of f->key after prefix ("flicker" of "flicker.amplitude" with prefix
 * ""; "amplitude" with prefix "flicker."), NULL when f is not under prefix. len gets its
 * length. */
static const char *component(const lr_field *f, const char *prefix, size_t *len)
{
    size_t pl = strlen(prefix);
    if (strncmp(f->key, prefix, pl) != 0)
        return NULL;
    const char *k = f->key + pl;
    const char *dot = strchr(k, '.');
    *len = dot ? (size_t)(dot - k) : strlen(k);
    return k;
}

/* The table's name of a nested object ("flicker" of "flicker.amplitude"): keys handed out
 * are static strings. */
static const char *intern(const lr_record_desc *d, const char *s, size_t len)
{
    for (int i = 0; d->objects && d->objects[i]; i++)
        if (strlen(d->objects[i]) == len && strncmp(d->objects[i], s, len) == 0)
            return d->objects[i];
    return NULL;
}

void lr_fields_keys(const lr_record_desc *d, int kind, const char *prefix, const char **out,
                    int cap)
{
    int n = 0;
    for (int i = 0; i < d->n && n < cap - 1; i++) {
        const lr_field *f = &d->fields[i];
        size_t len;
        const char *k = lr_field_has(f, kind) ? component(f, prefix, &len) : NULL;
        if (!k)
            continue;
        const char *key = k[len] ? intern(d, k, len) : k;
        if (!key)
            continue;
        bool dup = false;
        for (int m = 0; m < n && !dup; m++)
            dup = strcmp(out[m], key) == 0;
        if (!dup)
            out[n++] = key;
    }
    out[n] = NULL;
}

/* ---- reading JSON ------------------------------------------------------------------------------ */

static const char *cat(char *buf, size_t cap, const char *where, const char *key)
{
    snprintf(buf, cap, "%s.%s", where, key);
    return buf;
}

void lr_field_names_text(const char *const *names, const char *last, char *buf, size_t cap)
{
    buf[0] = '\0';
    for (int i = 0; names[i]; i++)
        snprintf(buf + strlen(buf), cap - strlen(buf), "%s%s",
                 i == 0 ? "" : names[i + 1] ? ", " : last, names[i]);
}

static int read_one(const lr_json *j, lr_jnode n, const char *fname, const lr_field *f,
                    void *rec, lr_err *e)
{
    void *p = at(rec, f->off);
    int rc = LR_OK;
    switch (f->type) {
    case LR_FT_NUM: {
        double v;
        if ((rc = lr_json_number(j, n, fname, &v, e)))
            return rc;
        if (f->flags & LR_FF_ZERO_FLAG)
            *(bool *)at(rec, f->aux) = v == 0.0; /* written 0: the shape, not the default */
        if (v == 0.0 && (f->flags & LR_FF_ZERO_DEFAULT))
            v = f->dflt[0];
        *(double *)p = v;
        return LR_OK;
    }
    case LR_FT_INT:
    case LR_FT_UINT: {
        long v;
        if ((rc = lr_json_int(j, n, fname, &v, e)))
            return rc;
        if (v < -1000000000L || v > 1000000000L)
            return lr_json_fail(j, n, fname, e, LR_EINVAL, "out of range, got %ld", v);
        if (f->type == LR_FT_UINT) {
            if (v < 0)
                return lr_json_fail(j, n, fname, e, LR_EINVAL, "must be >= 0, got %d", (int)v);
            *(unsigned *)p = (unsigned)v;
            return LR_OK;
        }
        if (v == 0 && (f->flags & LR_FF_ZERO_DEFAULT))
            v = (long)f->dflt[0];
        *(int *)p = (int)v;
        return LR_OK;
    }
    case LR_FT_VEC3:
    case LR_FT_RGB:
    case LR_FT_SIZE3: {
        double v[3];
        if ((rc = lr_json_numbers(j, n, fname, v, 3, e)))
            return rc;
        if (f->type == LR_FT_VEC3)
            *(lr_vec3 *)p = lr_v3(v[0], v[1], v[2]);
        else
            memcpy(p, v, sizeof v);
        return LR_OK;
    }
    case LR_FT_PAIR:
        return lr_json_numbers(j, n, fname, (double *)p, 2, e);
    case LR_FT_SCALE: {
        double v[3];
        if (lr_json_type(j, n) == LR_JSON_NUMBER) {
            if ((rc = lr_json_number(j, n, fname, &v[0], e)))
                return rc;
            v[1] = v[2] = v[0];
        } else if (lr_json_type(j, n) != LR_JSON_ARRAY) {
            return lr_json_fail(j, n, fname, e, LR_EPARSE,
                                "expected a number or an array of 3 numbers, got %s",
                                lr_json_type_name(lr_json_type(j, n)));
        } else if ((rc = lr_json_numbers(j, n, fname, v, 3, e))) {
            return rc;
        }
        *(lr_vec3 *)p = lr_v3(v[0], v[1], v[2]);
        return LR_OK;
    }
    case LR_FT_BOOL: {
        bool b;
        if ((rc = lr_json_bool(j, n, fname, &b, e)))
            return rc;
        *(bool *)p = b != !!(f->flags & LR_FF_INVERT);
        return LR_OK;
    }
    case LR_FT_ENUM:
    case LR_FT_ENUMB: {
        char s[64], list[256];
        if ((rc = lr_json_string(j, n, fname, s, sizeof s, e)))
            return rc;
        for (int i = 0; f->names[i]; i++)
            if (strcmp(s, f->names[i]) == 0) {
                if (f->type == LR_FT_ENUM)
                    *(int *)p = i;
                else
                    *(bool *)p = i == 1;
                return LR_OK;
            }
        if (strcmp(f->key, "type") == 0) { /* as a record's kind (load.c type_of) */
            lr_field_names_text(f->names, ", ", list, sizeof list);
            return lr_json_fail(j, n, fname, e, LR_EINVAL, "unknown type '%s' (one of: %s)", s,
                                list);
        }
        lr_field_names_text(f->names, " or ", list, sizeof list);
        return lr_json_fail(j, n, fname, e, LR_EINVAL, "'%s': expected %s", s, list);
    }
    case LR_FT_PATH:
        return lr_json_string(j, n, fname, (char *)p, LR_SCENE_PATH_MAX, e);
    case LR_FT_NAME:
    case LR_FT_TYPE:
    case LR_FT_OBJECT: break;
    }
    return LR_OK;
}

int lr_fields_read(const lr_json *j, lr_jnode obj, const char *where, const lr_record_desc *d,
                   int kind, void *rec, lr_err *e)
{
    char fname[256];
    for (int i = 0; i < d->n; i++) {
        const lr_field *f = &d->fields[i];
        if (!lr_field_has(f, kind) || f->type >= LR_FT_NAME)
            continue;
        /* "a.b": b in the object a (its keys checked when a is first met). */
        lr_jnode o = obj;
        const char *dot = strchr(f->key, '.');
        char sub[64] = "";
        if (dot) {
            snprintf(sub, sizeof sub, "%.*s", (int)(dot - f->key), f->key);
            o = lr_json_get(j, obj, sub);
            if (o == LR_JNONE)
                continue; /* the whole sub-object is optional */
            if (i == 0 || strncmp(d->fields[i - 1].key, f->key, (size_t)(dot - f->key) + 1)) {
                char sw[128], pre[80];
                const char *keys[32];
                snprintf(pre, sizeof pre, "%s.", sub);
                lr_fields_keys(d, kind, pre, keys, 32);
                int rc = lr_json_check_keys(j, o, cat(sw, sizeof sw, where, sub), keys, e);
                if (rc)
                    return rc;
            }
        }
        const char *leaf = dot ? dot + 1 : f->key;
        lr_jnode n = lr_json_get(j, o, leaf);
        cat(fname, sizeof fname, where, f->key);
        if (n == LR_JNONE) {
            if (f->flags & LR_FF_REQUIRED) {
                if (f->unit && f->unit[0] == '(') /* "(W/sr)": "missing (required, W/sr)" */
                    return lr_json_fail(j, o, fname, e, LR_EPARSE, "missing (required, %.*s)",
                                        (int)strlen(f->unit) - 2, f->unit + 1);
                return lr_json_fail(j, o, fname, e, LR_EPARSE, "missing (required)");
            }
            continue;
        }
        int rc = read_one(j, n, fname, f, rec, e);
        if (rc)
            return rc;
    }
    return LR_OK;
}

/* ---- checks ------------------------------------------------------------------------------------ */

/* "in (0, 90)", ">= 0", "between 1 and 256". */
static void range_text(const lr_field *f, bool show_hi, char *buf, size_t cap)
{
    if (f->lo == 0.0 && f->hi == 0.0) {
        buf[0] = '\0';
        return;
    }
    bool lo = !isnan(f->lo), hi = !isnan(f->hi) && show_hi;
    bool lo_open = f->flags & LR_FF_LO_OPEN, hi_open = f->flags & LR_FF_HI_OPEN;
    bool ints = f->type == LR_FT_INT || f->type == LR_FT_UINT;
    if (lo && hi && ints)
        snprintf(buf, cap, "between %.0f and %.0f", f->lo, f->hi);
    else if (lo && hi)
        snprintf(buf, cap, "in %c%g, %g%c", lo_open ? '(' : '[', f->lo, f->hi,
                 hi_open ? ')' : ']');
    else if (lo)
        snprintf(buf, cap, "%s %g", lo_open ? ">" : ">=", f->lo);
    else if (hi)
        snprintf(buf, cap, "%s %g", hi_open ? "<" : "<=", f->hi);
    else
        buf[0] = '\0';
}

void lr_field_range_text(const lr_field *f, char *buf, size_t cap)
{
    range_text(f, true, buf, cap);
}

/* 0: in range; 1: below lo; 2: above hi (NaN is below). */
static int out_of_range(const lr_field *f, double v)
{
    if (f->lo == 0.0 && f->hi == 0.0) /* a row that gives no range */
        return 0;
    if (!isnan(f->lo) && !((f->flags & LR_FF_LO_OPEN) ? v > f->lo : v >= f->lo))
        return 1;
    if (!isnan(f->hi) && !((f->flags & LR_FF_HI_OPEN) ? v < f->hi : v <= f->hi))
        return 2;
    return 0;
}

static int range_fail(const lr_field *f, int how, const char *got, const char **field, lr_err *e)
{
    char r[96];
    /* A quiet upper bound is named only to a value beyond it. */
    range_text(f, !(f->flags & LR_FF_HI_QUIET) || how == 2, r, sizeof r);
    if (how == 2 && (f->flags & LR_FF_HI_QUIET))
        snprintf(r, sizeof r, "%s %g", (f->flags & LR_FF_HI_OPEN) ? "<" : "<=", f->hi);
    const char *each = f->type == LR_FT_RGB ? "each band "
                       : f->type == LR_FT_SIZE3 || f->type == LR_FT_PAIR ? "each side "
                                                                         : "";
    *field = f->key;
    return lr_err_set(e, LR_EINVAL, "%smust be %s%s%s, got %s", each, r, f->unit ? " " : "",
                      f->unit ? f->unit : "", got);
}

static bool coord_ok(lr_vec3 v)
{
    return lr_v3_isfinite(v) && fabs(v.x) <= MAX_COORD && fabs(v.y) <= MAX_COORD &&
           fabs(v.z) <= MAX_COORD;
}

static int check_one(const lr_field *f, void *rec, const char **field, lr_err *e)
{
    void *p = at(rec, f->off);
    double v[3];
    int n = 0;
    switch (f->type) {
    case LR_FT_NUM:
        if ((f->flags & LR_FF_ZERO_FLAG) && *(bool *)at(rec, f->aux))
            return LR_OK;
        if ((f->flags & LR_FF_ZERO_ABSENT) && *(double *)p == 0.0)
            return LR_OK;
        v[n++] = *(double *)p;
        break;
    case LR_FT_INT: v[n++] = *(int *)p; break;
    case LR_FT_UINT: v[n++] = *(unsigned *)p; break;
    case LR_FT_VEC3:
    case LR_FT_SCALE: {
        lr_vec3 *x = p;
        if ((f->flags & LR_FF_COORD) && !coord_ok(*x)) {
            *field = f->key;
            return lr_err_set(e, LR_EINVAL, "must be finite and within 1e6 mm of the origin");
        }
        if ((f->flags & LR_FF_ANGLES) && !coord_ok(*x)) {
            *field = f->key;
            return lr_err_set(e, LR_EINVAL, "must be finite");
        }
        if (f->flags & LR_FF_UNIT) {
            double l = lr_v3_len(*x);
            if (!lr_v3_isfinite(*x) || !(l > 0.0) || !isfinite(l)) {
                *field = f->key;
                return lr_err_set(e, LR_EINVAL, "must be a non-zero vector");
            }
            *x = lr_v3_scale(*x, 1.0 / l);
        }
        v[0] = x->x;
        v[1] = x->y;
        v[2] = x->z;
        n = 3;
        break;
    }
    case LR_FT_RGB:
    case LR_FT_SIZE3: memcpy(v, p, 3 * sizeof(double)); n = 3; break;
    case LR_FT_PAIR: memcpy(v, p, 2 * sizeof(double)); n = 2; break;
    default: return LR_OK;
    }
    for (int i = 0; i < n; i++) {
        int how = out_of_range(f, v[i]);
        if (how) {
            char got[40];
            snprintf(got, sizeof got, f->type == LR_FT_INT || f->type == LR_FT_UINT ? "%.0f"
                                                                                   : "%g",
                     v[i]);
            return range_fail(f, how, got, field, e);
        }
    }
    return LR_OK;
}

int lr_fields_check(const lr_record_desc *d, void *rec, const char **field, lr_err *e)
{
    int kind = kind_of(d, rec);
    for (int i = 0; i < d->n; i++) {
        const lr_field *f = &d->fields[i];
        if (!lr_field_has(f, kind) || (f->check_kinds && !(f->check_kinds & (1u << kind))))
            continue;
        int rc = check_one(f, rec, field, e);
        if (rc)
            return rc;
    }
    return LR_OK;
}
