/* Scene files: JSON to validated records through the field tables (fields.h), then meshes and
 * materials (schema in scene.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/json.h"
#include "render/scene/fields.h"
#include "render/scene/scene_internal.h"

typedef struct ctx {
    const lr_json *j;
    lr_err *e;
    lr_scene *s;
} ctx;

static const char *cat(char *buf, size_t cap, const char *where, const char *key)
{
    snprintf(buf, cap, "%s.%s", where, key);
    return buf;
}

/* The node a record check's field name points at ("flicker.amplitude" -> obj.flicker.amplitude),
 * or the deepest object on the way when the field is absent (a default). */
static lr_jnode locate(const lr_json *j, lr_jnode obj, const char *field)
{
    char part[64];
    const char *p = field;
    lr_jnode n = obj;
    while (*p) {
        const char *dot = strchr(p, '.');
        size_t len = dot ? (size_t)(dot - p) : strlen(p);
        snprintf(part, sizeof part, "%.*s", (int)len, p);
        lr_jnode next = lr_json_get(j, n, part);
        if (next == LR_JNONE)
            return n;
        n = next;
        p += len + (dot ? 1 : 0);
    }
    return n;
}

/* Re-reports a record check's message at the file position of the field it names. */
static int fail_check(ctx *c, lr_jnode obj, const char *where, const char *field, int rc,
                      const lr_err *inner)
{
    char f[256];
    return lr_json_fail(c->j, locate(c->j, obj, field ? field : ""), cat(f, sizeof f, where,
                        field ? field : "?"), c->e, rc, "%s", inner->msg);
}

/* The table's keys for this kind (fields.h) as the allowed keys of obj. */
static int check_keys(ctx *c, lr_jnode obj, const char *where, const lr_record_desc *d, int kind)
{
    const char *keys[40];
    lr_fields_keys(d, kind, "", keys, 40);
    return lr_json_check_keys(c->j, obj, where, keys, c->e);
}

/* Names are how lr_scene_set finds things: plain, not all digits (those are indices). */
static bool name_ok(const char *s)
{
    bool digits = true;
    if (!s[0])
        return false;
    for (const char *p = s; *p; p++) {
        char ch = *p;
        if (!((ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') ||
              ch == '_' || ch == '-'))
            return false;
        digits = digits && ch >= '0' && ch <= '9';
    }
    return !digits;
}

static int get_name(ctx *c, lr_jnode obj, const char *where, const char *dflt, int index,
                    char out[LR_SCENE_NAME_MAX])
{
    lr_jnode n = lr_json_get(c->j, obj, "name");
    if (n == LR_JNONE) {
        snprintf(out, LR_SCENE_NAME_MAX, "%s%d", dflt, index);
        return LR_OK;
    }
    char f[256];
    int rc = lr_json_string(c->j, n, cat(f, sizeof f, where, "name"), out, LR_SCENE_NAME_MAX, c->e);
    if (rc)
        return rc;
    if (!name_ok(out))
        return lr_json_fail(c->j, n, f, c->e, LR_EINVAL,
                            "'%s': use letters, digits, '_' and '-' (not only digits)", out);
    return LR_OK;
}

static int type_of(ctx *c, lr_jnode obj, const char *where, const char *const *names,
                   const char *dflt, int *out)
{
    char f[256], t[32];
    cat(f, sizeof f, where, "type");
    lr_jnode n = lr_json_get(c->j, obj, "type");
    if (n == LR_JNONE) {
        if (!dflt)
            return lr_json_fail(c->j, obj, f, c->e, LR_EPARSE, "missing (required)");
        snprintf(t, sizeof t, "%s", dflt);
    } else {
        int rc = lr_json_string(c->j, n, f, t, sizeof t, c->e);
        if (rc)
            return rc;
    }
    char list[256] = "";
    for (int i = 0; names[i]; i++) {
        if (strcmp(t, names[i]) == 0) {
            *out = i;
            return LR_OK;
        }
        snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", i ? ", " : "",
                 names[i]);
    }
    return lr_json_fail(c->j, n, f, c->e, LR_EINVAL, "unknown type '%s' (one of: %s)", t, list);
}

/* ---- lights -------------------------------------------------------------------------------- */

