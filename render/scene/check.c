/* Checks of scene records, shared by the file loader and lr_scene_set so that a value is
 * accepted or refused the same way wherever it comes from: the ranges of the field tables
 * (field_tables.c), then the relations between fields and the generators' own checks. */
#include <math.h>
#include <string.h>

#include "render/base/mat4.h"
#include "render/photometry/photometry.h"
#include "render/scene/fields.h"
#include "render/scene/scene_internal.h"

void lr_scene_light_defaults(lr_light *l, enum lr_light_type type)
{
    memset(l, 0, sizeof *l);
    l->type = type;
    lr_fields_defaults(&lr_scene_light_desc, l);
}

int lr_scene_check_light(lr_light *l, const char **field, lr_err *e)
{
    /* Only the strength the light was given is checked: the others are derived below, and a
     * derived one may lie outside its field's range (a bright light in lumens over a large
     * area) without being wrong. */
    if (l->from != LR_STRENGTH_RADIOMETRIC)
        l->intensity = 0.0;
    if (l->from != LR_STRENGTH_CD)
        l->intensity_cd = 0.0;
    if (l->from != LR_STRENGTH_LM)
        l->flux_lm = 0.0;
    int rc = lr_fields_check(&lr_scene_light_desc, l, field, e);
    if (rc)
        return rc;
    /* A spot's inner cone lies inside its outer one. */
    if (l->type == LR_LIGHT_SPOT && !(l->inner_deg > 0.0 && l->inner_deg <= l->outer_deg)) {
        *field = "inner_deg";
        return lr_err_set(e, LR_EINVAL, "must be in (0, outer_deg = %g] degrees, got %g",
                          l->outer_deg, l->inner_deg);
    }
    /* A quad has an area: its half-edges span a plane (the area is 4 |edge_u x edge_v|; a
     * relative 1e-9 keeps the normal well defined in double). */
    if (l->type == LR_LIGHT_QUAD) {
        double a = lr_v3_len(lr_v3_cross(l->edge_u, l->edge_v));
        if (!(a > 1e-9 * lr_v3_dot(l->edge_u, l->edge_u) && a > 1e-9 * lr_v3_dot(l->edge_v, l->edge_v)
              && a > 1e-12)) {
            *field = "edge_v";
            return lr_err_set(e, LR_EINVAL, "must not be parallel to edge_u (the quad has no "
                              "area), got edge_u %g,%g,%g and edge_v %g,%g,%g", l->edge_u.x,
                              l->edge_u.y, l->edge_u.z, l->edge_v.x, l->edge_v.y, l->edge_v.z);
        }
    }
    /* Candela, lumens and colour temperature to the renderer's intensity and colour (last:
     * the flux of a spot or an area light depends on its cone or its area). */
    return lr_light_resolve_units(l, field, e);
}

void lr_scene_camera_defaults(lr_camera *c)
{
    memset(c, 0, sizeof *c);
    lr_fields_defaults(&lr_scene_camera_desc, c);
}

int lr_scene_check_camera(lr_camera *c, const char **field, lr_err *e)
{
    int rc = lr_fields_check(&lr_scene_camera_desc, c, field, e);
    if (rc)
        return rc;
    /* A camera that can see: a view direction, an up not along it, far beyond near. */
    lr_vec3 f = lr_v3_sub(c->target, c->position);
    if (!(lr_v3_len(f) > 1e-6)) {
        *field = "target";
        return lr_err_set(e, LR_EINVAL, "must differ from position");
    }
    double m[16];
    if (lr_mat4_look_at(c->position, c->target, c->up, m) != 0) {
        *field = "up";
        return lr_err_set(e, LR_EINVAL, "must not be parallel to the view direction");
    }
    if (!(c->far_mm > c->near_mm && c->far_mm <= 1e7)) {
        *field = "far";
        return lr_err_set(e, LR_EINVAL, "must be > near (%g mm) and <= 1e7 mm, got %g",
                          c->near_mm, c->far_mm);
    }
    return LR_OK;
}

int lr_scene_check_receiver(lr_receiver *r, const char **field, lr_err *e)
{
    int rc = lr_fields_check(&lr_scene_receiver_desc, r, field, e);
    if (rc)
        return rc;
    /* The generators' own checks (render/mesh/shapes.h), which also resolve defaults. */
    if (r->type == LR_RECEIVER_PLANE) {
        lr_quad_desc q = {.center = r->center, .normal = r->normal, .u_dir = r->u_dir,
                          .size_u = r->size[0], .size_v = r->size[1],
                          .subdivisions = r->subdivisions}, res;
        if ((rc = lr_quad_check(&q, &res, field, e)))
            return rc;
        r->normal = res.normal;
        r->u_dir = res.u_dir;
        r->subdivisions = res.subdivisions;
        r->size[2] = 0.0;
        return LR_OK;
    }
    lr_box_desc b = {.center = r->center, .size = lr_v3(r->size[0], r->size[1], r->size[2])}, res;
    return lr_box_check(&b, &res, field, e);
}

void lr_scene_render_defaults(lr_render_settings *r)
{
    lr_fields_defaults(&lr_scene_render_desc, r);
}

int lr_scene_check_render(lr_render_settings *r, const char **field, lr_err *e)
{
    int rc = lr_fields_check(&lr_scene_render_desc, r, field, e);
    if (rc)
        return rc;
    /* The exposure in the unit it was given, and the other derived (render/photometry). */
    if (r->exposure_from_ev) {
        double x = lr_ev_to_exposure(r->exposure_ev);
        if (!(x > 0.0 && x < 1e30)) {
            *field = "exposure_ev";
            return lr_err_set(e, LR_EINVAL, "gives exposure %g, outside (0, 1e30)", x);
        }
        r->exposure = x;
    } else {
        r->exposure_ev = lr_exposure_to_ev(r->exposure);
    }
    return LR_OK;
}

int lr_scene_check_quality(const lr_quality *q, const char **field, lr_err *e)
{
    lr_quality c = *q;
    return lr_fields_check(&lr_scene_quality_desc, &c, field, e);
}

int lr_scene_check_transform(const xform_spec *x, const char **field, lr_err *e)
{
    xform_spec c = *x;
    return lr_fields_check(&lr_scene_transform_desc, &c, field, e);
}

int lr_scene_check_mesh(const mesh_spec *m, const char **field, lr_err *e)
{
    const char *f = NULL;
    int rc = LR_OK;
    switch (m->kind) {
    case LR_MESH_CANDLE: {
        lr_candle_desc r;
        rc = lr_candle_check(&m->candle, &r, &f, e);
        break;
    }
    case LR_MESH_SHADE: {
        lr_shade_desc r;
        rc = lr_shade_check(&m->shade, &r, &f, e);
        break;
    }
    case LR_MESH_SPHERE: {
        lr_sphere_desc r;
        rc = lr_sphere_check(&m->sphere, &r, &f, e);
        break;
    }
    case LR_MESH_BOX: {
        lr_box_desc r;
        rc = lr_box_check(&m->box, &r, &f, e);
        break;
    }
    case LR_MESH_FILE:
        if (!m->path[0]) {
            f = "path";
            rc = lr_err_set(e, LR_EINVAL, "must not be empty");
        } else {
            mesh_spec c = *m;
            rc = lr_fields_check(&lr_scene_mesh_desc, &c, &f, e);
        }
        break;
    }
    /* The generators' field names are the file's ("pool_depth" in "mesh"). */
    *field = f;
    return rc;
}
