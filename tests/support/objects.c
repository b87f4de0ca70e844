#include "tests/support/objects.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/mesh/shapes.h"

static void die(const char *what, const lr_err *e)
{
    fprintf(stderr, "objects: %s: %s\n", what, e->msg);
    abort();
}

lr_bvh *lrt_bvh(const lr_mesh *m)
{
    lr_err e = {0};
    lr_bvh *b = NULL;
    if (lr_bvh_create(m, &b, &e))
        die("bvh", &e);
    return b;
}

void lrt_object_make(lr_mesh *m, const lr_medium *medium, lrt_object *out)
{
    lr_err e = {0};
    memset(out, 0, sizeof *out);
    if (lr_coeffs_derive(medium, &out->obj.coeffs, &e))
        die("material", &e);
    if (lr_bvh_create(m, &out->bvh, &e))
        die("bvh", &e);
    out->mesh = m;
    out->obj.mesh = m;
    out->obj.bvh = out->bvh;
    out->obj.material.medium = *medium;
    lr_mesh_bounding_sphere(m, &out->obj.center, &out->obj.radius);
    out->obj.area = lr_mesh_area(m);
    lr_mesh_report rep;
    lr_mesh_analyze(m, &rep);
    out->obj.closed = rep.closed;
}

void lrt_object_free(lrt_object *o)
{
    lr_bvh_destroy(o->bvh);
    lr_mesh_destroy(o->mesh);
    memset(o, 0, sizeof *o);
}

lr_mesh *lrt_shell_mesh(double ro, double ri, int sub)
{
    lr_err e = {0};
    lr_mesh *a, *b;
    lr_sphere_desc d = {.radius = ro, .subdivisions = sub};
    if (lr_mesh_sphere(&d, &a, &e))
        die("sphere", &e);
    if (ri <= 0.0)
        return a;
    d.radius = ri;
    if (lr_mesh_sphere(&d, &b, &e))
        die("sphere", &e);
    size_t na = lr_mesh_vertex_count(a), nb = lr_mesh_vertex_count(b);
    size_t ta = lr_mesh_triangle_count(a), tb = lr_mesh_triangle_count(b);
    double *pos = malloc(sizeof(double) * 3 * (na + nb));
    double *nor = malloc(sizeof(double) * 3 * (na + nb));
    uint32_t *idx = malloc(sizeof(uint32_t) * 3 * (ta + tb));
    if (!pos || !nor || !idx)
        abort();
    for (size_t v = 0; v < na; v++)
        for (int k = 0; k < 3; k++) {
            pos[3 * v + k] = lr_mesh_positions(a)[3 * v + k];
            nor[3 * v + k] = lr_mesh_normals(a)[3 * v + k];
        }
    for (size_t v = 0; v < nb; v++)
        for (int k = 0; k < 3; k++) {
            pos[3 * (na + v) + k] = lr_mesh_positions(b)[3 * v + k];
            nor[3 * (na + v) + k] = -lr_mesh_normals(b)[3 * v + k]; /* into the cavity */
        }
    for (size_t t = 0; t < 3 * ta; t++)
        idx[t] = lr_mesh_indices(a)[t];
    for (size_t t = 0; t < tb; t++) { /* reversed winding: the cavity's faces look inwards */
        const uint32_t *s = lr_mesh_indices(b) + 3 * t;
        idx[3 * (ta + t) + 0] = (uint32_t)na + s[0];
        idx[3 * (ta + t) + 1] = (uint32_t)na + s[2];
        idx[3 * (ta + t) + 2] = (uint32_t)na + s[1];
    }
    lr_mesh_desc md = {.name = "shell", .vertex_count = na + nb, .positions = pos,
                       .normals = nor, .triangle_count = ta + tb, .indices = idx,
                       .checks = {.flags = LR_MESH_KEEP_WINDING}};
    lr_mesh *m;
    if (lr_mesh_create(&md, &m, &e))
        die("shell", &e);
    lr_mesh_destroy(a);
    lr_mesh_destroy(b);
    free(pos);
    free(nor);
    free(idx);
    return m;
}

lr_light lrt_point_light(lr_vec3 p)
{
    lr_light l;
    memset(&l, 0, sizeof l);
    l.type = LR_LIGHT_POINT;
    l.position = p;
    l.intensity = 1.0;
    l.color[0] = l.color[1] = l.color[2] = 1.0;
    return l;
}

lr_light lrt_directional_light(lr_vec3 dir)
{
    lr_light l = lrt_point_light(lr_v3(0, 0, 0));
    l.type = LR_LIGHT_DIRECTIONAL;
    l.direction = lr_v3_normalize(dir);
    return l;
}