/* A light's strength is given once, in one unit (the others are derived from it: a file
 * that gave two could disagree with itself), and its colour once: `color` or
 * `color_temperature_k`. Directional lights have `radiance` only. */
static int light_strength(ctx *c, lr_jnode obj, const char *where, lr_light *l)
{
    static const char *const keys[] = {"intensity", "radiance", "intensity_cd", "flux_lm"};
    static const enum lr_light_strength from[] = {LR_STRENGTH_RADIOMETRIC,
        LR_STRENGTH_RADIOMETRIC, LR_STRENGTH_CD, LR_STRENGTH_LM};
    char f[96], list[96] = "";
    int given = -1;
    for (int k = 0; k < 4; k++)
        if (lr_field_find(&lr_scene_light_desc, (int)l->type, keys[k]))
            snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s",
                     list[0] ? ", " : "", keys[k]);
    for (int k = 0; k < 4; k++) {
        if (!lr_field_find(&lr_scene_light_desc, (int)l->type, keys[k]))
            continue;
        lr_jnode n = lr_json_get(c->j, obj, keys[k]);
        if (n == LR_JNONE)
            continue;
        if (given >= 0) {
            snprintf(f, sizeof f, "%s.%s", where, keys[k]);
            return lr_json_fail(c->j, n, f, c->e, LR_EINVAL, "give one of %s, not both '%s' "
                                "and '%s'", list, keys[given], keys[k]);
        }
        given = k;
    }
    if (given < 0 && l->profile.on) {
        /* The file's own strength: its stated flux, else (absolute photometry) its candela. */
        if (l->profile.lumens > 0.0) {
            l->from = LR_STRENGTH_LM;
            l->flux_lm = l->profile.lumens;
        } else if (!lr_light_is_area(l)) {
            l->from = LR_STRENGTH_CD;
            l->intensity_cd = l->profile.max_cd;
        } else {
            return lr_json_fail(c->j, obj, where, c->e, LR_EPARSE, "missing its strength: the "
                                "profile states no flux (required: one of %s)", list);
        }
    } else if (given < 0) {
        return lr_json_fail(c->j, obj, where, c->e, LR_EPARSE, "missing its strength (required: "
                            "one of %s)", list);
    } else {
        l->from = from[given];
    }
    lr_jnode t = lr_json_get(c->j, obj, "color_temperature_k");
    if (t != LR_JNONE && lr_json_get(c->j, obj, "color") != LR_JNONE) {
        snprintf(f, sizeof f, "%s.color_temperature_k", where);
        return lr_json_fail(c->j, t, f, c->e, LR_EINVAL, "give one of color and "
                            "color_temperature_k, not both");
    }
    return LR_OK;
}

static int parse_light(ctx *c, lr_jnode obj, int i, lr_light *l)
{
    char where[64];
    snprintf(where, sizeof where, "lights[%d]", i);
    int type = 0, rc;
    if (lr_json_type(c->j, obj) != LR_JSON_OBJECT)
        return lr_json_fail(c->j, obj, where, c->e, LR_EPARSE, "expected an object");
    if ((rc = type_of(c, obj, where, lr_scene_light_desc.kind_names, NULL, &type)) ||
        (rc = check_keys(c, obj, where, &lr_scene_light_desc, type)))
        return rc;
    lr_scene_light_defaults(l, (enum lr_light_type)type);
    if ((rc = get_name(c, obj, where, "light", i, l->name)))
        return rc;
    if ((rc = lr_fields_read(c->j, obj, where, &lr_scene_light_desc, type, l, c->e)))
        return rc;
    if (l->profile_path[0]) {
        /* The photometric file, relative to the scene; its errors name the file's line. */
        char path[LR_SCENE_PATH_MAX], f[96];
        lr_err inner = {0};
        lr_jnode at = lr_json_get(c->j, obj, "profile");
        snprintf(f, sizeof f, "%s.profile", where);
        if (lr_scene_resolve_path(c->s, l->profile_path, path, sizeof path))
            return lr_json_fail(c->j, at, f, c->e, LR_EINVAL, "path too long");
        if ((rc = lr_light_profile_load(path, &l->profile, &inner)))
            return lr_json_fail(c->j, at, f, c->e, rc, "%s", inner.msg);
    }
    if ((rc = light_strength(c, obj, where, l)))
        return rc;
    const char *field = NULL;
    lr_err inner = {0};
    if ((rc = lr_scene_check_light(l, &field, &inner)))
        return fail_check(c, obj, where, field, rc, &inner);
    return LR_OK;
}

