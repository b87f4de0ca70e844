/* Material files: parsing, validation and `base` / `scale` resolution (format in material.h). */
#include "render/material/material.h"

#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/paths.h"

/* The files being loaded, outermost first: a `base` that resolves to one of them is a cycle. */
typedef struct chain {
    int n;
    char real[LR_MATERIAL_BASE_DEPTH + 1][PATH_MAX];
    char name[LR_MATERIAL_BASE_DEPTH + 1][LR_MATERIAL_NAME_MAX];
} chain;

static int load_file(const char *path, const char *base_dir, const char *expect_name, chain *ch,
                     lr_material *out, lr_err *e);

/* "prefix.key" (or "key" when prefix is empty) into buf. */
static const char *field_name(char *buf, size_t cap, const char *prefix, const char *key)
{
    if (prefix && prefix[0])
        snprintf(buf, cap, "%s.%s", prefix, key);
    else
        snprintf(buf, cap, "%s", key);
    return buf;
}

int lr_material_name_ok(const char *name)
{
    size_t n = name ? strlen(name) : 0;
    if (n == 0 || n >= LR_MATERIAL_NAME_MAX || name[0] == '.')
        return 0;
    for (size_t i = 0; i < n; i++) {
        char c = name[i];
        bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                  c == '_' || c == '-' || c == '.';
        if (!ok)
            return 0;
    }
    return 1;
}

/* An RGB triple of coefficients, each >= 0 (JSON numbers are already finite). */
static int get_coeffs(const lr_json *j, lr_jnode node, const char *field, double out[3],
                      lr_err *e)
{
    double v[3];
    int rc = lr_json_numbers(j, node, field, v, 3, e);
    if (rc)
        return rc;
    for (int i = 0; i < 3; i++) {
        if (v[i] < 0.0) {
            char sub[300];
            snprintf(sub, sizeof sub, "%s[%d]", field, i);
            return lr_json_fail(j, lr_json_at(j, node, i), sub, e, LR_EINVAL,
                                "must be >= 0 (mm^-1), got %g", v[i]);
        }
    }
    memcpy(out, v, sizeof v);
    return LR_OK;
}

/* `scale`: a number or an RGB triple, each finite and > 0. */
static int get_scale(const lr_json *j, lr_jnode node, const char *field, double out[3], lr_err *e)
{
    double v[3];
    int rc;
    if (lr_json_type(j, node) == LR_JSON_ARRAY) {
        rc = lr_json_numbers(j, node, field, v, 3, e);
        if (rc)
            return rc;
    } else if (lr_json_type(j, node) == LR_JSON_NUMBER) {
        rc = lr_json_number(j, node, field, &v[0], e);
        if (rc)
            return rc;
        v[1] = v[2] = v[0];
    } else {
        return lr_json_fail(j, node, field, e, LR_EPARSE,
                            "expected a number or an array of 3 numbers, got %s",
                            lr_json_type_name(lr_json_type(j, node)));
    }
    for (int i = 0; i < 3; i++) {
        if (!(v[i] > 0.0)) {
            lr_jnode at = lr_json_type(j, node) == LR_JSON_ARRAY ? lr_json_at(j, node, i) : node;
            return lr_json_fail(j, at, field, e, LR_EINVAL, "must be > 0, got %g", v[i]);
        }
    }
    memcpy(out, v, sizeof v);
    return LR_OK;
}

