/* Placing a mesh in the world: positions by the affine transform, normals by its inverse
 * transpose (so that a non-uniform scale keeps them perpendicular to the surface). */
#include "render/mesh/mesh_internal.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/mat4.h"

int lr_mesh_transform(const lr_mesh *m, const double mat[16], lr_mesh **out, lr_err *e)
{
    *out = NULL;
    double nm[9];
    if (lr_mat4_normal_matrix(mat, nm))
        return lr_err_set(e, LR_EINVAL, "%s: transform is singular (a scale of zero?)", m->name);
    bool mirror = lr_mat4_det3(mat) < 0.0;
    lr_mesh *t = calloc(1, sizeof *t);
    if (!t || !(t->name = strdup(m->name)) || !(t->pos = malloc(3 * m->nv * sizeof *t->pos)) ||
        !(t->nrm = malloc(3 * m->nv * sizeof *t->nrm)) ||
        !(t->idx = malloc(3 * m->nt * sizeof *t->idx))) {
        lr_mesh_destroy(t);
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory", m->name);
    }
    t->nv = m->nv;
    t->nt = m->nt;
    for (size_t v = 0; v < m->nv; v++) {
        lr_vec3 p = lr_mat4_point(mat, lr_mesh_vertex(m, v));
        if (!lr_v3_isfinite(p) || fabs(p.x) > FLT_MAX || fabs(p.y) > FLT_MAX ||
            fabs(p.z) > FLT_MAX) {
            lr_mesh_destroy(t);
            return lr_err_set(e, LR_EINVAL, "%s: vertex %zu leaves the float range when "
                              "transformed", m->name, v);
        }
        const float *n0 = &m->nrm[3 * v];
        lr_vec3 n = lr_v3_normalize(lr_mat3_apply(nm, lr_v3(n0[0], n0[1], n0[2])));
        t->pos[3 * v] = (float)p.x;
        t->pos[3 * v + 1] = (float)p.y;
        t->pos[3 * v + 2] = (float)p.z;
        t->nrm[3 * v] = (float)n.x;
        t->nrm[3 * v + 1] = (float)n.y;
        t->nrm[3 * v + 2] = (float)n.z;
    }
    for (size_t i = 0; i < m->nt; i++) {
        t->idx[3 * i] = m->idx[3 * i];
        t->idx[3 * i + 1] = m->idx[3 * i + (mirror ? 2 : 1)];
        t->idx[3 * i + 2] = m->idx[3 * i + (mirror ? 1 : 2)];
    }
    *out = t;
    return LR_OK;
}