/* ---- camera -------------------------------------------------------------------------------- */

static int parse_camera(ctx *c, lr_jnode obj, lr_camera *cam)
{
    const char *where = "camera";
    int rc;
    if ((rc = check_keys(c, obj, where, &lr_scene_camera_desc, 0)))
        return rc;
    lr_scene_camera_defaults(cam);
    if ((rc = lr_fields_read(c->j, obj, where, &lr_scene_camera_desc, 0, cam, c->e)))
        return rc;
    const char *field = NULL;
    lr_err inner = {0};
    if ((rc = lr_scene_check_camera(cam, &field, &inner)))
        return fail_check(c, obj, where, field, rc, &inner);
    return LR_OK;
}

/* ---- receivers ------------------------------------------------------------------------------ */

static int parse_receiver(ctx *c, lr_jnode obj, int i, lr_receiver *r)
{
    char where[64];
    snprintf(where, sizeof where, "receivers[%d]", i);
    int type = 0, rc;
    if (lr_json_type(c->j, obj) != LR_JSON_OBJECT)
        return lr_json_fail(c->j, obj, where, c->e, LR_EPARSE, "expected an object");
    if ((rc = type_of(c, obj, where, lr_scene_receiver_desc.kind_names, NULL, &type)) ||
        (rc = check_keys(c, obj, where, &lr_scene_receiver_desc, type)))
        return rc;
    memset(r, 0, sizeof *r);
    r->type = (enum lr_receiver_type)type;
    lr_fields_defaults(&lr_scene_receiver_desc, r);
    if ((rc = get_name(c, obj, where, "receiver", i, r->name)))
        return rc;
    if ((rc = lr_fields_read(c->j, obj, where, &lr_scene_receiver_desc, type, r, c->e)))
        return rc;
    const char *field = NULL;
    lr_err inner = {0};
    if ((rc = lr_scene_check_receiver(r, &field, &inner)))
        return fail_check(c, obj, where, field, rc, &inner);
    return LR_OK;
}

/* ---- objects -------------------------------------------------------------------------------- */

static int parse_mesh(ctx *c, lr_jnode obj, const char *owhere, mesh_spec *m)
{
    char where[96];
    cat(where, sizeof where, owhere, "mesh");
    int type = 0, rc;
    if (lr_json_type(c->j, obj) != LR_JSON_OBJECT)
        return lr_json_fail(c->j, obj, where, c->e, LR_EPARSE, "expected an object, got %s",
                            lr_json_type_name(lr_json_type(c->j, obj)));
    if ((rc = type_of(c, obj, where, lr_scene_mesh_desc.kind_names, NULL, &type)) ||
        (rc = check_keys(c, obj, where, &lr_scene_mesh_desc, type)))
        return rc;
    memset(m, 0, sizeof *m);
    m->kind = (enum lr_mesh_kind)type;
    lr_fields_defaults(&lr_scene_mesh_desc, m);
    if ((rc = lr_fields_read(c->j, obj, where, &lr_scene_mesh_desc, type, m, c->e)))
        return rc;
    const char *field = NULL;
    lr_err inner = {0};
    if ((rc = lr_scene_check_mesh(m, &field, &inner)))
        return fail_check(c, obj, where, field, rc, &inner);
    return LR_OK;
}