/* Resolves `base` (a plain preset name) in base_dir and loads it with cycle detection. */
static int load_base(const lr_json *j, lr_jnode node, const char *field, const char *base_dir,
                     chain *ch, lr_medium *out, lr_err *e)
{
    char name[LR_MATERIAL_NAME_MAX];
    int rc = lr_json_string(j, node, field, name, sizeof name, e);
    if (rc)
        return rc;
    if (!lr_material_name_ok(name))
        return lr_json_fail(j, node, field, e, LR_EINVAL,
                            "'%s' is not a preset name (letters, digits, '_', '-', '.'; no '/' "
                            "or leading '.')",
                            name);
    char path[PATH_MAX];
    char leaf[LR_MATERIAL_NAME_MAX + 16];
    snprintf(leaf, sizeof leaf, "%s.json", name);
    if (lr_path_join(path, sizeof path, base_dir, leaf, NULL) != 0)
        return lr_json_fail(j, node, field, e, LR_EINVAL, "path of preset '%s' too long", name);
    char real[PATH_MAX];
    if (!realpath(path, real))
        return lr_json_fail(j, node, field, e, LR_EIO, "no preset '%s' (%s not found)", name,
                            path);
    for (int i = 0; i < ch->n; i++) {
        if (strcmp(ch->real[i], real) == 0) {
            char cyc[LR_ERR_MSG_MAX] = "";
            size_t o = 0;
            for (int k = i; k < ch->n && o < sizeof cyc; k++)
                o += (size_t)snprintf(cyc + o, sizeof cyc - o, "%s -> ", ch->name[k]);
            if (o < sizeof cyc)
                snprintf(cyc + o, sizeof cyc - o, "%s", name);
            return lr_json_fail(j, node, field, e, LR_EINVAL, "base cycle: %s", cyc);
        }
    }
    if (ch->n >= LR_MATERIAL_BASE_DEPTH)
        return lr_json_fail(j, node, field, e, LR_EINVAL,
                            "more than %d levels of 'base' presets", LR_MATERIAL_BASE_DEPTH);
    lr_material base;
    rc = load_file(path, base_dir, name, ch, &base, e);
    if (rc) {
        /* Keep the inner message (it names the base's own file, line and field) and say
         * which reference led there. */
        char inner[LR_ERR_MSG_MAX];
        snprintf(inner, sizeof inner, "%s", e ? e->msg : "");
        return lr_json_fail(j, node, field, e, rc, "in base preset '%s': %s", name, inner);
    }
    *out = base.medium;
    return LR_OK;
}

/* The node whose line best locates a lr_medium_validate message (it names the field). */
static lr_jnode node_for_message(const lr_json *j, lr_jnode obj, const char *msg,
                                 const char **key)
{
    static const char *const keys[] = {"sigma_s_prime", "sigma_a", "eta", "g", NULL};
    for (const char *const *k = keys; *k; k++) {
        const char *p = strstr(msg, *k);
        /* "g" alone would match inside other words; require it to stand as a word. */
        while (p && strcmp(*k, "g") == 0 &&
               ((p > msg && (p[-1] >= 'a' && p[-1] <= 'z')) || (p[1] >= 'a' && p[1] <= 'z')))
            p = strstr(p + 1, *k);
        if (p) {
            lr_jnode n = lr_json_get(j, obj, *k);
            *key = *k;
            return n != LR_JNONE ? n : obj;
        }
    }
    *key = NULL;
    return obj;
}

