/* Scene parameters by name: lr_scene_set (validated, all or nothing, dirty flags) and
 * lr_scene_get. Names, value syntax and dirty bits come from the field tables (fields.h);
 * what is here is finding the record a key names, the material (whose fields are
 * render/material's), and applying a change all or nothing. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/json.h"
#include "render/scene/fields.h"
#include "render/scene/scene_internal.h"

typedef lr_field_op op;

/* Gets or sets the table field `key` of a record (no range check: the caller runs the record
 * check); *dirty gets its lr_dirty bits. */
static int table_field(op *o, const lr_record_desc *d, void *rec, const char *key,
                       unsigned *dirty)
{
    int kind = d->kind_of ? d->kind_of(rec) : 0;
    const lr_field *f = lr_field_find(d, kind, key);
    if (!f || (f->flags & LR_FF_NO_SET) || f->type >= LR_FT_NAME)
        return lr_fields_unknown(o, d, kind, key);
    *dirty = f->dirty;
    return lr_field_apply(o, f, rec);
}

static int name_field(op *o, char *p, size_t cap)
{
    if (o->get)
        return lr_field_out(o, "%s", p);
    if (!lr_material_name_ok(o->value) || strlen(o->value) >= cap)
        return lr_field_fail(o, LR_EINVAL, "'%s' is not a name (letters, digits, '_', '-', '.')",
                    o->value);
    snprintf(p, cap, "%s", o->value);
    return LR_OK;
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
    /* Directional and area lights: radiance; point and spot: intensity. */
    bool dir = l->type == LR_LIGHT_DIRECTIONAL || lr_light_is_area(l);
    if ((dir && strcmp(f, "intensity") == 0) || (!dir && strcmp(f, "radiance") == 0))
        return lr_field_fail(o, LR_EINVAL, "a %s light's strength is its '%s'",
                    lr_scene_light_desc.kind_names[l->type], dir ? "radiance" : "intensity");
    int rc = table_field(o, &lr_scene_light_desc, l, f, d);
    if (rc || o->get)
        return rc;
    /* The strength just set is the one the others follow (lr_light_resolve_units); a colour
     * set replaces the colour temperature. */
    if (strcmp(f, "intensity") == 0 || strcmp(f, "radiance") == 0)
        l->from = LR_STRENGTH_RADIOMETRIC;
    else if (strcmp(f, "intensity_cd") == 0)
        l->from = LR_STRENGTH_CD;
    else if (strcmp(f, "flux_lm") == 0)
        l->from = LR_STRENGTH_LM;
    else if (strcmp(f, "color") == 0)
        l->color_temperature_k = 0.0;
    return LR_OK;
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

/* The material spec's fields that a change writes (their meaning is render/material's). */
#define MS(m) offsetof(mat_spec, m)
static const lr_field mat_sigma_a = {.key = "sigma_a", .type = LR_FT_RGB, .off = MS(sigma_a)};
static const lr_field mat_sigma_s_prime = {.key = "sigma_s_prime", .type = LR_FT_RGB,
                                           .off = MS(sigma_s_prime)};
static const lr_field mat_eta = {.key = "eta", .type = LR_FT_NUM, .off = MS(eta)};
static const lr_field mat_g = {.key = "g", .type = LR_FT_NUM, .off = MS(g)};
/* A preset's scale: a number or per band (as an lr_vec3 in a scratch record). */
static const lr_field mat_scale = {.key = "scale", .type = LR_FT_SCALE};

static int material_field(op *o, mat_spec *m, const char *f)
{
    if (f[0] == '\0') { /* the preset itself */
        if (o->get)
            return lr_field_out(o, "%s", m->is_preset ? m->preset : m->has_base ? m->base : m->name);
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
            return lr_field_out(o, "1");
        if (strcmp(f, "base") == 0)
            return lr_field_out(o, "%s", m->preset);
    }
    if (!o->get)
        inline_preset(m);
    if (strcmp(f, "scale") == 0) {
        if (!m->has_base)
            return lr_field_fail(o, LR_EINVAL, "the material has no 'base' to scale (scale multiplies "
                        "a preset's coefficients)");
        if (o->get && !m->has_scale)
            return lr_field_out(o, "1");
        if (!o->get && !m->has_scale)
            m->scale[0] = m->scale[1] = m->scale[2] = 1.0;
        m->has_scale = true;
        lr_vec3 v = lr_v3(m->scale[0], m->scale[1], m->scale[2]);
        int rc = lr_field_apply(o, &mat_scale, &v);
        if (rc || o->get)
            return rc;
        m->scale[0] = v.x;
        m->scale[1] = v.y;
        m->scale[2] = v.z;
        for (int b = 0; b < 3; b++)
            if (!(m->scale[b] > 0.0))
                return lr_field_fail(o, LR_EINVAL, "must be > 0, got %g", m->scale[b]);
        return LR_OK;
    }
    if (strcmp(f, "base") == 0) {
        if (o->get && !m->has_base)
            return lr_field_out(o, "%s", "");
        m->has_base = true;
        return name_field(o, m->base, sizeof m->base);
    }
    if (strcmp(f, "sigma_a") == 0 || strcmp(f, "sigma_s_prime") == 0) {
        bool a = f[6] == 'a';
        if (!o->get)
            *(a ? &m->has_sigma_a : &m->has_sigma_s_prime) = true;
        int rc = lr_field_apply(o, a ? &mat_sigma_a : &mat_sigma_s_prime, m);
        if (!rc && !o->get)
            for (int b = 0; b < 3; b++)
                if (!((a ? m->sigma_a : m->sigma_s_prime)[b] >= 0.0))
                    return lr_field_fail(o, LR_EINVAL, "must be >= 0 (mm^-1), got %g",
                                (a ? m->sigma_a : m->sigma_s_prime)[b]);
        return rc;
    }
    if (strcmp(f, "eta") == 0) {
        if (!o->get)
            m->has_eta = true;
        return lr_field_apply(o, &mat_eta, m);
    }
    if (strcmp(f, "g") == 0) {
        if (!o->get)
            m->has_g = true;
        return lr_field_apply(o, &mat_g, m);
    }
    return lr_field_fail(o, LR_EINVAL, "a material has no parameter '%s' (known: (the preset itself), "
                "scale, base, sigma_a, sigma_s_prime, eta, g)", f);
}

static int mesh_field(op *o, mesh_spec *m, const char *f, unsigned *d)
{
    if (strcmp(f, "type") == 0) {
        if (o->get)
            return lr_field_out(o, "%s", lr_scene_mesh_desc.kind_names[m->kind]);
        return lr_field_fail(o, LR_EINVAL, "the mesh type cannot change at run time (edit the scene "
                    "file)");
    }
    if (!o->get)
        return table_field(o, &lr_scene_mesh_desc, m, f, d);
    /* get shows resolved values: the generators' defaults filled in (the flags that 0 set
     * stay as written). */
    mesh_spec r = *m;
    const char *bad;
    lr_err ignore = {0};
    switch (m->kind) {
    case LR_MESH_CANDLE: lr_candle_check(&m->candle, &r.candle, &bad, &ignore); break;
    case LR_MESH_SHADE: lr_shade_check(&m->shade, &r.shade, &bad, &ignore); break;
    case LR_MESH_SPHERE: lr_sphere_check(&m->sphere, &r.sphere, &bad, &ignore); break;
    case LR_MESH_BOX: lr_box_check(&m->box, &r.box, &bad, &ignore); break;
    case LR_MESH_FILE: break;
    }
    r.candle.flat_top = m->candle.flat_top;
    r.shade.single_surface = m->shade.single_surface;
    r.shade.no_rims = m->shade.no_rims;
    return table_field(o, &lr_scene_mesh_desc, &r, f, d);
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

#define OBJECT_KNOWN                                                                      \
    "known: material, material.*, mesh.*, transform.*, model, thickness_mm, normalize, "      \
    "dgrid_h_mm, dgrid_volume"

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
        /* The object's model must hold the new material (its numerics: optics.h,
         * lr_sss_model_props.max_sigma_tr). */
        if ((rc = lr_coeffs_derive(&mat.medium, &co, &inner)) ||
            (rc = lr_sss_model_check_medium(rec->pub.sss_model, &mat.medium, &inner)))
            return lr_err_set(o->e, rc, "%s: %s", o->key, inner.msg);
        rec->mat = m;
        rec->pub.material = mat;
        rec->pub.coeffs = co;
        *d = LR_DIRTY_MATERIAL;
        return LR_OK;
    }
    if (strcmp(f, "normalize") == 0 || strcmp(f, "dgrid_volume") == 0) /* another S_d; the
                                                   grid model's volume (read when it solves) */
        return table_field(o, &lr_scene_object_desc, rec, f, d);
    if (strcmp(f, "model") == 0 || strcmp(f, "thickness_mm") == 0 || strcmp(f, "dgrid_h_mm") == 0) {
        /* The multipole models a wall: it needs the wall's thickness (issue 12). */
        obj_rec next = *rec;
        const char *bad = NULL;
        if ((rc = table_field(o, &lr_scene_object_desc, &next, f, d)))
            return rc;
        if ((rc = lr_fields_check(&lr_scene_object_desc, &next, &bad, &inner)))
            return check_failed(o, f, bad, rc, &inner);
        if (lr_sss_model_props_of(next.pub.sss_model)->needs_thickness &&
            !(next.pub.thickness_mm > 0.0))
            return lr_field_fail(o, LR_EINVAL, strcmp(f, "model") == 0
                                          ? "%s needs the object's thickness_mm set first"
                                          : "the %s needs a thickness > 0 mm",
                                 lr_sss_model_name(next.pub.sss_model));
        if ((rc = lr_sss_model_check_medium(next.pub.sss_model, &next.pub.material.medium,
                                            &inner)))
            return lr_err_set(o->e, rc, "%s: the material's %s", o->key, inner.msg);
        *rec = next;
        return LR_OK;
    }
    mesh_spec ms = rec->mesh;
    xform_spec xf = rec->xf;
    const char *bad = NULL;
    if (strncmp(f, "mesh.", 5) == 0) {
        if ((rc = mesh_field(o, &ms, f + 5, d)))
            return rc;
        if ((rc = lr_scene_check_mesh(&ms, &bad, &inner)))
            return check_failed(o, f + 5, bad, rc, &inner);
    } else if (strncmp(f, "transform.", 10) == 0) {
        if ((rc = table_field(o, &lr_scene_transform_desc, &xf, f + 10, d)))
            return rc;
        if ((rc = lr_scene_check_transform(&xf, &bad, &inner)))
            return check_failed(o, f + 10, bad, rc, &inner);
    } else {
        return lr_field_fail(o, LR_EINVAL, "an object has no parameter '%s' (%s)", f, OBJECT_KNOWN);
    }
    lr_mesh *world, *built;
    lr_bvh *bvh;
    double model[16];
    if ((rc = lr_scene_build_object(s, where, &ms, &xf, &world, &built, &bvh, model, &inner)))
        return lr_err_set(o->e, rc, "%s: %s", o->key, inner.msg);
    lr_bvh_destroy(rec->bvh);
    lr_scene_object_meshes_destroy(rec->world, rec->built);
    rec->world = world;
    rec->built = built;
    rec->bvh = bvh;
    rec->mesh = ms;
    rec->xf = xf;
    memcpy(rec->pub.model, model, sizeof model);
    lr_scene_object_attach(&rec->pub, world, built, bvh);
    return LR_OK;
}