static int parse_material(ctx *c, lr_jnode n, const char *owhere, mat_spec *ms, lr_material *out)
{
    char where[96];
    cat(where, sizeof where, owhere, "material");
    memset(ms, 0, sizeof *ms);
    int rc;
    if (lr_json_type(c->j, n) == LR_JSON_STRING) {
        ms->is_preset = true;
        if ((rc = lr_json_string(c->j, n, where, ms->preset, sizeof ms->preset, c->e)))
            return rc;
        lr_err inner = {0};
        if ((rc = lr_material_find(ms->preset, out, &inner)))
            return lr_json_fail(c->j, n, where, c->e, rc, "no usable preset '%s': %s",
                                ms->preset, inner.msg);
        return LR_OK;
    }
    if (lr_json_type(c->j, n) != LR_JSON_OBJECT)
        return lr_json_fail(c->j, n, where, c->e, LR_EPARSE,
                            "expected a preset name or a material object, got %s",
                            lr_json_type_name(lr_json_type(c->j, n)));
    if ((rc = lr_material_from_json(c->j, n, where, out, c->e)))
        return rc;
    /* Valid now: keep what was written, for changes of single fields later. */
    const lr_json *j = c->j;
    lr_json_get_string(j, n, "name", false, ms->name, sizeof ms->name, NULL);
    lr_json_get_string(j, n, "source", false, ms->source, sizeof ms->source, NULL);
    ms->has_base = lr_json_get_string(j, n, "base", false, ms->base, sizeof ms->base, NULL) ==
                       LR_OK && lr_json_get(j, n, "base") != LR_JNONE;
    lr_jnode sc = lr_json_get(j, n, "scale");
    if (sc != LR_JNONE) {
        ms->has_scale = true;
        if (lr_json_type(j, sc) == LR_JSON_NUMBER) {
            lr_json_number(j, sc, "scale", &ms->scale[0], NULL);
            ms->scale[1] = ms->scale[2] = ms->scale[0];
        } else {
            lr_json_numbers(j, sc, "scale", ms->scale, 3, NULL);
        }
    }
    ms->has_sigma_a = lr_json_get(j, n, "sigma_a") != LR_JNONE;
    if (ms->has_sigma_a)
        lr_json_get_numbers(j, n, "sigma_a", false, ms->sigma_a, 3, NULL);
    ms->has_sigma_s_prime = lr_json_get(j, n, "sigma_s_prime") != LR_JNONE;
    if (ms->has_sigma_s_prime)
        lr_json_get_numbers(j, n, "sigma_s_prime", false, ms->sigma_s_prime, 3, NULL);
    ms->has_eta = lr_json_get(j, n, "eta") != LR_JNONE;
    if (ms->has_eta)
        lr_json_get_number(j, n, "eta", false, &ms->eta, NULL);
    ms->has_g = lr_json_get(j, n, "g") != LR_JNONE;
    if (ms->has_g)
        lr_json_get_number(j, n, "g", false, &ms->g, NULL);
    return LR_OK;
}

static int parse_transform(ctx *c, lr_jnode n, const char *owhere, xform_spec *x)
{
    lr_fields_defaults(&lr_scene_transform_desc, x);
    if (n == LR_JNONE)
        return LR_OK;
    char where[96];
    cat(where, sizeof where, owhere, "transform");
    int rc;
    if ((rc = check_keys(c, n, where, &lr_scene_transform_desc, 0)))
        return rc;
    if ((rc = lr_fields_read(c->j, n, where, &lr_scene_transform_desc, 0, x, c->e)))
        return rc;
    const char *field = NULL;
    lr_err inner = {0};
    if ((rc = lr_scene_check_transform(x, &field, &inner)))
        return fail_check(c, n, where, field, rc, &inner);
    return LR_OK;
}