static int parse_object(const lr_json *j, lr_jnode obj, const char *where, const char *base_dir,
                        const char *expect_name, chain *ch, lr_material *out, lr_err *e)
{
    static const char *const allowed[] = {"name",  "source", "sigma_a", "sigma_s_prime",
                                          "eta",   "g",      "base",    "scale",
                                          "sh_scale", NULL};
    const char *what = where && where[0] ? where : "material";
    char f[256];
    int rc = lr_json_check_keys(j, obj, what, allowed, e);
    if (rc)
        return rc;

    lr_material m;
    memset(&m, 0, sizeof m);

    lr_jnode n = lr_json_get(j, obj, "name");
    if (n == LR_JNONE)
        return lr_json_fail(j, obj, field_name(f, sizeof f, where, "name"), e, LR_EPARSE,
                            "missing (required)");
    rc = lr_json_string(j, n, field_name(f, sizeof f, where, "name"), m.name, sizeof m.name, e);
    if (rc)
        return rc;
    if (!m.name[0])
        return lr_json_fail(j, n, f, e, LR_EINVAL, "must not be empty");
    if (expect_name && strcmp(m.name, expect_name) != 0)
        return lr_json_fail(j, n, f, e, LR_EINVAL,
                            "is '%s' but the preset file is named '%s.json' (they must agree)",
                            m.name, expect_name);

    n = lr_json_get(j, obj, "source");
    if (n == LR_JNONE)
        return lr_json_fail(j, obj, field_name(f, sizeof f, where, "source"), e, LR_EPARSE,
                            "missing (required: cite where the numbers come from)");
    rc = lr_json_string(j, n, field_name(f, sizeof f, where, "source"), m.source,
                        sizeof m.source, e);
    if (rc)
        return rc;
    if (!m.source[0])
        return lr_json_fail(j, n, f, e, LR_EINVAL,
                            "must not be empty (cite where the numbers come from)");

    lr_jnode base = lr_json_get(j, obj, "base");
    lr_jnode scale = lr_json_get(j, obj, "scale");
    bool have_base = base != LR_JNONE;
    if (have_base) {
        rc = load_base(j, base, field_name(f, sizeof f, where, "base"), base_dir, ch, &m.medium,
                       e);
        if (rc)
            return rc;
    } else if (scale != LR_JNONE) {
        return lr_json_fail(j, scale, field_name(f, sizeof f, where, "scale"), e, LR_EPARSE,
                            "needs 'base' (scale multiplies the base preset's coefficients)");
    }
    if (scale != LR_JNONE) {
        double s[3];
        rc = get_scale(j, scale, field_name(f, sizeof f, where, "scale"), s, e);
        if (rc)
            return rc;
        for (int i = 0; i < 3; i++) {
            m.medium.sigma_a[i] *= s[i];
            m.medium.sigma_s_prime[i] *= s[i];
        }
    }

    /* Without a base these three are required; with one they are optional overrides. */
    static const char *const coeff_keys[] = {"sigma_a", "sigma_s_prime"};
    for (int k = 0; k < 2; k++) {
        double *dst = k == 0 ? m.medium.sigma_a : m.medium.sigma_s_prime;
        n = lr_json_get(j, obj, coeff_keys[k]);
        field_name(f, sizeof f, where, coeff_keys[k]);
        if (n == LR_JNONE) {
            if (!have_base)
                return lr_json_fail(j, obj, f, e, LR_EPARSE,
                                    "missing (required unless 'base' is given)");
            continue;
        }
        rc = get_coeffs(j, n, f, dst, e);
        if (rc)
            return rc;
    }
    n = lr_json_get(j, obj, "eta");
    field_name(f, sizeof f, where, "eta");
    if (n == LR_JNONE) {
        if (!have_base)
            return lr_json_fail(j, obj, f, e, LR_EPARSE,
                                "missing (required unless 'base' is given)");
    } else {
        rc = lr_json_number(j, n, f, &m.medium.eta, e);
        if (rc)
            return rc;
        if (!(m.medium.eta > 0.0))
            return lr_json_fail(j, n, f, e, LR_EINVAL,
                                "relative index of refraction must be > 0, got %g",
                                m.medium.eta);
    }
    n = lr_json_get(j, obj, "g");
    if (n != LR_JNONE) {
        field_name(f, sizeof f, where, "g");
        rc = lr_json_number(j, n, f, &m.medium.g, e);
        if (rc)
            return rc;
        if (!(m.medium.g > -1.0 && m.medium.g < 1.0))
            return lr_json_fail(j, n, f, e, LR_EINVAL, "must be in (-1, 1), got %g",
                                m.medium.g);
    }

    /* Seed 002's energy scale (render/optics/sh_translucency.h); never taken from a base: a
     * scaled or overridden medium has its own fit. */
    n = lr_json_get(j, obj, "sh_scale");
    if (n != LR_JNONE) {
        rc = get_scale(j, n, field_name(f, sizeof f, where, "sh_scale"), m.sh_scale, e);
        if (rc)
            return rc;
    }

    /* The optics' own range checks (sigma_t' > 0, eta range of the Fresnel fits, ...). */
    lr_err ve = {0};
    rc = lr_medium_validate(&m.medium, &ve);
    if (rc) {
        const char *key = NULL;
        lr_jnode at = node_for_message(j, obj, ve.msg, &key);
        return lr_json_fail(j, at, field_name(f, sizeof f, where, key ? key : "medium"), e, rc,
                            "%s%s", ve.msg, have_base && scale != LR_JNONE
                                                ? " (after applying 'scale' to the base)"
                                                : "");
    }
    *out = m;
    return LR_OK;
}

