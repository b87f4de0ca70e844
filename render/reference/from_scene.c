/* The reference scene of a project scene (render/scene, configs/scenes/NAME.json): what the bench
 * measures the real-time models against. */
#include "render/reference/ref_priv.h"

#include "render/base/mat4.h"
#include "render/scene/scene.h"

/* Receivers are moved this far (mm) away from the scene, along their normal: a candle
 * standing on the table has its bottom face in the table's plane, and two coincident surfaces
 * leave it to rounding which one a ray meets (light leaving the wax there could slip past the
 * table). With the gap the light leaves the wax, meets the table and comes back, as it does
 * through the microscopic air gap under a real candle. */
#define RECEIVER_GAP_MM 1e-3

/* The gap (mm) between the two faces of a two-sided area light: the reference's area lights
 * are one-sided surfaces that absorb what meets them, so a two-sided one is two of them back
 * to back; the gap keeps their order along a ray unambiguous (as RECEIVER_GAP_MM does). */
#define TWO_SIDED_GAP_MM 1e-3

static int add_light(lr_ref_scene *s, const lr_light *l, lr_err *e)
{
    /* The steady light: flicker is a display effect around intensity (mean factor 1). */
    lr_ref_light_desc ld = {.kind = l->type == LR_LIGHT_SPOT ? LR_REF_LIGHT_SPOT
                                                              : LR_REF_LIGHT_POINT,
                            .position = l->position, .direction = l->direction,
                            .inner_deg = l->inner_deg, .outer_deg = l->outer_deg};
    lr_light_rgb(l, ld.emission);
    if (l->profile.on) {
        ld.profile = &l->profile;
        lr_light_profile_axes(l, &ld.prof_x, &ld.prof_y, &ld.prof_z);
    }
    if (l->type == LR_LIGHT_QUAD) {
        /* The reference's quad is a corner and full edges; it emits on edge1 x edge2's side,
         * which is edge_u x edge_v's. */
        ld.kind = LR_REF_LIGHT_QUAD;
        ld.position = lr_v3_sub(lr_v3_sub(l->position, l->edge_u), l->edge_v);
        ld.edge1 = lr_v3_scale(l->edge_u, 2.0);
        ld.edge2 = lr_v3_scale(l->edge_v, 2.0);
    } else if (l->type == LR_LIGHT_DISK) {
        ld.kind = LR_REF_LIGHT_DISK;
        ld.radius = l->radius;
    }
    int rc = lr_ref_scene_add_light(s, &ld, e);
    if (rc || !lr_light_is_area(l) || !l->two_sided)
        return rc;
    /* The back face: the same emitter turned over, just behind the front one. */
    lr_vec3 n = l->type == LR_LIGHT_DISK ? l->direction
                                         : lr_v3_normalize(lr_v3_cross(l->edge_u, l->edge_v));
    lr_vec3 back = lr_v3_scale(n, -TWO_SIDED_GAP_MM);
    ld.position = lr_v3_add(ld.position, back);
    if (l->type == LR_LIGHT_QUAD) {
        lr_vec3 t = ld.edge1;
        ld.edge1 = ld.edge2;
        ld.edge2 = t;
    } else {
        ld.direction = lr_v3_scale(l->direction, -1.0);
    }
    /* The back face's pattern is the front's mirrored in the emitter's plane: nadir turned. */
    ld.prof_z = lr_v3_scale(ld.prof_z, -1.0);
    return lr_ref_scene_add_light(s, &ld, e);
}

int lr_ref_scene_from_scene(const lr_scene *sc, lr_ref_scene **out, lr_ref_camera *cam,
                            lr_err *e)
{
    *out = NULL;
    const lr_camera *c = lr_scene_camera(sc);
    if (c->orthographic)
        return lr_err_set(e, LR_EUNSUPPORTED, "%s: the reference renders perspective cameras "
                          "only", lr_scene_name(sc));
    for (int i = 0; i < lr_scene_light_count(sc); i++)
        if (lr_scene_light_at(sc, i)->type == LR_LIGHT_DIRECTIONAL)
            return lr_err_set(e, LR_EUNSUPPORTED, "%s: light '%s': the reference has no "
                              "directional lights", lr_scene_name(sc),
                              lr_scene_light_at(sc, i)->name);
    lr_ref_scene *s;
    int rc = lr_ref_scene_create(NULL, &s, e);
    for (int i = 0; !rc && i < lr_scene_object_count(sc); i++) {
        const lr_scene_object *ob = lr_scene_object_at(sc, i);
        lr_ref_medium_desc md;
        lr_ref_medium_from_optics(&ob->material.medium, &md);
        md.name = ob->material.name;
        int id;
        lr_ref_shape *shape;
        if ((rc = lr_ref_scene_add_medium(s, &md, &id, e)) ||
            (rc = lr_ref_mesh_create((lr_mesh *)ob->built_mesh, false, &shape, e)))
            break;
        lr_ref_object_desc od = {.kind = LR_REF_BOUNDARY, .shape = shape, .inside = id,
                                 .name = ob->name};
        rc = lr_ref_scene_add_object(s, &od, e);
    }
    for (int i = 0; !rc && i < lr_scene_receiver_count(sc); i++) {
        const lr_receiver *r = lr_scene_receiver_at(sc, i);
        lr_mesh *moved = NULL;
        if (r->type == LR_RECEIVER_PLANE) {
            double t[16];
            lr_mat4_translate(lr_v3_scale(r->normal, -RECEIVER_GAP_MM), t);
            if ((rc = lr_mesh_transform(r->mesh, t, &moved, e)))
                break;
        }
        lr_ref_shape *shape;
        if ((rc = lr_ref_mesh_create(moved ? moved : (lr_mesh *)r->mesh, moved != NULL, &shape,
                                     e)))
            break;
        lr_ref_object_desc od = {.kind = LR_REF_RECEIVER, .shape = shape, .name = r->name};
        for (int b = 0; b < 3; b++)
            od.albedo[b] = r->albedo[b];
        rc = lr_ref_scene_add_object(s, &od, e);
    }
    for (int i = 0; !rc && i < lr_scene_light_count(sc); i++)
        rc = add_light(s, lr_scene_light_at(sc, i), e);
    if (!rc)
        rc = lr_ref_scene_finish(s, e);
    if (rc) {
        lr_ref_scene_destroy(s);
        return lr_err_prefix(e, "%s", lr_scene_name(sc));
    }
    *cam = (lr_ref_camera){.position = c->position, .look_at = c->target, .up = c->up,
                           .fov_y_deg = c->fov_deg};
    *out = s;
    return LR_OK;
}
