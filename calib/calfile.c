#include "calib/calfile.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/atomic_file.h"

static void field_name(char *buf, size_t cap, const char *prefix, const char *key)
{
    if (prefix && prefix[0])
        snprintf(buf, cap, "%s.%s", prefix, key);
    else
        snprintf(buf, cap, "%s", key);
}

/* Finds a required member; "missing" names the enclosing object's line. */
static int member(const lr_json *j, lr_jnode obj, const char *field, const char *key,
                  lr_jnode *out, lr_err *e)
{
    if (lr_json_type(j, obj) != LR_JSON_OBJECT)
        return lr_json_fail(j, obj, field, e, LR_EPARSE, "enclosing value is not an object");
    *out = lr_json_get(j, obj, key);
    if (*out == LR_JNONE)
        return lr_json_fail(j, obj, field, e, LR_EPARSE, "missing");
    return LR_OK;
}

static int check_header(const lr_json *j, const char *kind, lr_jnode *root, lr_err *e)
{
    *root = lr_json_root(j);
    if (lr_json_type(j, *root) != LR_JSON_OBJECT)
        return lr_json_fail(j, *root, NULL, e, LR_EPARSE,
                            "a calibration file is a JSON object, got %s",
                            lr_json_type_name(lr_json_type(j, *root)));
    lr_jnode v;
    int rc = member(j, *root, "version", "version", &v, e);
    if (rc)
        return rc;
    long version;
    rc = lr_json_int(j, v, "version", &version, e);
    if (rc)
        return rc;
    if (version != LR_CALFILE_VERSION)
        return lr_json_fail(j, v, "version", e, LR_EINVAL,
                            "unsupported version %ld (this lamprig reads version %d; "
                            "recalibrate or convert the file)",
                            version, LR_CALFILE_VERSION);
    lr_jnode k = lr_json_get(j, *root, "kind");
    if (kind && k != LR_JNONE) {
        char got[64];
        rc = lr_json_string(j, k, "kind", got, sizeof got, e);
        if (rc)
            return rc;
        if (strcmp(got, kind) != 0)
            return lr_json_fail(j, k, "kind", e, LR_EINVAL, "this is a '%s' file, expected '%s'",
                                got, kind);
    }
    return LR_OK;
}

int lr_calfile_parse(const char *text, size_t len, const char *name, const char *kind,
                     lr_json **j, lr_jnode *root, lr_err *e)
{
    *j = NULL;
    lr_json *doc;
    int rc = lr_json_parse(text, len, name, &doc, e);
    if (rc)
        return rc;
    rc = check_header(doc, kind, root, e);
    if (rc) {
        lr_json_destroy(doc);
        return rc;
    }
    *j = doc;
    return LR_OK;
}

int lr_calfile_load(const char *path, const char *kind, lr_json **j, lr_jnode *root,
                    lr_err *e)
{
    *j = NULL;
    lr_json *doc;
    int rc = lr_json_load(path, &doc, e);
    if (rc)
        return rc;
    rc = check_header(doc, kind, root, e);
    if (rc) {
        lr_json_destroy(doc);
        return rc;
    }
    *j = doc;
    return LR_OK;
}

int lr_calfile_peek_kind(const char *path, char *kind, size_t cap, lr_err *e)
{
    lr_json *j;
    lr_jnode root;
    int rc = lr_calfile_load(path, NULL, &j, &root, e);
    if (rc)
        return rc;
    lr_jnode k;
    rc = member(j, root, "kind", "kind", &k, e);
    if (!rc)
        rc = lr_json_string(j, k, "kind", kind, cap, e);
    lr_json_destroy(j);
    return rc;
}

int lr_calfile_save(const char *path, const char *kind, lr_calfile_fill_fn fill,
                    const void *obj, lr_calfile_check_fn check, lr_err *e)
{
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    if (!f)
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
    lr_jw *w = lr_jw_create(f);
    if (!w) {
        fclose(f);
        free(text);
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
    }
    lr_jw_object(w, NULL);
    lr_jw_int(w, "version", LR_CALFILE_VERSION);
    lr_jw_string(w, "kind", kind);
    fill(w, obj);
    lr_jw_object_end(w);
    int rc = lr_jw_finish(w, e);
    if (fclose(f) != 0 && !rc)
        rc = lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
    if (rc) {
        free(text);
        return lr_err_prefix(e, "%s: not written", path);
    }
    /* Read back what would be written, exactly as a later load will. */
    lr_json *j;
    lr_jnode root;
    rc = lr_calfile_parse(text, len, path, kind, &j, &root, e);
    if (!rc) {
        rc = check(j, root, e);
        lr_json_destroy(j);
    }
    if (rc) {
        free(text);
        return lr_err_prefix(e, "refusing to write %s (the previous file is kept)", path);
    }
    /* A calibration is the rig's own state: the service's group reads it, others not. */
    rc = lr_atomic_write_mode(path, text, len, LR_FILE_MODE_PRIVATE, e);
    free(text);
    return rc;
}