static int object_get(op *o, const lr_scene *s, int i, const char *f)
{
    obj_rec rec = s->obj[i]; /* a copy: the field map writes nothing back in get mode */
    const lr_medium *med = &rec.pub.material.medium;
    if (strcmp(f, "material") == 0 || strncmp(f, "material.", 9) == 0) {
        const char *g = f[8] ? f + 9 : "";
        /* Coefficients: the effective ones, whatever the spec says. */
        mat_spec eff = rec.mat;
        memcpy(eff.sigma_a, med->sigma_a, sizeof eff.sigma_a);
        memcpy(eff.sigma_s_prime, med->sigma_s_prime, sizeof eff.sigma_s_prime);
        eff.eta = med->eta;
        eff.g = med->g;
        const lr_field *coef[] = {&mat_sigma_a, &mat_sigma_s_prime, &mat_eta, &mat_g};
        for (int c = 0; c < 4; c++)
            if (strcmp(g, coef[c]->key) == 0)
                return lr_field_apply(o, coef[c], &eff);
        return material_field(o, &rec.mat, g);
    }
    unsigned d;
    if (strncmp(f, "mesh.", 5) == 0)
        return mesh_field(o, &rec.mesh, f + 5, &d);
    if (strncmp(f, "transform.", 10) == 0)
        return table_field(o, &lr_scene_transform_desc, &rec.xf, f + 10, &d);
    if (strcmp(f, "model") == 0 || strcmp(f, "normalize") == 0 || strcmp(f, "thickness_mm") == 0 ||
        strcmp(f, "dgrid_h_mm") == 0 || strcmp(f, "dgrid_volume") == 0)
        return table_field(o, &lr_scene_object_desc, &rec, f, &d);
    return lr_field_fail(o, LR_EINVAL, "an object has no parameter '%s' (%s)", f, OBJECT_KNOWN);
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
                return lr_field_fail(o, LR_EINVAL, "'%s' takes no index", S[i].name);
            const char *close = strchr(p, ']');
            if (!close || close == p + 1 || close[1] != '.')
                return lr_field_fail(o, LR_EINVAL, "expected %s[INDEX or NAME].PARAMETER", S[i].name);
            char idx[LR_SCENE_NAME_MAX];
            size_t len = (size_t)(close - p - 1);
            if (len >= sizeof idx)
                return lr_field_fail(o, LR_EINVAL, "index too long");
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
                    return lr_field_fail(o, LR_EINVAL, "index %s out of range (the scene has %d %s)", idx,
                                count, S[i].name);
            } else {
                k->index = k->section == K_OBJECT ? lr_scene_find_object(s, idx)
                           : k->section == K_LIGHT ? lr_scene_find_light(s, idx)
                                                   : lr_scene_find_receiver(s, idx);
                if (k->index < 0)
                    return lr_field_fail(o, LR_EINVAL, "no %s named '%s'", S[i].name, idx);
            }
            p = close + 1;
        } else if (S[i].list) {
            return lr_field_fail(o, LR_EINVAL, "expected %s[INDEX or NAME].PARAMETER", S[i].name);
        } else if (k->section == K_LIGHT && s->nlight == 0) {
            return lr_field_fail(o, LR_EINVAL, "the scene has no light");
        }
        k->field = p + 1;
        if (!k->field[0])
            return lr_field_fail(o, LR_EINVAL, "no parameter after the '.'");
        return LR_OK;
    }
    return lr_field_fail(o, LR_EINVAL, "unknown parameter (expected objects[i].*, lights[i].*, "
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
        /* A light given in lumens keeps its flux when its cone or area changes: its
         * intensity moved too. */
        const lr_light *was = &s->light[k.index];
        if (l.intensity != was->intensity || memcmp(l.color, was->color, sizeof l.color) != 0)
            d |= LR_DIRTY_INTENSITY;
        s->light[k.index] = l;
        break;
    }
    case K_CAMERA: {
        lr_camera c = s->camera;
        if ((rc = table_field(&o, &lr_scene_camera_desc, &c, k.field, &d)))
            return rc;
        if ((rc = lr_scene_check_camera(&c, &bad, &inner)))
            return check_failed(&o, k.field, bad, rc, &inner);
        s->camera = c;
        break;
    }
    case K_RENDER: {
        lr_render_settings r = s->render;
        if ((rc = table_field(&o, &lr_scene_render_desc, &r, k.field, &d)))
            return rc;
        if (strcmp(k.field, "exposure_ev") == 0)
            r.exposure_from_ev = true;
        else if (strcmp(k.field, "exposure") == 0)
            r.exposure_from_ev = false;
        if ((rc = lr_scene_check_render(&r, &bad, &inner)))
            return check_failed(&o, k.field, bad, rc, &inner);
        s->render = r;
        lr_scene_render_mark_given(s, k.field);
        break;
    }
    case K_QUALITY: {
        lr_quality q = s->quality;
        if ((rc = table_field(&o, &lr_scene_quality_desc, &q, k.field, &d)))
            return rc;
        if ((rc = lr_scene_check_quality(&q, &bad, &inner)))
            return check_failed(&o, k.field, bad, rc, &inner);
        s->quality = q;
        break;
    }
    case K_RECEIVER: {
        recv_rec *rr = &s->recv[k.index];
        lr_receiver r = rr->pub;
        if ((rc = table_field(&o, &lr_scene_receiver_desc, &r, k.field, &d)))
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
    if (s->journal.fn)
        s->journal.fn(s->journal.user, key, o.value, d);
    return LR_OK;
}

void lr_scene_set_journal(lr_scene *s, const lr_scene_journal *j)
{
    s->journal = j ? *j : (lr_scene_journal){0};
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
        return table_field(&o, &lr_scene_camera_desc, &c, k.field, &d);
    }
    case K_RENDER: {
        lr_render_settings r = s->render;
        return table_field(&o, &lr_scene_render_desc, &r, k.field, &d);
    }
    case K_QUALITY: {
        lr_quality q = s->quality;
        return table_field(&o, &lr_scene_quality_desc, &q, k.field, &d);
    }
    case K_RECEIVER: {
        lr_receiver r = s->recv[k.index].pub;
        return table_field(&o, &lr_scene_receiver_desc, &r, k.field, &d);
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
