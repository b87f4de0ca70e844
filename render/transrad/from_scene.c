/* lamprig — translucent radiosity from a scene: every object translucent (its model, its
 * thickness), every receiver diffuse (planes as grids, boxes as meshes). */
#include "render/transrad/tr_priv.h"

int lr_tr_create_scene(const lr_scene *s, const lr_tr_settings *settings, lr_tr **out,
                       lr_err *e)
{
    lr_tr_surface_desc d[LR_TR_MAX_SURFACES];
    int n = 0, no = lr_scene_object_count(s), nr = lr_scene_receiver_count(s);
    if (no + nr > LR_TR_MAX_SURFACES)
        return lr_err_set(e, LR_EINVAL, "transrad: %s: %d objects and receivers, at most %d",
                          lr_scene_name(s), no + nr, LR_TR_MAX_SURFACES);
    for (int i = 0; i < no; i++) {
        const lr_scene_object *o = lr_scene_object_at(s, i);
        /* A closed body covers the receiver cells it stands on (cover.c): their part under
         * its foot is no surface, as in the receivers' bounce (render/bounce). */
        d[n++] = (lr_tr_surface_desc){.kind = LR_TR_TRANSLUCENT, .mesh = o->mesh, .bvh = o->bvh,
                                      .coeffs = &o->coeffs, .model = o->sss_model,
                                      .thickness_mm = o->thickness_mm, .covers = o->closed};
    }
    for (int i = 0; i < nr; i++) {
        const lr_receiver *r = lr_scene_receiver_at(s, i);
        lr_tr_surface_desc x = {.kind = r->type == LR_RECEIVER_PLANE ? LR_TR_PLANE : LR_TR_DIFFUSE,
                                .mesh = r->mesh, .bvh = r->bvh, .center = r->center,
                                .normal = r->normal, .u_dir = r->u_dir, .size_u = r->size[0],
                                .size_v = r->size[1]};
        for (int b = 0; b < 3; b++)
            x.albedo[b] = r->albedo[b];
        d[n++] = x;
    }
    return lr_tr_create(d, n, settings, out, e);
}
