/* Scene files: JSON to validated records, then meshes and materials (schema in scene.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/json.h"
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

static int get_num(ctx *c, lr_jnode obj, const char *where, const char *key, double *out)
{
    lr_jnode n = lr_json_get(c->j, obj, key);
    char f[256];
    return n == LR_JNONE ? LR_OK : lr_json_number(c->j, n, cat(f, sizeof f, where, key), out, c->e);
}

static int get_int(ctx *c, lr_jnode obj, const char *where, const char *key, int *out)
{
    lr_jnode n = lr_json_get(c->j, obj, key);
    if (n == LR_JNONE)
        return LR_OK;
    char f[256];
    long v;
    int rc = lr_json_int(c->j, n, cat(f, sizeof f, where, key), &v, c->e);
    if (rc)
        return rc;
    if (v < -1000000000L || v > 1000000000L)
        return lr_json_fail(c->j, n, f, c->e, LR_EINVAL, "out of range, got %ld", v);
    *out = (int)v;
    return LR_OK;
}

static int get_bool(ctx *c, lr_jnode obj, const char *where, const char *key, bool *out)
{
    lr_jnode n = lr_json_get(c->j, obj, key);
    char f[256];
    return n == LR_JNONE ? LR_OK : lr_json_bool(c->j, n, cat(f, sizeof f, where, key), out, c->e);
}

static int get_vec(ctx *c, lr_jnode obj, const char *where, const char *key, bool required,
                   lr_vec3 *out)
{
    lr_jnode n = lr_json_get(c->j, obj, key);
    char f[256];
    cat(f, sizeof f, where, key);
    if (n == LR_JNONE)
        return required ? lr_json_fail(c->j, obj, f, c->e, LR_EPARSE, "missing (required)")
                        : LR_OK;
    double v[3];
    int rc = lr_json_numbers(c->j, n, f, v, 3, c->e);
    if (!rc)
        *out = lr_v3(v[0], v[1], v[2]);
    return rc;
}

static int get_rgb(ctx *c, lr_jnode obj, const char *where, const char *key, bool required,
                   double out[3])
{
    lr_vec3 v = lr_v3(out[0], out[1], out[2]);
    int rc = get_vec(c, obj, where, key, required, &v);
    out[0] = v.x;
    out[1] = v.y;
    out[2] = v.z;
    return rc;
}

/* A number or [x, y, z] (a scale). */
static int get_scale3(ctx *c, lr_jnode obj, const char *where, const char *key, lr_vec3 *out)
{
    lr_jnode n = lr_json_get(c->j, obj, key);
    if (n == LR_JNONE)
        return LR_OK;
    char f[256];
    cat(f, sizeof f, where, key);
    if (lr_json_type(c->j, n) == LR_JSON_NUMBER) {
        double s;
        int rc = lr_json_number(c->j, n, f, &s, c->e);
        if (!rc)
            *out = lr_v3(s, s, s);
        return rc;
    }
    if (lr_json_type(c->j, n) != LR_JSON_ARRAY)
        return lr_json_fail(c->j, n, f, c->e, LR_EPARSE,
                            "expected a number or an array of 3 numbers, got %s",
                            lr_json_type_name(lr_json_type(c->j, n)));
    return get_vec(c, obj, where, key, true, out);
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

static int parse_light(ctx *c, lr_jnode obj, int i, lr_light *l)
{
    char where[64];
    snprintf(where, sizeof where, "lights[%d]", i);
    static const char *const types[] = {"point", "spot", "directional", NULL};
    int type = 0, rc;
    if (lr_json_type(c->j, obj) != LR_JSON_OBJECT)
        return lr_json_fail(c->j, obj, where, c->e, LR_EPARSE, "expected an object");
    if ((rc = type_of(c, obj, where, types, NULL, &type)))
        return rc;
    static const char *const k_point[] = {"type", "name", "position", "intensity", "color",
                                          "flicker", NULL};
    static const char *const k_spot[] = {"type", "name", "position", "direction", "inner_deg",
                                         "outer_deg", "intensity", "color", "flicker", NULL};
    static const char *const k_dir[] = {"type", "name", "direction", "radiance", "color", NULL};
    const char *const *allowed = type == 0 ? k_point : type == 1 ? k_spot : k_dir;
    if ((rc = lr_json_check_keys(c->j, obj, where, allowed, c->e)))
        return rc;
    lr_scene_light_defaults(l, (enum lr_light_type)type);
    if ((rc = get_name(c, obj, where, "light", i, l->name)))
        return rc;
    char f[256];
    if (type != LR_LIGHT_DIRECTIONAL) {
        if ((rc = get_vec(c, obj, where, "position", true, &l->position)))
            return rc;
        if (lr_json_get(c->j, obj, "intensity") == LR_JNONE)
            return lr_json_fail(c->j, obj, cat(f, sizeof f, where, "intensity"), c->e,
                                LR_EPARSE, "missing (required, W/sr)");
        if ((rc = get_num(c, obj, where, "intensity", &l->intensity)))
            return rc;
    } else {
        if (lr_json_get(c->j, obj, "radiance") == LR_JNONE)
            return lr_json_fail(c->j, obj, cat(f, sizeof f, where, "radiance"), c->e, LR_EPARSE,
                                "missing (required, W/mm^2)");
        if ((rc = get_num(c, obj, where, "radiance", &l->intensity)))
            return rc;
    }
    if (type != LR_LIGHT_POINT && (rc = get_vec(c, obj, where, "direction", true, &l->direction)))
        return rc;
    if ((rc = get_num(c, obj, where, "inner_deg", &l->inner_deg)) ||
        (rc = get_num(c, obj, where, "outer_deg", &l->outer_deg)) ||
        (rc = get_rgb(c, obj, where, "color", false, l->color)))
        return rc;
    lr_jnode fl = lr_json_get(c->j, obj, "flicker");
    if (fl != LR_JNONE) {
        static const char *const k_fl[] = {"amplitude", "frequency_hz", "jitter_mm", "seed",
                                           NULL};
        char fw[96];
        cat(fw, sizeof fw, where, "flicker");
        int seed = (int)l->flicker.seed;
        if ((rc = lr_json_check_keys(c->j, fl, fw, k_fl, c->e)) ||
            (rc = get_num(c, fl, fw, "amplitude", &l->flicker.amplitude)) ||
            (rc = get_num(c, fl, fw, "frequency_hz", &l->flicker.frequency_hz)) ||
            (rc = get_num(c, fl, fw, "jitter_mm", &l->flicker.jitter_mm)) ||
            (rc = get_int(c, fl, fw, "seed", &seed)))
            return rc;
        if (seed < 0)
            return lr_json_fail(c->j, lr_json_get(c->j, fl, "seed"), cat(f, sizeof f, fw, "seed"),
                                c->e, LR_EINVAL, "must be >= 0, got %d", seed);
        l->flicker.seed = (unsigned)seed;
    }
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
    static const char *const keys[] = {"type", "position", "target", "up", "fov_deg",
                                       "height_mm", "near", "far", NULL};
    static const char *const types[] = {"perspective", "orthographic", NULL};
    int rc, type = 0;
    if ((rc = lr_json_check_keys(c->j, obj, where, keys, c->e)) ||
        (rc = type_of(c, obj, where, types, "perspective", &type)))
        return rc;
    lr_scene_camera_defaults(cam);
    cam->orthographic = type == 1;
    if ((rc = get_vec(c, obj, where, "position", true, &cam->position)) ||
        (rc = get_vec(c, obj, where, "target", true, &cam->target)) ||
        (rc = get_vec(c, obj, where, "up", false, &cam->up)) ||
        (rc = get_num(c, obj, where, "fov_deg", &cam->fov_deg)) ||
        (rc = get_num(c, obj, where, "height_mm", &cam->height_mm)) ||
        (rc = get_num(c, obj, where, "near", &cam->near_mm)) ||
        (rc = get_num(c, obj, where, "far", &cam->far_mm)))
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
    static const char *const types[] = {"plane", "box", NULL};
    int type = 0, rc;
    if (lr_json_type(c->j, obj) != LR_JSON_OBJECT)
        return lr_json_fail(c->j, obj, where, c->e, LR_EPARSE, "expected an object");
    if ((rc = type_of(c, obj, where, types, NULL, &type)))
        return rc;
    static const char *const k_plane[] = {"name", "type", "center", "normal", "size", "u_dir",
                                          "albedo", "subdivisions", NULL};
    static const char *const k_box[] = {"name", "type", "center", "size", "albedo", NULL};
    if ((rc = lr_json_check_keys(c->j, obj, where, type == 0 ? k_plane : k_box, c->e)))
        return rc;
    memset(r, 0, sizeof *r);
    r->type = (enum lr_receiver_type)type;
    if ((rc = get_name(c, obj, where, "receiver", i, r->name)) ||
        (rc = get_vec(c, obj, where, "center", true, &r->center)) ||
        (rc = get_rgb(c, obj, where, "albedo", true, r->albedo)))
        return rc;
    char f[256];
    lr_jnode sz = lr_json_get(c->j, obj, "size");
    if (sz == LR_JNONE)
        return lr_json_fail(c->j, obj, cat(f, sizeof f, where, "size"), c->e, LR_EPARSE,
                            "missing (required)");
    if ((rc = lr_json_numbers(c->j, sz, cat(f, sizeof f, where, "size"), r->size,
                              type == 0 ? 2 : 3, c->e)))
        return rc;
    if (type == 0 && ((rc = get_vec(c, obj, where, "normal", true, &r->normal)) ||
                      (rc = get_vec(c, obj, where, "u_dir", false, &r->u_dir)) ||
                      (rc = get_int(c, obj, where, "subdivisions", &r->subdivisions))))
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
    static const char *const types[] = {"candle", "shade", "sphere", "box", "file", NULL};
    int type = 0, rc;
    if (lr_json_type(c->j, obj) != LR_JSON_OBJECT)
        return lr_json_fail(c->j, obj, where, c->e, LR_EPARSE, "expected an object, got %s",
                            lr_json_type_name(lr_json_type(c->j, obj)));
    if ((rc = type_of(c, obj, where, types, NULL, &type)))
        return rc;
    static const char *const keys[5][10] = {
        {"type", "radius", "height", "pool_depth", "pool_radius", "segments", "pool_rings",
         "side_rings", NULL},
        {"type", "radius_bottom", "radius_top", "height", "thickness", "rims", "segments",
         "rings", NULL},
        {"type", "radius", "subdivisions", NULL},
        {"type", "size", NULL},
        {"type", "path", "scale", NULL}};
    if ((rc = lr_json_check_keys(c->j, obj, where, keys[type], c->e)))
        return rc;
    memset(m, 0, sizeof *m);
    m->kind = (enum lr_mesh_kind)type;
    m->file_scale = 1.0;
    switch (m->kind) {
    case LR_MESH_CANDLE: {
        lr_candle_desc *d = &m->candle;
        if ((rc = get_num(c, obj, where, "radius", &d->radius)) ||
            (rc = get_num(c, obj, where, "height", &d->height)) ||
            (rc = get_num(c, obj, where, "pool_radius", &d->pool_radius)) ||
            (rc = get_int(c, obj, where, "segments", &d->segments)) ||
            (rc = get_int(c, obj, where, "pool_rings", &d->pool_rings)) ||
            (rc = get_int(c, obj, where, "side_rings", &d->side_rings)))
            return rc;
        lr_jnode pd = lr_json_get(c->j, obj, "pool_depth");
        if (pd != LR_JNONE) {
            if ((rc = get_num(c, obj, where, "pool_depth", &d->pool_depth)))
                return rc;
            d->flat_top = d->pool_depth == 0.0; /* written 0: a new, flat-topped candle */
        }
        break;
    }
    case LR_MESH_SHADE: {
        lr_shade_desc *d = &m->shade;
        bool rims = true;
        if ((rc = get_num(c, obj, where, "radius_bottom", &d->radius_bottom)) ||
            (rc = get_num(c, obj, where, "radius_top", &d->radius_top)) ||
            (rc = get_num(c, obj, where, "height", &d->height)) ||
            (rc = get_bool(c, obj, where, "rims", &rims)) ||
            (rc = get_int(c, obj, where, "segments", &d->segments)) ||
            (rc = get_int(c, obj, where, "rings", &d->rings)))
            return rc;
        d->no_rims = !rims;
        if (lr_json_get(c->j, obj, "thickness") != LR_JNONE) {
            if ((rc = get_num(c, obj, where, "thickness", &d->thickness)))
                return rc;
            d->single_surface = d->thickness == 0.0; /* written 0: a zero-thickness shade */
        }
        break;
    }
    case LR_MESH_SPHERE:
        if ((rc = get_num(c, obj, where, "radius", &m->sphere.radius)) ||
            (rc = get_int(c, obj, where, "subdivisions", &m->sphere.subdivisions)))
            return rc;
        break;
    case LR_MESH_BOX:
        if ((rc = get_vec(c, obj, where, "size", false, &m->box.size)))
            return rc;
        break;
    case LR_MESH_FILE: {
        char f[256];
        if ((rc = lr_json_get_string(c->j, obj, "path", true, m->path, sizeof m->path, c->e)))
            return lr_json_get(c->j, obj, "path") == LR_JNONE
                       ? lr_json_fail(c->j, obj, cat(f, sizeof f, where, "path"), c->e, rc,
                                      "missing (required)")
                       : rc;
        if ((rc = get_num(c, obj, where, "scale", &m->file_scale)))
            return rc;
        break;
    }
    }
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
    x->translate = lr_v3(0, 0, 0);
    x->rotate_deg = lr_v3(0, 0, 0);
    x->scale = lr_v3(1, 1, 1);
    if (n == LR_JNONE)
        return LR_OK;
    char where[96];
    cat(where, sizeof where, owhere, "transform");
    static const char *const keys[] = {"translate", "rotate_deg", "scale", NULL};
    int rc;
    if ((rc = lr_json_check_keys(c->j, n, where, keys, c->e)) ||
        (rc = get_vec(c, n, where, "translate", false, &x->translate)) ||
        (rc = get_vec(c, n, where, "rotate_deg", false, &x->rotate_deg)) ||
        (rc = get_scale3(c, n, where, "scale", &x->scale)))
        return rc;
    const char *field = NULL;
    lr_err inner = {0};
    if ((rc = lr_scene_check_transform(x, &field, &inner))) {
        /* field is "transform.X": locate from the object holding "transform". */
        char f[256];
        return lr_json_fail(c->j, locate(c->j, n, field + strlen("transform.")),
                            cat(f, sizeof f, owhere, field), c->e, rc, "%s", inner.msg);
    }
    return LR_OK;
}

/* "thickness_mm": the wall the multipole models (render/optics/optics.h); required with
 * "model": "multipole", optional (kept for a later model change) otherwise. */
static int get_thickness(ctx *c, lr_jnode obj, const char *where, lr_scene_object *o)
{
    char f[96];
    lr_jnode t = lr_json_get(c->j, obj, "thickness_mm");
    o->thickness_mm = 0.0;
    if (t == LR_JNONE)
        return o->sss_model == LR_SSS_MULTIPOLE
                   ? lr_json_fail(c->j, obj, cat(f, sizeof f, where, "thickness_mm"), c->e,
                                  LR_EPARSE, "missing (required with model multipole)")
                   : LR_OK;
    int rc = get_num(c, obj, where, "thickness_mm", &o->thickness_mm);
    lr_err inner = {0};
    if (!rc && (rc = lr_multipole_thickness_validate(o->thickness_mm, &inner)))
        return lr_json_fail(c->j, t, cat(f, sizeof f, where, "thickness_mm"), c->e, rc, "%s",
                            inner.msg);
    return rc;
}

static int parse_object(ctx *c, lr_jnode obj, int i, obj_rec *o)
{
    char where[64];
    snprintf(where, sizeof where, "objects[%d]", i);
    if (lr_json_type(c->j, obj) != LR_JSON_OBJECT)
        return lr_json_fail(c->j, obj, where, c->e, LR_EPARSE, "expected an object");
    static const char *const keys[] = {"name", "material", "mesh", "transform", "model",
                                       "normalize", "thickness_mm", NULL};
    int rc;
    bool normalize = true; /* PIPELINE.md "Energy": S_d energy-normalised unless false */
    if ((rc = lr_json_check_keys(c->j, obj, where, keys, c->e)) ||
        (rc = get_name(c, obj, where, "object", i, o->pub.name)))
        return rc;
    lr_jnode nz = lr_json_get(c->j, obj, "normalize");
    char nf[96];
    if (nz != LR_JNONE &&
        (rc = lr_json_bool(c->j, nz, cat(nf, sizeof nf, where, "normalize"), &normalize, c->e)))
        return rc;
    o->pub.sd_raw = !normalize;
    char f[256];
    o->pub.sss_model = LR_SSS_DIRECTIONAL_DIPOLE;
    lr_jnode model = lr_json_get(c->j, obj, "model");
    if (model != LR_JNONE) {
        char name[32];
        if ((rc = lr_json_string(c->j, model, cat(f, sizeof f, where, "model"), name,
                                 sizeof name, c->e)))
            return rc;
        if (!lr_sss_model_parse(name, &o->pub.sss_model))
            return lr_json_fail(c->j, model, f, c->e, LR_EINVAL,
                                "'%s': expected directional_dipole, standard_dipole or multipole",
                                name);
    }
    if ((rc = get_thickness(c, obj, where, &o->pub)))
        return rc;
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
    lr_err inner = {0};
    if ((rc = lr_coeffs_derive(&o->pub.material.medium, &o->pub.coeffs, &inner)))
        return lr_json_fail(c->j, mat, cat(f, sizeof f, where, "material"), c->e, rc, "%s",
                            inner.msg);
    o->pub.kind = o->mesh.kind;
    if ((rc = lr_scene_build_object(c->s, where, &o->mesh, &o->xf, &o->world, &o->bvh,
                                    o->pub.model, &inner))) {
        /* A file that cannot be read or is broken: point at the path in the scene. */
        lr_jnode at = o->mesh.kind == LR_MESH_FILE ? lr_json_get(c->j, mesh, "path") : mesh;
        return lr_json_fail(c->j, at, cat(f, sizeof f, where,
                                          o->mesh.kind == LR_MESH_FILE ? "mesh.path" : "mesh"),
                            c->e, rc, "%s", inner.msg);
    }
    lr_scene_object_attach(&o->pub, o->world, o->bvh);
    return LR_OK;
}

/* ---- settings -------------------------------------------------------------------------------- */

static int parse_render(ctx *c, lr_jnode n, lr_render_settings *r)
{
    lr_scene_render_defaults(r);
    if (n == LR_JNONE)
        return LR_OK;
    static const char *const keys[] = {"K", "N", "N_vpl", "map_size", "gbuffer_size",
                                       "vpl_map_size", "frames", "exposure", NULL};
    const char *where = "render";
    int rc;
    lr_render_settings w = {0};
    if ((rc = lr_json_check_keys(c->j, n, where, keys, c->e)) ||
        (rc = get_int(c, n, where, "K", &w.K)) || (rc = get_int(c, n, where, "N", &w.N)) ||
        (rc = get_int(c, n, where, "N_vpl", &w.N_vpl)) ||
        (rc = get_int(c, n, where, "map_size", &w.map_size)) ||
        (rc = get_int(c, n, where, "gbuffer_size", &w.gbuffer_size)) ||
        (rc = get_int(c, n, where, "vpl_map_size", &w.vpl_map_size)) ||
        (rc = get_int(c, n, where, "frames", &w.frames)) ||
        (rc = get_num(c, n, where, "exposure", &w.exposure)))
        return rc;
    /* Zero or absent: the default. */
    if (w.K) r->K = w.K;
    if (w.N) r->N = w.N;
    if (w.N_vpl) r->N_vpl = w.N_vpl;
    if (w.map_size) r->map_size = w.map_size;
    if (w.gbuffer_size) r->gbuffer_size = w.gbuffer_size;
    if (w.vpl_map_size) r->vpl_map_size = w.vpl_map_size;
    if (w.frames) r->frames = w.frames;
    if (w.exposure != 0.0) r->exposure = w.exposure;
    const char *field = NULL;
    lr_err inner = {0};
    if ((rc = lr_scene_check_render(r, &field, &inner)))
        return fail_check(c, n, where, field, rc, &inner);
    return LR_OK;
}

static int parse_quality(ctx *c, lr_jnode n, lr_quality *q)
{
    memset(q, 0, sizeof *q);
    if (n == LR_JNONE)
        return LR_OK;
    static const char *const keys[] = {"max_error", "frame_ms", NULL};
    int rc;
    if ((rc = lr_json_check_keys(c->j, n, "quality", keys, c->e)) ||
        (rc = get_num(c, n, "quality", "max_error", &q->max_error)) ||
        (rc = get_num(c, n, "quality", "frame_ms", &q->frame_ms)))
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
    if ((rc = parse_render(c, lr_json_get(j, root, "render"), &s->render)) ||
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
    /* A light inside solid material: every ray from it meets the surface from behind, which
     * the surface-incidence BSSRDF (PIPELINE.md) counts as no light, so that object stays dark
     * for this light. Say so rather than render 0 silently (issue 3). */
    for (int i = 0; i < nl; i++) {
        int k = -1;
        if (lr_scene_light_enclosure(s, i, &k) == LR_ENCLOSURE_SOLID && k >= 0)
            lr_warn(&s->warn,
                    "%s:%d: lights[%d] '%s' is inside the material of objects[%d] '%s': the "
                    "model has no term for a source embedded in the medium, so that object "
                    "gets no light from it (put the light in a cavity: a hollow object)",
                    s->path, lr_json_line(j, lr_json_at(j, lights, i)), i, s->light[i].name, k,
                    s->obj[k].pub.name);
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
