#include "render/core/ray.h"

#include <math.h>

#include "render/mesh/bvh.h"
#include "render/mesh/mesh.h"

void lr_tangents(lr_vec3 n, lr_vec3 *t1, lr_vec3 *t2)
{
    /* Duff et al. 2017, "Building an Orthonormal Basis, Revisited". */
    double sign = copysign(1.0, n.z);
    double a = -1.0 / (sign + n.z);
    double b = n.x * n.y * a;
    *t1 = lr_v3(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    *t2 = lr_v3(b, sign + n.y * n.y * a, -n.y);
}

bool lr_first_surface(const lr_scene_object *obj, lr_vec3 o, lr_vec3 dir, double tmin,
                      lr_vec3 *xi, lr_vec3 *ni)
{
    lr_hit hit;
    if (!lr_bvh_intersect(obj->bvh, o, dir, tmin, INFINITY, &hit))
        return false;
    *xi = lr_v3_add(o, lr_v3_scale(dir, hit.t));
    const lr_mesh *m = obj->mesh;
    const uint32_t *idx = lr_mesh_indices(m) + 3 * hit.triangle;
    const float *nv = lr_mesh_normals(m);
    double w0 = 1.0 - hit.u - hit.v;
    lr_vec3 n = lr_v3(0, 0, 0);
    const double w[3] = {w0, hit.u, hit.v};
    for (int k = 0; k < 3; k++) {
        const float *p = nv + 3 * idx[k];
        n = lr_v3_add(n, lr_v3_scale(lr_v3(p[0], p[1], p[2]), w[k]));
    }
    double len = lr_v3_len(n);
    *ni = len > 1e-12 ? lr_v3_scale(n, 1.0 / len) : lr_mesh_triangle_normal(m, hit.triangle);
    return true;
}
