/* lamprig — a deep copy of a scene (scene.h, lr_scene_clone): a worker thread renders its own
 * copy while the caller's loop keeps changing the original. */
#include <stdlib.h>
#include <string.h>

#include "render/base/mat4.h"
#include "render/mesh/bvh.h"
#include "render/scene/scene_internal.h"

/* An exact copy: the identity transform multiplies by 1 and adds 0, which leaves every finite
 * coordinate and normal as it was. */
static int mesh_copy(const lr_mesh *m, lr_mesh **out, lr_err *e)
{
    double id[16];
    lr_mat4_identity(id);
    return lr_mesh_transform(m, id, out, e);
}

int lr_scene_clone(const lr_scene *s, const lr_warn_sink *warn, lr_scene **out, lr_err *e)
{
    *out = NULL;
    lr_scene *c = calloc(1, sizeof *c);
    if (!c)
        return lr_err_set(e, LR_ENOMEM, "scene %s: copy: out of memory", s->name);
    *c = *s;
    c->warn = warn ? *warn : (lr_warn_sink){0};
    c->journal = (lr_scene_journal){0};
    c->obj = s->nobj ? calloc((size_t)s->nobj, sizeof *c->obj) : NULL;
    c->light = s->nlight ? calloc((size_t)s->nlight, sizeof *c->light) : NULL;
    c->recv = s->nrecv ? calloc((size_t)s->nrecv, sizeof *c->recv) : NULL;
    c->nobj = c->nrecv = 0; /* counted as they are copied, so destroy frees what exists */
    int rc = LR_OK;
    if ((s->nobj && !c->obj) || (s->nlight && !c->light) || (s->nrecv && !c->recv))
        rc = lr_err_set(e, LR_ENOMEM, "scene %s: copy: out of memory", s->name);
    if (!rc && s->nlight)
        memcpy(c->light, s->light, (size_t)s->nlight * sizeof *c->light);
    for (int i = 0; !rc && i < s->nobj; i++) {
        const obj_rec *so = &s->obj[i];
        obj_rec *co = &c->obj[i];
        *co = *so;
        co->world = co->built = NULL;
        co->bvh = NULL;
        rc = mesh_copy(so->world, &co->world, e);
        if (!rc)
            rc = so->built == so->world ? (co->built = co->world, LR_OK)
                                        : mesh_copy(so->built, &co->built, e);
        if (!rc)
            rc = lr_bvh_create(co->world, &co->bvh, e);
        if (co->world)
            c->nobj = i + 1;
        if (!rc) {
            /* The derived fields (bounds, area, wall) are copied as they are: same mesh. */
            co->pub.mesh = co->world;
            co->pub.built_mesh = co->built;
            co->pub.bvh = co->bvh;
        }
    }
    for (int i = 0; !rc && i < s->nrecv; i++) {
        const recv_rec *sr = &s->recv[i];
        recv_rec *cr = &c->recv[i];
        *cr = *sr;
        cr->mesh = NULL;
        cr->bvh = NULL;
        rc = mesh_copy(sr->mesh, &cr->mesh, e);
        if (cr->mesh)
            c->nrecv = i + 1;
        if (!rc)
            rc = lr_bvh_create(cr->mesh, &cr->bvh, e);
        if (!rc) {
            cr->pub.mesh = cr->mesh;
            cr->pub.bvh = cr->bvh;
        }
    }
    if (rc) {
        lr_scene_destroy(c);
        return lr_err_prefix(e, "scene %s: copy", s->name);
    }
    *out = c;
    return LR_OK;
}
