/* Triangle meshes (render/mesh) as reference shapes, ray cast through their BVH.
 *
 * The normal of a hit is the triangle's geometric normal, not the interpolated vertex normal
 * the GPU shades with: the reference renders the faceted surface that the mesh is, so that
 * refraction is a property of a real surface (a shading normal is not one: it breaks the
 * reciprocity of the Fresnel boundary, and a ray refracted by it can leave through the face it
 * entered). Compare the GPU against a reference of a finely enough tessellated mesh. */
#include "render/reference/ref_priv.h"

#include <stdlib.h>

#include "render/mesh/bvh.h"

typedef struct mesh_shape {
    const lr_mesh *m;
    lr_mesh *owned; /* freed with the shape when the shape owns the mesh */
    lr_bvh *bvh;
} mesh_shape;

static bool mesh_intersect(const void *self, lr_vec3 o, lr_vec3 d, double tmin, double tmax,
                           lr_ref_hit *hit)
{
    const mesh_shape *s = self;
    lr_hit h;
    if (!lr_bvh_intersect(s->bvh, o, d, tmin, tmax, &h) || !(h.t > tmin && h.t < tmax))
        return false;
    hit->t = h.t;
    hit->n = lr_mesh_triangle_normal(s->m, h.triangle);
    return true;
}

static void mesh_hash(const void *self, lr_ref_hash *h)
{
    const mesh_shape *s = self;
    size_t nv = lr_mesh_vertex_count(s->m), nt = lr_mesh_triangle_count(s->m);
    lr_ref_hash_str(h, "mesh");
    lr_ref_hash_u64(h, nv);
    lr_ref_hash_u64(h, nt);
    /* The float positions and indices are the geometry (normals are not used here). */
    const float *p = lr_mesh_positions(s->m);
    for (size_t i = 0; i < 3 * nv; i++)
        lr_ref_hash_double(h, p[i]);
    const uint32_t *ix = lr_mesh_indices(s->m);
    for (size_t i = 0; i < 3 * nt; i++)
        lr_ref_hash_u64(h, ix[i]);
}

static void mesh_destroy(void *self)
{
    mesh_shape *s = self;
    lr_bvh_destroy(s->bvh);
    lr_mesh_destroy(s->owned);
    free(s);
}

static const lr_ref_shape_ops closed_ops = {
    .name = "closed mesh",
    .intersect = mesh_intersect,
    .hash = mesh_hash,
    .destroy = mesh_destroy,
    .closed = true,
};

static const lr_ref_shape_ops open_ops = {
    .name = "open mesh",
    .intersect = mesh_intersect,
    .hash = mesh_hash,
    .destroy = mesh_destroy,
    .closed = false,
};

int lr_ref_mesh_create(lr_mesh *m, bool take, lr_ref_shape **out, lr_err *e)
{
    *out = NULL;
    mesh_shape *s = calloc(1, sizeof *s);
    if (!s) {
        if (take)
            lr_mesh_destroy(m);
        return lr_err_set(e, LR_ENOMEM, "reference: out of memory for a mesh shape");
    }
    s->m = m;
    s->owned = take ? m : NULL;
    int rc = lr_bvh_create(m, &s->bvh, e);
    if (rc) {
        mesh_destroy(s);
        return rc;
    }
    /* Only a watertight mesh whose faces agree on outside can bound a medium. */
    lr_mesh_report rep;
    lr_mesh_analyze(m, &rep);
    return lr_ref_shape_create(rep.closed && rep.oriented ? &closed_ops : &open_ops, s, out, e);
}
