/* Scene parameters by name: lr_scene_set (validated, all or nothing, dirty flags) and
 * lr_scene_get, sharing one map from names to fields. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/json.h"
#include "render/scene/scene_internal.h"

/* One get or set of one field. */
typedef struct op {
    bool get;
    const char *key;   /* the whole key, for messages */
    const char *value; /* set: the text */
    char *buf;         /* get: output */
    size_t cap;
    lr_err *e;
} op;

static int fail(op *o, int code, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static int fail(op *o, int code, const char *fmt, ...)
{
    char msg[LR_ERR_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return lr_err_set(o->e, code, "%s: %s", o->key, msg);
}

static int out(op *o, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int out(op *o, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(o->buf, o->cap, fmt, ap);
    va_end(ap);
    if (n < 0 || (size_t)n >= o->cap)
        return fail(o, LR_EINVAL, "value does not fit the %zu-byte buffer", o->cap);
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

/* Parses a list value "x,y,z" or "[x,y,z]" as a JSON array (strict numbers: no hex, nan, inf
 * or leading '+'). */
static lr_json *value_json(op *o)
{
    char text[512];
    const char *v = o->value;
    while (*v == ' ')
        v++;
    int n = v[0] != '[' ? snprintf(text, sizeof text, "[%s]", v)
                        : snprintf(text, sizeof text, "%s", v);
    if (n < 0 || (size_t)n >= sizeof text)
        return NULL;
    lr_json *j = NULL;
    if (lr_json_parse(text, (size_t)n, o->key, &j, NULL) != LR_OK)
        return NULL;
    return j;
}

/* The value as one JSON number, read as the only element of an array (the same path as
 * value_json, so "1,2" is two numbers and refused here). */
static bool value_number(op *o, double *v)
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

static int num_field(op *o, double *p)
{
    if (o->get) {
        char b[40];
        fmt_num(b, sizeof b, *p);
        return out(o, "%s", b);
    }
    double v;
    if (!value_number(o, &v))
        return fail(o, LR_EPARSE, "expected a number, got '%s'", o->value);
    *p = v;
    return LR_OK;
}

static int int_field(op *o, int *p)
{
    if (o->get)
        return out(o, "%d", *p);
    double v;
    int rc = num_field(o, &v);
    if (rc)
        return rc;
    if (v != floor(v) || fabs(v) > 1e9)
        return fail(o, LR_EPARSE, "expected an integer, got '%s'", o->value);
    *p = (int)v;
    return LR_OK;
}

static int vec_field(op *o, lr_vec3 *p)
{
    if (o->get) {
        char x[40], y[40], z[40];
        fmt_num(x, sizeof x, p->x);
        fmt_num(y, sizeof y, p->y);
        fmt_num(z, sizeof z, p->z);
        return out(o, "%s,%s,%s", x, y, z);
    }
    lr_json *j = value_json(o);
    double v[3];
    int rc = j ? lr_json_numbers(j, lr_json_root(j), o->key, v, 3, NULL) : LR_EPARSE;
    lr_json_destroy(j);
    if (rc)
        return fail(o, LR_EPARSE, "expected x,y,z (three numbers), got '%s'", o->value);
    *p = lr_v3(v[0], v[1], v[2]);
    return LR_OK;
}

static int rgb_field(op *o, double p[3])
{
    lr_vec3 v = lr_v3(p[0], p[1], p[2]);
    int rc = vec_field(o, &v);
    if (!rc && !o->get) {
        p[0] = v.x;
        p[1] = v.y;
        p[2] = v.z;
    }
    return rc;
}

/* A number (the same on all three axes or bands) or x,y,z. */
static int scale_field(op *o, double p[3])
{
    if (o->get) {
        if (p[0] == p[1] && p[1] == p[2]) {
            double v = p[0];
            return num_field(o, &v);
        }
        return rgb_field(o, p);
    }
    double scalar_v;
    if (value_number(o, &scalar_v)) {
        double v;
        int rc = num_field(o, &v);
        if (!rc)
            p[0] = p[1] = p[2] = v;
        return rc;
    }
    double v[3] = {p[0], p[1], p[2]};
    int rc = rgb_field(o, v);
    if (rc)
        return fail(o, LR_EPARSE, "expected a number or x,y,z, got '%s'", o->value);
    memcpy(p, v, sizeof v);
    return LR_OK;
}

static int bool_field(op *o, bool *p)
{
    if (o->get)
        return out(o, "%s", *p ? "true" : "false");
    if (strcmp(o->value, "true") == 0)
        *p = true;
    else if (strcmp(o->value, "false") == 0)
        *p = false;
    else
        return fail(o, LR_EPARSE, "expected true or false, got '%s'", o->value);
    return LR_OK;
}

static int name_field(op *o, char *p, size_t cap)
{
    if (o->get)
        return out(o, "%s", p);
    if (!lr_material_name_ok(o->value) || strlen(o->value) >= cap)
        return fail(o, LR_EINVAL, "'%s' is not a name (letters, digits, '_', '-', '.')",
                    o->value);
    snprintf(p, cap, "%s", o->value);
    return LR_OK;
}

static int unknown(op *o, const char *what, const char *field, const char *known)
{
    return fail(o, LR_EINVAL, "%s has no parameter '%s' (known: %s)", what, field, known);
}

/* Reports a record check's failure under the key; names the field it is about when that is
 * another one (inner_deg after a change of outer_deg). */
static int check_failed(op *o, const char *field, const char *bad, int rc, const lr_err *inner)
{
    if (bad && strcmp(bad, field) != 0)
        return lr_err_set(o->e, rc, "%s: then %s %s", o->key, bad, inner->msg);
    return lr_err_set(o->e, rc, "%s: %s", o->key, inner->msg);
}

/* ---- lights ---------------------------------------------------------------------------------- */

static int light_field(op *o, lr_light *l, const char *f, unsigned *d)
{
    static const char *const type_name[] = {"point", "spot", "directional"};
    bool dir = l->type == LR_LIGHT_DIRECTIONAL, spot = l->type == LR_LIGHT_SPOT;
    if (strcmp(f, "intensity") == 0 || strcmp(f, "radiance") == 0) {
        if (dir != (strcmp(f, "radiance") == 0))
            return fail(o, LR_EINVAL, "a %s light's strength is its '%s'", type_name[l->type],
                        dir ? "radiance" : "intensity");
        *d = LR_DIRTY_INTENSITY;
        return num_field(o, &l->intensity);
    }
    if (strcmp(f, "color") == 0) {
        *d = LR_DIRTY_INTENSITY; /* per band, still linear */
        return rgb_field(o, l->color);
    }
    if (strcmp(f, "position") == 0 && !dir) {
        *d = LR_DIRTY_LIGHT_GEOMETRY;
        return vec_field(o, &l->position);
    }
    if (strcmp(f, "direction") == 0 && l->type != LR_LIGHT_POINT) {
        *d = LR_DIRTY_LIGHT_GEOMETRY;
        return vec_field(o, &l->direction);
    }
    if (spot && strcmp(f, "inner_deg") == 0) {
        *d = LR_DIRTY_LIGHT_GEOMETRY;
        return num_field(o, &l->inner_deg);
    }
    if (spot && strcmp(f, "outer_deg") == 0) {
        *d = LR_DIRTY_LIGHT_GEOMETRY;
        return num_field(o, &l->outer_deg);
    }
    if (!dir && strncmp(f, "flicker.", 8) == 0) {
        const char *g = f + 8;
        /* Flicker is applied by the renderer at composition on its clock (render/renderer.h
         * lr_renderer_set_time), the sway included: the transport stays at the light's mean
         * position (jitter << 1/sigma_tr), so every flicker field is composition-only. */
        if (strcmp(g, "amplitude") == 0) {
            *d = LR_DIRTY_INTENSITY;
            return num_field(o, &l->flicker.amplitude);
        }
        if (strcmp(g, "frequency_hz") == 0) {
            *d = LR_DIRTY_INTENSITY;
            return num_field(o, &l->flicker.frequency_hz);
        }
        if (strcmp(g, "jitter_mm") == 0) {
            *d = LR_DIRTY_INTENSITY;
            return num_field(o, &l->flicker.jitter_mm);
        }
        if (strcmp(g, "seed") == 0) {
            *d = LR_DIRTY_INTENSITY;
            int seed = (int)l->flicker.seed;
            int rc = int_field(o, &seed);
            if (!rc && seed < 0)
                return fail(o, LR_EINVAL, "must be >= 0, got %d", seed);
            l->flicker.seed = (unsigned)seed;
            return rc;
        }
    }
    return unknown(o, dir ? "a directional light" : spot ? "a spot light" : "a point light", f,
                   dir ? "radiance, color, direction"
                   : spot ? "intensity, color, position, direction, inner_deg, outer_deg, "
                            "flicker.{amplitude, frequency_hz, jitter_mm, seed}"
                          : "intensity, color, position, flicker.{amplitude, frequency_hz, "
                            "jitter_mm, seed}");
}

/* ---- camera, settings ----------------------------------------------------------------------- */

static int camera_field(op *o, lr_camera *c, const char *f, unsigned *d)
{
    *d = LR_DIRTY_CAMERA;
    if (strcmp(f, "position") == 0)
        return vec_field(o, &c->position);
    if (strcmp(f, "target") == 0)
        return vec_field(o, &c->target);
    if (strcmp(f, "up") == 0)
        return vec_field(o, &c->up);
    if (strcmp(f, "fov_deg") == 0)
        return num_field(o, &c->fov_deg);
    if (strcmp(f, "height_mm") == 0)
        return num_field(o, &c->height_mm);
    if (strcmp(f, "near") == 0)
        return num_field(o, &c->near_mm);
    if (strcmp(f, "far") == 0)
        return num_field(o, &c->far_mm);
    if (strcmp(f, "type") == 0) {
        if (o->get)
            return out(o, "%s", c->orthographic ? "orthographic" : "perspective");
        if (strcmp(o->value, "perspective") && strcmp(o->value, "orthographic"))
            return fail(o, LR_EINVAL, "expected perspective or orthographic, got '%s'",
                        o->value);
        c->orthographic = strcmp(o->value, "orthographic") == 0;
        return LR_OK;
    }
    return unknown(o, "camera", f, "type, position, target, up, fov_deg, height_mm, near, far");
}

static int render_field(op *o, lr_render_settings *r, const char *f, unsigned *d)
{
    static const struct { const char *name; size_t off; } ints[] = {
        {"K", offsetof(lr_render_settings, K)},
        {"N", offsetof(lr_render_settings, N)},
        {"N_vpl", offsetof(lr_render_settings, N_vpl)},
        {"map_size", offsetof(lr_render_settings, map_size)},
        {"gbuffer_size", offsetof(lr_render_settings, gbuffer_size)},
        {"vpl_map_size", offsetof(lr_render_settings, vpl_map_size)},
        {"frames", offsetof(lr_render_settings, frames)}};
    for (size_t i = 0; i < sizeof ints / sizeof ints[0]; i++)
        if (strcmp(f, ints[i].name) == 0) {
            *d = LR_DIRTY_SETTINGS;
            int *p = (int *)((char *)r + ints[i].off);
            int rc = int_field(o, p);
            if (!rc && !o->get && *p == 0) { /* 0 means the default, as in the file */
                lr_render_settings def;
                lr_scene_render_defaults(&def);
                *p = *(int *)((char *)&def + ints[i].off);
            }
            return rc;
        }
    if (strcmp(f, "exposure") == 0) {
        *d = LR_DIRTY_DISPLAY;
        int rc = num_field(o, &r->exposure);
        if (!rc && !o->get && r->exposure == 0.0)
            r->exposure = 1.0;
        return rc;
    }
    return unknown(o, "render", f,
                   "K, N, N_vpl, map_size, gbuffer_size, vpl_map_size, frames, exposure");
}

static int quality_field(op *o, lr_quality *q, const char *f, unsigned *d)
{
    *d = LR_DIRTY_SETTINGS;
    if (strcmp(f, "max_error") == 0)
        return num_field(o, &q->max_error);
    if (strcmp(f, "frame_ms") == 0)
        return num_field(o, &q->frame_ms);
    return unknown(o, "quality", f, "max_error, frame_ms");
}

static int receiver_field(op *o, lr_receiver *r, const char *f, unsigned *d)
{
    bool plane = r->type == LR_RECEIVER_PLANE;
    *d = LR_DIRTY_RECEIVERS;
    if (strcmp(f, "albedo") == 0)
        return rgb_field(o, r->albedo);
    if (strcmp(f, "center") == 0)
        return vec_field(o, &r->center);
    if (plane && strcmp(f, "normal") == 0)
        return vec_field(o, &r->normal);
    if (plane && strcmp(f, "u_dir") == 0)
        return vec_field(o, &r->u_dir);
    if (plane && strcmp(f, "subdivisions") == 0)
        return int_field(o, &r->subdivisions);
    if (strcmp(f, "size") == 0) {
        if (!plane)
            return rgb_field(o, r->size);
        /* A plane's size is "w,h". */
        if (o->get) {
            char w[40], h[40];
            fmt_num(w, sizeof w, r->size[0]);
            fmt_num(h, sizeof h, r->size[1]);
            return out(o, "%s,%s", w, h);
        }
        lr_json *j = value_json(o);
        int rc = j ? lr_json_numbers(j, lr_json_root(j), o->key, r->size, 2, NULL) : LR_EPARSE;
        lr_json_destroy(j);
        return rc ? fail(o, LR_EPARSE, "expected w,h (two numbers), got '%s'", o->value) : LR_OK;
    }
    return unknown(o, plane ? "a plane receiver" : "a box receiver", f,
                   plane ? "albedo, center, normal, u_dir, size, subdivisions"
                         : "albedo, center, size");
}

/* ---- objects ---------------------------------------------------------------------------------- */

/* Turns "material": "NAME" into {"base": "NAME"} so that one field can change. */
static void inline_preset(mat_spec *m)
{
    if (!m->is_preset)
        return;
    char preset[LR_MATERIAL_NAME_MAX];
    snprintf(preset, sizeof preset, "%s", m->preset);
    memset(m, 0, sizeof *m);
    snprintf(m->name, sizeof m->name, "%s", preset);
    snprintf(m->source, sizeof m->source, "preset '%s', changed at run time", preset);
    m->has_base = true;
    snprintf(m->base, sizeof m->base, "%s", preset);
}

static int material_field(op *o, mat_spec *m, const char *f)
{
    if (f[0] == '\0') { /* the preset itself */
        if (o->get)
            return out(o, "%s", m->is_preset ? m->preset : m->has_base ? m->base : m->name);
        char name[LR_MATERIAL_NAME_MAX];
        int rc = name_field(o, name, sizeof name);
        if (rc)
            return rc;
        memset(m, 0, sizeof *m);
        m->is_preset = true;
        snprintf(m->preset, sizeof m->preset, "%s", name);
        return LR_OK;
    }
    if (o->get && m->is_preset) {
        /* Of a bare preset: its base is itself and its scale 1; coefficients come from the
         * resolved material (handled by the caller). */
        if (strcmp(f, "scale") == 0)
            return out(o, "1");
        if (strcmp(f, "base") == 0)
            return out(o, "%s", m->preset);
    }
    if (!o->get)
        inline_preset(m);
    if (strcmp(f, "scale") == 0) {
        if (!m->has_base)
            return fail(o, LR_EINVAL, "the material has no 'base' to scale (scale multiplies "
                        "a preset's coefficients)");
        if (o->get && !m->has_scale)
            return out(o, "1");
        if (!o->get && !m->has_scale)
            m->scale[0] = m->scale[1] = m->scale[2] = 1.0;
        m->has_scale = true;
        int rc = scale_field(o, m->scale);
        if (!rc && !o->get)
            for (int b = 0; b < 3; b++)
                if (!(m->scale[b] > 0.0))
                    return fail(o, LR_EINVAL, "must be > 0, got %g", m->scale[b]);
        return rc;
    }
    if (strcmp(f, "base") == 0) {
        if (o->get && !m->has_base)
            return out(o, "%s", "");
        m->has_base = true;
        return name_field(o, m->base, sizeof m->base);
    }
    if (strcmp(f, "sigma_a") == 0 || strcmp(f, "sigma_s_prime") == 0) {
        bool a = f[6] == 'a';
        if (!o->get)
            *(a ? &m->has_sigma_a : &m->has_sigma_s_prime) = true;
        int rc = rgb_field(o, a ? m->sigma_a : m->sigma_s_prime);
        if (!rc && !o->get)
            for (int b = 0; b < 3; b++)
                if (!((a ? m->sigma_a : m->sigma_s_prime)[b] >= 0.0))
                    return fail(o, LR_EINVAL, "must be >= 0 (mm^-1), got %g",
                                (a ? m->sigma_a : m->sigma_s_prime)[b]);
        return rc;
    }
    if (strcmp(f, "eta") == 0) {
        if (!o->get)
            m->has_eta = true;
        return num_field(o, &m->eta);
    }
    if (strcmp(f, "g") == 0) {
        if (!o->get)
            m->has_g = true;
        return num_field(o, &m->g);
    }
    return unknown(o, "a material", f, "(the preset itself), scale, base, sigma_a, "
                   "sigma_s_prime, eta, g");
}

/* "pool_depth" and "thickness": 0 is a shape (flat top, single surface), not "the default". */
static int zero_flag_field(op *o, double *v, bool *flag, double resolved)
{
    if (o->get) {
        double shown = *flag ? 0.0 : resolved;
        return num_field(o, &shown);
    }
    double x;
    int rc = num_field(o, &x);
    if (rc)
        return rc;
    *flag = x == 0.0;
    *v = x;
    return LR_OK;
}

static int mesh_field(op *o, mesh_spec *m, const char *f)
{
    static const char *const kind_name[] = {"candle", "shade", "sphere", "box", "file"};
    if (strcmp(f, "type") == 0) {
        if (o->get)
            return out(o, "%s", kind_name[m->kind]);
        return fail(o, LR_EINVAL, "the mesh type cannot change at run time (edit the scene "
                    "file)");
    }
    /* get shows resolved values: defaults filled in. */
    const char *bad;
    lr_err ignore = {0};
    switch (m->kind) {
    case LR_MESH_CANDLE: {
        lr_candle_desc r = {0}, *d = o->get ? &r : &m->candle;
        if (o->get)
            lr_candle_check(&m->candle, &r, &bad, &ignore);
        if (strcmp(f, "radius") == 0) return num_field(o, &d->radius);
        if (strcmp(f, "height") == 0) return num_field(o, &d->height);
        if (strcmp(f, "pool_depth") == 0)
            return zero_flag_field(o, &m->candle.pool_depth, &m->candle.flat_top, r.pool_depth);
        if (strcmp(f, "pool_radius") == 0) return num_field(o, &d->pool_radius);
        if (strcmp(f, "segments") == 0) return int_field(o, &d->segments);
        if (strcmp(f, "pool_rings") == 0) return int_field(o, &d->pool_rings);
        if (strcmp(f, "side_rings") == 0) return int_field(o, &d->side_rings);
        return unknown(o, "a candle mesh", f, "radius, height, pool_depth, pool_radius, "
                       "segments, pool_rings, side_rings");
    }
    case LR_MESH_SHADE: {
        lr_shade_desc r = {0}, *d = o->get ? &r : &m->shade;
        if (o->get)
            lr_shade_check(&m->shade, &r, &bad, &ignore);
        if (strcmp(f, "radius_bottom") == 0) return num_field(o, &d->radius_bottom);
        if (strcmp(f, "radius_top") == 0) return num_field(o, &d->radius_top);
        if (strcmp(f, "height") == 0) return num_field(o, &d->height);
        if (strcmp(f, "thickness") == 0)
            return zero_flag_field(o, &m->shade.thickness, &m->shade.single_surface,
                                   r.thickness);
        if (strcmp(f, "rims") == 0) {
            bool rims = !m->shade.no_rims;
            int rc = bool_field(o, &rims);
            if (!o->get)
                m->shade.no_rims = !rims;
            return rc;
        }
        if (strcmp(f, "segments") == 0) return int_field(o, &d->segments);
        if (strcmp(f, "rings") == 0) return int_field(o, &d->rings);
        return unknown(o, "a shade mesh", f, "radius_bottom, radius_top, height, thickness, "
                       "rims, segments, rings");
    }
    case LR_MESH_SPHERE: {
        lr_sphere_desc r = {0}, *d = o->get ? &r : &m->sphere;
        if (o->get)
            lr_sphere_check(&m->sphere, &r, &bad, &ignore);
        if (strcmp(f, "radius") == 0) return num_field(o, &d->radius);
        if (strcmp(f, "subdivisions") == 0) return int_field(o, &d->subdivisions);
        return unknown(o, "a sphere mesh", f, "radius, subdivisions");
    }
    case LR_MESH_BOX: {
        lr_box_desc r = {0}, *d = o->get ? &r : &m->box;
        if (o->get)
            lr_box_check(&m->box, &r, &bad, &ignore);
        if (strcmp(f, "size") == 0) return vec_field(o, &d->size);
        return unknown(o, "a box mesh", f, "size");
    }
    case LR_MESH_FILE:
        if (strcmp(f, "path") == 0) {
            if (o->get)
                return out(o, "%s", m->path);
            if (!o->value[0] || strlen(o->value) >= sizeof m->path)
                return fail(o, LR_EINVAL, "expected a file path");
            snprintf(m->path, sizeof m->path, "%s", o->value);
            return LR_OK;
        }
        if (strcmp(f, "scale") == 0)
            return num_field(o, &m->file_scale);
        return unknown(o, "a file mesh", f, "path, scale");
    }
    return LR_EINVAL;
}

static int transform_field(op *o, xform_spec *x, const char *f)
{
    if (strcmp(f, "translate") == 0)
        return vec_field(o, &x->translate);
    if (strcmp(f, "rotate_deg") == 0)
        return vec_field(o, &x->rotate_deg);
    if (strcmp(f, "scale") == 0) {
        double s[3] = {x->scale.x, x->scale.y, x->scale.z};
        int rc = scale_field(o, s);
        if (!o->get)
            x->scale = lr_v3(s[0], s[1], s[2]);
        return rc;
    }
    return unknown(o, "a transform", f, "translate, rotate_deg, scale");
}

/* Reformats lr_material_from_json's "NAME:LINE: field 'F': msg" as "F: msg" under the key. */
static int material_failed(op *o, int rc, const lr_err *inner)
{
    const char *p = strstr(inner->msg, "field '");
    const char *q = p ? strstr(p, "': ") : NULL;
    if (p && q) {
        int flen = (int)(q - p - 7);
        if ((size_t)flen == strlen(o->key) && strncmp(p + 7, o->key, (size_t)flen) == 0)
            return lr_err_set(o->e, rc, "%s: %s", o->key, q + 3);
        return lr_err_set(o->e, rc, "%s: %.*s: %s", o->key, flen, p + 7, q + 3);
    }
    return lr_err_set(o->e, rc, "%s: %s", o->key, inner->msg);
}

static int object_set(op *o, lr_scene *s, int i, const char *f, unsigned *d)
{
    obj_rec *rec = &s->obj[i];
    char where[96];
    snprintf(where, sizeof where, "objects[%d]", i);
    int rc;
    lr_err inner = {0};
    if (strcmp(f, "material") == 0 || strncmp(f, "material.", 9) == 0) {
        mat_spec m = rec->mat;
        if ((rc = material_field(o, &m, f[8] ? f + 9 : "")))
            return rc;
        lr_material mat;
        lr_coeffs co;
        char mw[112];
        snprintf(mw, sizeof mw, "%s.material", where);
        if ((rc = lr_scene_resolve_material(&m, mw, &mat, &inner)))
            return material_failed(o, rc, &inner);
        if ((rc = lr_coeffs_derive(&mat.medium, &co, &inner)))
            return lr_err_set(o->e, rc, "%s: %s", o->key, inner.msg);
        rec->mat = m;
        rec->pub.material = mat;
        rec->pub.coeffs = co;
        *d = LR_DIRTY_MATERIAL;
        return LR_OK;
    }
    if (strcmp(f, "normalize") == 0) {
        bool normalize = !rec->pub.sd_raw;
        if ((rc = bool_field(o, &normalize)))
            return rc;
        rec->pub.sd_raw = !normalize;
        *d = LR_DIRTY_MATERIAL; /* the radiosity maps restart */
        return LR_OK;
    }
    if (strcmp(f, "model") == 0) {
        enum lr_sss_model m;
        if (!lr_sss_model_parse(o->value, &m))
            return fail(o, LR_EINVAL,
                        "expected directional_dipole, standard_dipole or multipole, got '%s'",
                        o->value);
        if (m == LR_SSS_MULTIPOLE && !(rec->pub.thickness_mm > 0.0))
            return fail(o, LR_EINVAL, "multipole needs the object's thickness_mm set first");
        rec->pub.sss_model = m;
        *d = LR_DIRTY_MATERIAL; /* another S_d: maps, VPLs, composition */
        return LR_OK;
    }
    if (strcmp(f, "thickness_mm") == 0) {
        double t = rec->pub.thickness_mm;
        if ((rc = num_field(o, &t)))
            return rc;
        if ((rc = lr_multipole_thickness_validate(t, &inner)))
            return lr_err_set(o->e, rc, "%s: %s", o->key, inner.msg);
        rec->pub.thickness_mm = t;
        *d = LR_DIRTY_MATERIAL; /* the multipole's S_d: maps, VPLs, composition */
        return LR_OK;
    }
    mesh_spec ms = rec->mesh;
    xform_spec xf = rec->xf;
    const char *bad = NULL;
    if (strncmp(f, "mesh.", 5) == 0) {
        if ((rc = mesh_field(o, &ms, f + 5)))
            return rc;
        if ((rc = lr_scene_check_mesh(&ms, &bad, &inner)))
            return check_failed(o, f + 5, bad, rc, &inner);
    } else if (strncmp(f, "transform.", 10) == 0) {
        if ((rc = transform_field(o, &xf, f + 10)))
            return rc;
        if ((rc = lr_scene_check_transform(&xf, &bad, &inner)))
            return check_failed(o, f, bad, rc, &inner);
    } else {
        return unknown(o, "an object", f,
                       "material, material.*, mesh.*, transform.*, model, normalize, "
                       "thickness_mm");
    }
    lr_mesh *world;
    lr_bvh *bvh;
    double model[16];
    if ((rc = lr_scene_build_object(s, where, &ms, &xf, &world, &bvh, model, &inner)))
        return lr_err_set(o->e, rc, "%s: %s", o->key, inner.msg);
    lr_bvh_destroy(rec->bvh);
    lr_mesh_destroy(rec->world);
    rec->world = world;
    rec->bvh = bvh;
    rec->mesh = ms;
    rec->xf = xf;
    memcpy(rec->pub.model, model, sizeof model);
    lr_scene_object_attach(&rec->pub, world, bvh);
    *d = LR_DIRTY_GEOMETRY;
    return LR_OK;
}

static int object_get(op *o, const lr_scene *s, int i, const char *f)
{
    obj_rec rec = s->obj[i]; /* a copy: the field map writes nothing back in get mode */
    const lr_medium *med = &rec.pub.material.medium;
    if (strcmp(f, "material") == 0 || strncmp(f, "material.", 9) == 0) {
        const char *g = f[8] ? f + 9 : "";
        /* Coefficients: the effective ones, whatever the spec says. */
        if (strcmp(g, "sigma_a") == 0)
            return rgb_field(o, (double *)med->sigma_a);
        if (strcmp(g, "sigma_s_prime") == 0)
            return rgb_field(o, (double *)med->sigma_s_prime);
        if (strcmp(g, "eta") == 0)
            return num_field(o, (double *)&med->eta);
        if (strcmp(g, "g") == 0)
            return num_field(o, (double *)&med->g);
        return material_field(o, &rec.mat, g);
    }
    if (strncmp(f, "mesh.", 5) == 0)
        return mesh_field(o, &rec.mesh, f + 5);
    if (strncmp(f, "transform.", 10) == 0)
        return transform_field(o, &rec.xf, f + 10);
    if (strcmp(f, "model") == 0)
        return out(o, "%s", lr_sss_model_name(rec.pub.sss_model));
    if (strcmp(f, "thickness_mm") == 0)
        return num_field(o, &rec.pub.thickness_mm);
    if (strcmp(f, "normalize") == 0) {
        bool normalize = !rec.pub.sd_raw;
        return bool_field(o, &normalize);
    }
    return unknown(o, "an object", f,
                   "material, material.*, mesh.*, transform.*, model, normalize, "
                   "thickness_mm");
}

/* ---- keys ------------------------------------------------------------------------------------- */

typedef struct keyref {
    enum { K_OBJECT, K_LIGHT, K_RECEIVER, K_CAMERA, K_RENDER, K_QUALITY } section;
    int index;
    const char *field;
} keyref;

/* "lights[1].x", "lights[flame].x", "light.x" (= lights[0]), "object.x" (= objects[0]),
 * "camera.x", "render.x", "quality.x". */
static int parse_key(const lr_scene *s, op *o, keyref *k)
{
    const char *key = o->key;
    static const struct { const char *name; int section; bool list; } S[] = {
        {"objects", K_OBJECT, true},     {"object", K_OBJECT, false},
        {"lights", K_LIGHT, true},       {"light", K_LIGHT, false},
        {"receivers", K_RECEIVER, true}, {"camera", K_CAMERA, false},
        {"render", K_RENDER, false},     {"quality", K_QUALITY, false}};
    for (size_t i = 0; i < sizeof S / sizeof S[0]; i++) {
        size_t n = strlen(S[i].name);
        if (strncmp(key, S[i].name, n) != 0 || (key[n] != '.' && key[n] != '['))
            continue;
        k->section = S[i].section;
        k->index = 0;
        const char *p = key + n;
        if (*p == '[') {
            if (!S[i].list)
                return fail(o, LR_EINVAL, "'%s' takes no index", S[i].name);
            const char *close = strchr(p, ']');
            if (!close || close == p + 1 || close[1] != '.')
                return fail(o, LR_EINVAL, "expected %s[INDEX or NAME].PARAMETER", S[i].name);
            char idx[LR_SCENE_NAME_MAX];
            size_t len = (size_t)(close - p - 1);
            if (len >= sizeof idx)
                return fail(o, LR_EINVAL, "index too long");
            memcpy(idx, p + 1, len);
            idx[len] = '\0';
            bool digits = true;
            for (size_t c = 0; c < len; c++)
                digits = digits && idx[c] >= '0' && idx[c] <= '9';
            int count = k->section == K_OBJECT ? s->nobj
                        : k->section == K_LIGHT ? s->nlight
                                                : s->nrecv;
            if (digits) {
                k->index = len > 6 ? count : atoi(idx);
                if (k->index >= count)
                    return fail(o, LR_EINVAL, "index %s out of range (the scene has %d %s)", idx,
                                count, S[i].name);
            } else {
                k->index = k->section == K_OBJECT ? lr_scene_find_object(s, idx)
                           : k->section == K_LIGHT ? lr_scene_find_light(s, idx)
                                                   : lr_scene_find_receiver(s, idx);
                if (k->index < 0)
                    return fail(o, LR_EINVAL, "no %s named '%s'", S[i].name, idx);
            }
            p = close + 1;
        } else if (S[i].list) {
            return fail(o, LR_EINVAL, "expected %s[INDEX or NAME].PARAMETER", S[i].name);
        } else if (k->section == K_LIGHT && s->nlight == 0) {
            return fail(o, LR_EINVAL, "the scene has no light");
        }
        k->field = p + 1;
        if (!k->field[0])
            return fail(o, LR_EINVAL, "no parameter after the '.'");
        return LR_OK;
    }
    return fail(o, LR_EINVAL, "unknown parameter (expected objects[i].*, lights[i].*, "
                "light.*, receivers[i].*, camera.*, render.* or quality.*)");
}

int lr_scene_set(lr_scene *s, const char *key, const char *value, unsigned *dirty, lr_err *e)
{
    op o = {.get = false, .key = key, .value = value ? value : "", .e = e};
    keyref k;
    int rc = parse_key(s, &o, &k);
    if (rc)
        return rc;
    unsigned d = 0;
    const char *bad = NULL;
    lr_err inner = {0};
    switch (k.section) {
    case K_LIGHT: {
        lr_light l = s->light[k.index];
        if ((rc = light_field(&o, &l, k.field, &d)))
            return rc;
        if ((rc = lr_scene_check_light(&l, &bad, &inner)))
            return check_failed(&o, k.field, bad, rc, &inner);
        s->light[k.index] = l;
        break;
    }
    case K_CAMERA: {
        lr_camera c = s->camera;
        if ((rc = camera_field(&o, &c, k.field, &d)))
            return rc;
        if ((rc = lr_scene_check_camera(&c, &bad, &inner)))
            return check_failed(&o, k.field, bad, rc, &inner);
        s->camera = c;
        break;
    }
    case K_RENDER: {
        lr_render_settings r = s->render;
        if ((rc = render_field(&o, &r, k.field, &d)))
            return rc;
        if ((rc = lr_scene_check_render(&r, &bad, &inner)))
            return check_failed(&o, k.field, bad, rc, &inner);
        s->render = r;
        break;
    }
    case K_QUALITY: {
        lr_quality q = s->quality;
        if ((rc = quality_field(&o, &q, k.field, &d)))
            return rc;
        if ((rc = lr_scene_check_quality(&q, &bad, &inner)))
            return check_failed(&o, k.field, bad, rc, &inner);
        s->quality = q;
        break;
    }
    case K_RECEIVER: {
        recv_rec *rr = &s->recv[k.index];
        lr_receiver r = rr->pub;
        if ((rc = receiver_field(&o, &r, k.field, &d)))
            return rc;
        if ((rc = lr_scene_check_receiver(&r, &bad, &inner)))
            return check_failed(&o, k.field, bad, rc, &inner);
        if (strcmp(k.field, "albedo") != 0) {
            lr_mesh *m;
            lr_bvh *b;
            if ((rc = lr_scene_build_receiver(s, &r, &m, &b, &inner)))
                return lr_err_set(e, rc, "%s: %s", key, inner.msg);
            lr_bvh_destroy(rr->bvh);
            lr_mesh_destroy(rr->mesh);
            rr->mesh = m;
            rr->bvh = b;
        }
        r.mesh = rr->mesh;
        r.bvh = rr->bvh;
        rr->pub = r;
        break;
    }
    case K_OBJECT:
        if ((rc = object_set(&o, s, k.index, k.field, &d)))
            return rc;
        break;
    }
    if (dirty)
        *dirty |= d;
    return LR_OK;
}

int lr_scene_get(const lr_scene *s, const char *key, char *buf, size_t cap, lr_err *e)
{
    if (cap)
        buf[0] = '\0';
    op o = {.get = true, .key = key, .buf = buf, .cap = cap, .e = e};
    keyref k;
    int rc = parse_key(s, &o, &k);
    if (rc)
        return rc;
    unsigned d;
    switch (k.section) {
    case K_LIGHT: {
        lr_light l = s->light[k.index];
        return light_field(&o, &l, k.field, &d);
    }
    case K_CAMERA: {
        lr_camera c = s->camera;
        return camera_field(&o, &c, k.field, &d);
    }
    case K_RENDER: {
        lr_render_settings r = s->render;
        return render_field(&o, &r, k.field, &d);
    }
    case K_QUALITY: {
        lr_quality q = s->quality;
        return quality_field(&o, &q, k.field, &d);
    }
    case K_RECEIVER: {
        lr_receiver r = s->recv[k.index].pub;
        return receiver_field(&o, &r, k.field, &d);
    }
    case K_OBJECT:
        return object_get(&o, s, k.index, k.field);
    }
    return LR_EINVAL;
}

int lr_scene_set_assignment(lr_scene *s, const char *assignment, unsigned *dirty, lr_err *e)
{
    const char *eq = strchr(assignment, '=');
    char key[256];
    if (!eq || eq == assignment || (size_t)(eq - assignment) >= sizeof key)
        return lr_err_set(e, LR_EINVAL, "'%s': expected KEY=VALUE", assignment);
    memcpy(key, assignment, (size_t)(eq - assignment));
    key[eq - assignment] = '\0';
    return lr_scene_set(s, key, eq + 1, dirty, e);
}