int lr_calfile_number(const lr_json *j, lr_jnode obj, const char *prefix, const char *key,
                      double lo, double hi, double *out, lr_err *e)
{
    char field[128];
    field_name(field, sizeof field, prefix, key);
    lr_jnode n;
    int rc = member(j, obj, field, key, &n, e);
    if (rc)
        return rc;
    double v;
    rc = lr_json_number(j, n, field, &v, e);
    if (rc)
        return rc;
    if (!(v >= lo && v <= hi))
        return lr_json_fail(j, n, field, e, LR_EINVAL, "must be in [%g, %g], got %g", lo, hi, v);
    *out = v;
    return LR_OK;
}

int lr_calfile_int(const lr_json *j, lr_jnode obj, const char *prefix, const char *key,
                   long lo, long hi, long *out, lr_err *e)
{
    char field[128];
    field_name(field, sizeof field, prefix, key);
    lr_jnode n;
    int rc = member(j, obj, field, key, &n, e);
    if (rc)
        return rc;
    long v;
    rc = lr_json_int(j, n, field, &v, e);
    if (rc)
        return rc;
    if (v < lo || v > hi)
        return lr_json_fail(j, n, field, e, LR_EINVAL, "must be in [%ld, %ld], got %ld", lo, hi,
                            v);
    *out = v;
    return LR_OK;
}

static int numbers_at(const lr_json *j, lr_jnode n, const char *field, int count, double lo,
                      double hi, double *out, lr_err *e)
{
    int rc = lr_json_numbers(j, n, field, out, count, e);
    if (rc)
        return rc;
    for (int i = 0; i < count; i++)
        if (!(out[i] >= lo && out[i] <= hi))
            return lr_json_fail(j, n, field, e, LR_EINVAL,
                                "element %d must be in [%g, %g], got %g", i, lo, hi, out[i]);
    return LR_OK;
}

int lr_calfile_numbers(const lr_json *j, lr_jnode obj, const char *prefix, const char *key,
                       int n, double lo, double hi, double *out, lr_err *e)
{
    char field[128];
    field_name(field, sizeof field, prefix, key);
    lr_jnode a;
    int rc = member(j, obj, field, key, &a, e);
    if (rc)
        return rc;
    return numbers_at(j, a, field, n, lo, hi, out, e);
}

int lr_calfile_matrix(const lr_json *j, lr_jnode obj, const char *prefix, const char *key,
                      int rows, int cols, double lo, double hi, double *out, lr_err *e)
{
    char field[128];
    field_name(field, sizeof field, prefix, key);
    lr_jnode a;
    int rc = member(j, obj, field, key, &a, e);
    if (rc)
        return rc;
    if (lr_json_type(j, a) != LR_JSON_ARRAY || lr_json_count(j, a) != rows)
        return lr_json_fail(j, a, field, e, LR_EPARSE, "expected a %dx%d matrix (%d rows)", rows,
                            cols, rows);
    for (int r = 0; r < rows; r++) {
        char sub[160];
        snprintf(sub, sizeof sub, "%s[%d]", field, r);
        rc = numbers_at(j, lr_json_at(j, a, r), sub, cols, lo, hi, out + (size_t)r * (size_t)cols,
                        e);
        if (rc)
            return rc;
    }
    return LR_OK;
}

int lr_calfile_array(const lr_json *j, lr_jnode obj, const char *prefix, const char *key,
                     lr_jnode *arr, int *count, lr_err *e)
{
    char field[128];
    field_name(field, sizeof field, prefix, key);
    int rc = member(j, obj, field, key, arr, e);
    if (rc)
        return rc;
    if (lr_json_type(j, *arr) != LR_JSON_ARRAY)
        return lr_json_fail(j, *arr, field, e, LR_EPARSE, "expected an array, got %s",
                            lr_json_type_name(lr_json_type(j, *arr)));
    *count = lr_json_count(j, *arr);
    return LR_OK;
}

int lr_calfile_object(const lr_json *j, lr_jnode obj, const char *prefix, const char *key,
                      lr_jnode *out, lr_err *e)
{
    char field[128];
    field_name(field, sizeof field, prefix, key);
    int rc = member(j, obj, field, key, out, e);
    if (rc)
        return rc;
    if (lr_json_type(j, *out) != LR_JSON_OBJECT)
        return lr_json_fail(j, *out, field, e, LR_EPARSE, "expected an object, got %s",
                            lr_json_type_name(lr_json_type(j, *out)));
    return LR_OK;
}