static int parse_object(ctx *c, lr_jnode obj, int i, obj_rec *o)
{
    char where[64];
    snprintf(where, sizeof where, "objects[%d]", i);
    if (lr_json_type(c->j, obj) != LR_JSON_OBJECT)
        return lr_json_fail(c->j, obj, where, c->e, LR_EPARSE, "expected an object");
    int rc;
    /* normalize: PIPELINE.md "Energy": S_d energy-normalised unless false. */
    lr_fields_defaults(&lr_scene_object_desc, o);
    if ((rc = check_keys(c, obj, where, &lr_scene_object_desc, 0)) ||
        (rc = get_name(c, obj, where, "object", i, o->pub.name)) ||
        (rc = lr_fields_read(c->j, obj, where, &lr_scene_object_desc, 0, o, c->e)))
        return rc;
    char f[256];
    const char *field = NULL;
    lr_err inner = {0};
    if ((rc = lr_fields_check(&lr_scene_object_desc, o, &field, &inner)))
        return fail_check(c, obj, where, field, rc, &inner);
    if (lr_sss_model_props_of(o->pub.sss_model)->needs_thickness && !(o->pub.thickness_mm > 0.0))
        return lr_json_fail(c->j, obj, cat(f, sizeof f, where, "thickness_mm"), c->e, LR_EPARSE,
                            "missing (required with model %s)",
                            lr_sss_model_name(o->pub.sss_model));
    lr_jnode mat = lr_json_get(c->j, obj, "material"), mesh = lr_json_get(c->j, obj, "mesh");
    if (mat == LR_JNONE)
        return lr_json_fail(c->j, obj, cat(f, sizeof f, where, "material"), c->e, LR_EPARSE,
                            "missing (required: a preset name or a material object)");
    if (mesh == LR_JNONE)
        return lr_json_fail(c->j, obj, cat(f, sizeof f, where, "mesh"), c->e, LR_EPARSE,
                            "missing (required)");
    if ((rc = parse_material(c, mat, where, &o->mat, &o->pub.material)) ||
        (rc = parse_mesh(c, mesh, where, &o->mesh)) ||
        (rc = parse_transform(c, lr_json_get(c->j, obj, "transform"), where, &o->xf)))
        return rc;
    if ((rc = lr_coeffs_derive(&o->pub.material.medium, &o->pub.coeffs, &inner)) ||
        (rc = lr_sss_model_check_medium(o->pub.sss_model, &o->pub.material.medium, &inner)))
        return lr_json_fail(c->j, mat, cat(f, sizeof f, where, "material"), c->e, rc, "%s",
                            inner.msg);
    o->pub.kind = o->mesh.kind;
    if ((rc = lr_scene_build_object(c->s, where, &o->mesh, &o->xf, &o->world, &o->built, &o->bvh,
                                    o->pub.model, &inner))) {
        /* A file that cannot be read or is broken: point at the path in the scene. */
        lr_jnode at = o->mesh.kind == LR_MESH_FILE ? lr_json_get(c->j, mesh, "path") : mesh;
        return lr_json_fail(c->j, at, cat(f, sizeof f, where,
                                          o->mesh.kind == LR_MESH_FILE ? "mesh.path" : "mesh"),
                            c->e, rc, "%s", inner.msg);
    }
    lr_scene_object_attach(&o->pub, o->world, o->built, o->bvh);
    return LR_OK;
}

/* ---- settings -------------------------------------------------------------------------------- */

static int parse_render(ctx *c, lr_jnode n, lr_scene *s)
{
    lr_render_settings *r = &s->render;
    lr_scene_render_defaults(r); /* zero or absent: the default */
    if (n == LR_JNONE)
        return LR_OK;
    int rc;
    if ((rc = check_keys(c, n, "render", &lr_scene_render_desc, 0)))
        return rc;
    if ((rc = lr_fields_read(c->j, n, "render", &lr_scene_render_desc, 0, r, c->e)))
        return rc;
    for (int i = 0; i < lr_scene_render_desc.n; i++)
        if (lr_json_get(c->j, n, lr_scene_render_desc.fields[i].key) != LR_JNONE)
            lr_scene_render_mark_given(s, lr_scene_render_desc.fields[i].key);
    lr_jnode ev = lr_json_get(c->j, n, "exposure_ev");
    if (ev != LR_JNONE && lr_json_get(c->j, n, "exposure") != LR_JNONE)
        return lr_json_fail(c->j, ev, "render.exposure_ev", c->e, LR_EINVAL,
                            "give one of exposure and exposure_ev, not both");
    r->exposure_from_ev = ev != LR_JNONE;
    const char *field = NULL;
    lr_err inner = {0};
    if ((rc = lr_scene_check_render(r, &field, &inner)))
        return fail_check(c, n, "render", field, rc, &inner);
    return LR_OK;
}

static int parse_quality(ctx *c, lr_jnode n, lr_quality *q)
{
    memset(q, 0, sizeof *q);
    if (n == LR_JNONE)
        return LR_OK;
    int rc;
    if ((rc = check_keys(c, n, "quality", &lr_scene_quality_desc, 0)))
        return rc;
    if ((rc = lr_fields_read(c->j, n, "quality", &lr_scene_quality_desc, 0, q, c->e)))
        return rc;
    const char *field = NULL;
    lr_err inner = {0};
    if ((rc = lr_scene_check_quality(q, &field, &inner)))
        return fail_check(c, n, "quality", field, rc, &inner);
    return LR_OK;
}