static int load_file(const char *path, const char *base_dir, const char *expect_name, chain *ch,
                     lr_material *out, lr_err *e)
{
    lr_json *j = NULL;
    int rc = lr_json_load(path, &j, e);
    if (rc)
        return rc;
    int slot = ch->n;
    if (!realpath(path, ch->real[slot]))
        snprintf(ch->real[slot], sizeof ch->real[slot], "%s", path);
    const char *leaf = strrchr(path, '/');
    leaf = leaf ? leaf + 1 : path;
    snprintf(ch->name[slot], sizeof ch->name[slot], "%.*s",
             (int)(strlen(leaf) > 5 && strcmp(leaf + strlen(leaf) - 5, ".json") == 0
                       ? strlen(leaf) - 5
                       : strlen(leaf)),
             leaf);
    ch->n++;
    rc = parse_object(j, lr_json_root(j), "", base_dir, expect_name, ch, out, e);
    ch->n--;
    lr_json_destroy(j);
    return rc;
}

int lr_material_load(const char *path, lr_material *out, lr_err *e)
{
    char dir[PATH_MAX];
    const char *slash = strrchr(path, '/');
    if (slash)
        snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    else
        snprintf(dir, sizeof dir, ".");
    if (!dir[0]) /* "/name.json" */
        snprintf(dir, sizeof dir, "/");
    chain *ch = calloc(1, sizeof *ch);
    if (!ch)
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
    int rc = load_file(path, dir, NULL, ch, out, e);
    free(ch);
    return rc;
}

/* <configs>/materials */
static int presets_dir(char *buf, size_t cap, lr_err *e)
{
    if (lr_path_join(buf, cap, lr_configs_dir(), "materials", NULL) != 0)
        return lr_err_set(e, LR_EINVAL, "configs path too long: %s", lr_configs_dir());
    return LR_OK;
}

int lr_material_from_json(const lr_json *j, lr_jnode obj, const char *where, lr_material *out,
                          lr_err *e)
{
    char dir[PATH_MAX];
    int rc = presets_dir(dir, sizeof dir, e);
    if (rc)
        return rc;
    chain *ch = calloc(1, sizeof *ch);
    if (!ch)
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory", lr_json_name(j));
    rc = parse_object(j, obj, where, dir, NULL, ch, out, e);
    free(ch);
    return rc;
}

int lr_material_find(const char *name, lr_material *out, lr_err *e)
{
    if (!lr_material_name_ok(name))
        return lr_err_set(e, LR_EINVAL,
                          "material '%s': not a preset name (letters, digits, '_', '-', '.'; "
                          "no '/' or leading '.')",
                          name ? name : "(null)");
    char dir[PATH_MAX], path[PATH_MAX], leaf[LR_MATERIAL_NAME_MAX + 16];
    int rc = presets_dir(dir, sizeof dir, e);
    if (rc)
        return rc;
    snprintf(leaf, sizeof leaf, "%s.json", name);
    if (lr_path_join(path, sizeof path, dir, leaf, NULL) != 0)
        return lr_err_set(e, LR_EINVAL, "material '%s': path too long", name);
    chain *ch = calloc(1, sizeof *ch);
    if (!ch)
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
    rc = load_file(path, dir, name, ch, out, e);
    free(ch);
    return rc;
}