/* ---- the document ----------------------------------------------------------------------------- */

static int array_of(ctx *c, lr_jnode root, const char *key, bool required, lr_jnode *out)
{
    *out = lr_json_get(c->j, root, key);
    if (*out == LR_JNONE)
        return required ? lr_json_fail(c->j, root, key, c->e, LR_EPARSE, "missing (required)")
                        : LR_OK;
    if (lr_json_type(c->j, *out) != LR_JSON_ARRAY)
        return lr_json_fail(c->j, *out, key, c->e, LR_EPARSE, "expected an array, got %s",
                            lr_json_type_name(lr_json_type(c->j, *out)));
    if (required && lr_json_count(c->j, *out) == 0)
        return lr_json_fail(c->j, *out, key, c->e, LR_EPARSE, "must not be empty");
    if (lr_json_count(c->j, *out) > 256)
        return lr_json_fail(c->j, *out, key, c->e, LR_EPARSE, "more than 256 entries");
    return LR_OK;
}

/* Names must be unique within their list: lr_scene_set finds elements by name. */
static int unique_names(ctx *c, lr_jnode arr, const char *key, const char *(*name_at)(lr_scene *, int),
                        int count)
{
    for (int i = 0; i < count; i++)
        for (int k = 0; k < i; k++)
            if (strcmp(name_at(c->s, i), name_at(c->s, k)) == 0) {
                char f[64];
                snprintf(f, sizeof f, "%s[%d].name", key, i);
                return lr_json_fail(c->j, lr_json_at(c->j, arr, i), f, c->e, LR_EINVAL,
                                    "'%s' is already the name of %s[%d]", name_at(c->s, i), key,
                                    k);
            }
    return LR_OK;
}

static const char *obj_name(lr_scene *s, int i) { return s->obj[i].pub.name; }
static const char *light_name(lr_scene *s, int i) { return s->light[i].name; }
static const char *recv_name(lr_scene *s, int i) { return s->recv[i].pub.name; }

static int parse_document(ctx *c)
{
    const lr_json *j = c->j;
    lr_scene *s = c->s;
    lr_jnode root = lr_json_root(j);
    static const char *const keys[] = {"name", "objects", "lights", "camera", "receivers",
                                       "render", "quality", NULL};
    int rc;
    if ((rc = lr_json_check_keys(j, root, "scene", keys, c->e)))
        return rc;
    lr_jnode nn = lr_json_get(j, root, "name");
    if (nn != LR_JNONE &&
        (rc = lr_json_string(j, nn, "name", s->name, sizeof s->name, c->e)))
        return rc;
    lr_jnode objs, lights, recvs;
    if ((rc = array_of(c, root, "objects", true, &objs)) ||
        (rc = array_of(c, root, "lights", true, &lights)) ||
        (rc = array_of(c, root, "receivers", false, &recvs)))
        return rc;
    int no = lr_json_count(j, objs), nl = lr_json_count(j, lights);
    if (nl > LR_SCENE_MAX_LIGHTS)
        return lr_json_fail(j, lights, "lights", c->e, LR_EINVAL,
                            "%d lights; at most %d (each has its own G-buffer and radiosity maps)",
                            nl, LR_SCENE_MAX_LIGHTS);
    int nr = recvs == LR_JNONE ? 0 : lr_json_count(j, recvs);
    s->obj = calloc((size_t)no, sizeof *s->obj);
    s->light = calloc((size_t)nl, sizeof *s->light);
    s->recv = calloc(nr ? (size_t)nr : 1, sizeof *s->recv);
    if (!s->obj || !s->light || !s->recv)
        return lr_err_set(c->e, LR_ENOMEM, "%s: out of memory", s->path);
    for (int i = 0; i < nl; i++) {
        if ((rc = parse_light(c, lr_json_at(j, lights, i), i, &s->light[i])))
            return rc;
        s->nlight = i + 1;
    }
    if ((rc = unique_names(c, lights, "lights", light_name, nl)))
        return rc;
    lr_jnode cam = lr_json_get(j, root, "camera");
    if (cam == LR_JNONE)
        return lr_json_fail(j, root, "camera", c->e, LR_EPARSE, "missing (required)");
    if ((rc = parse_camera(c, cam, &s->camera)))
        return rc;
    if ((rc = parse_render(c, lr_json_get(j, root, "render"), s)) ||
        (rc = parse_quality(c, lr_json_get(j, root, "quality"), &s->quality)))
        return rc;
    for (int i = 0; i < nr; i++) {
        recv_rec *r = &s->recv[i];
        if ((rc = parse_receiver(c, lr_json_at(j, recvs, i), i, &r->pub)))
            return rc;
        lr_err inner = {0};
        if ((rc = lr_scene_build_receiver(s, &r->pub, &r->mesh, &r->bvh, &inner))) {
            char f[64];
            snprintf(f, sizeof f, "receivers[%d]", i);
            return lr_json_fail(j, lr_json_at(j, recvs, i), f, c->e, rc, "%s", inner.msg);
        }
        r->pub.mesh = r->mesh;
        r->pub.bvh = r->bvh;
        s->nrecv = i + 1;
    }
    if ((rc = unique_names(c, recvs, "receivers", recv_name, nr)))
        return rc;
    for (int i = 0; i < no; i++) {
        obj_rec *o = &s->obj[i];
        rc = parse_object(c, lr_json_at(j, objs, i), i, o);
        s->nobj = i + 1; /* so that destroy frees what this one built */
        if (rc)
            return rc;
    }
    if ((rc = unique_names(c, objs, "objects", obj_name, no)))
        return rc;
    /* A light that lights nothing the renderer draws (render/scene/dark.c): inside solid
     * material every ray from it meets the surface from behind, which the surface-incidence
     * BSSRDF (PIPELINE.md) counts as no light; zero power is no light. Say so rather than
     * render 0 silently (issues 3 and 33). */
    for (int i = 0; i < nl; i++) {
        char why[LR_ERR_MSG_MAX];
        if (!lr_scene_light_dark(s, i, why, sizeof why))
            continue;
        int line = lr_json_line(j, lr_json_at(j, lights, i));
        if (lr_scene_light_enclosure(s, i, NULL) == LR_ENCLOSURE_SOLID)
            lr_warn(&s->warn,
                    "%s:%d: %s: it lights nothing the renderer draws (the model has no term "
                    "for a source embedded in the medium; put the light in a cavity: a hollow "
                    "object)",
                    s->path, line, why);
        else
            lr_warn(&s->warn, "%s:%d: %s: it lights nothing the renderer draws", s->path, line,
                    why);
    }
    return LR_OK;
}

static int load_common(const char *name, lr_json *j, const lr_warn_sink *warn, lr_scene **out,
                       lr_err *e)
{
    lr_scene *s = calloc(1, sizeof *s);
    if (!s) {
        lr_json_destroy(j);
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory", name);
    }
    snprintf(s->path, sizeof s->path, "%s", name);
    const char *slash = strrchr(name, '/');
    if (slash)
        snprintf(s->dir, sizeof s->dir, "%.*s", (int)(slash - name), name);
    if (slash == name)
        snprintf(s->dir, sizeof s->dir, "/");
    const char *leaf = slash ? slash + 1 : name;
    size_t ll = strlen(leaf);
    snprintf(s->name, sizeof s->name, "%.*s",
             (int)(ll > 5 && strcmp(leaf + ll - 5, ".json") == 0 ? ll - 5 : ll), leaf);
    if (warn)
        s->warn = *warn;
    ctx c = {j, e, s};
    int rc = parse_document(&c);
    lr_json_destroy(j);
    if (rc) {
        lr_scene_destroy(s);
        return rc;
    }
    *out = s;
    return LR_OK;
}

int lr_scene_load(const char *path, const lr_warn_sink *warn, lr_scene **out, lr_err *e)
{
    *out = NULL;
    lr_json *j = NULL;
    int rc = lr_json_load(path, &j, e);
    if (rc)
        return rc;
    return load_common(path, j, warn, out, e);
}

int lr_scene_parse(const char *text, size_t len, const char *name, const lr_warn_sink *warn,
                   lr_scene **out, lr_err *e)
{
    *out = NULL;
    lr_json *j = NULL;
    int rc = lr_json_parse(text, len, name, &j, e);
    if (rc)
        return rc;
    return load_common(name, j, warn, out, e);
}
