/* lamprig — translucent radiosity: meshes cut finer than their patches.
 *
 * A cluster (patches.c) can only be as small as the triangles it groups; a mesh with large
 * triangles (the votive's 160 faces) is cut, each triangle into L^2 by the same L for every
 * triangle, so that shared edges get the same points and no crack opens between neighbours
 * (each point is sum_k i_k p_k / L, the same sums in either triangle). */
#include "render/transrad/tr_priv.h"

#include <math.h>
#include <stdlib.h>

int lr_tr_refine(lr_tr *t, int s, lr_err *e)
{
    lr_tr_surf *sf = &t->surf[s];
    const lr_mesh *m = sf->d.mesh;
    double h = sf->d.patch_mm > 0 ? sf->d.patch_mm
                                  : sf->d.kind == LR_TR_TRANSLUCENT ? t->set.patch_mm
                                                                    : t->set.receiver_mm;
    size_t nt = lr_mesh_triangle_count(m);
    double longest = 0;
    for (size_t i = 0; i < nt; i++) {
        lr_vec3 p[3];
        lr_mesh_triangle(m, i, p);
        for (int k = 0; k < 3; k++)
            longest = fmax(longest, lr_v3_len(lr_v3_sub(p[(k + 1) % 3], p[k])));
    }
    /* Cut until edges are at most half a patch: clusters then follow the cells. */
    int L = (int)ceil(longest / (0.5 * h));
    while (L > 1 && nt * (size_t)L * (size_t)L > LR_TR_MAX_TRIANGLES)
        L--;
    if (L <= 1)
        return LR_OK;
    size_t vpt = (size_t)(L + 1) * (size_t)(L + 2) / 2, tpt = (size_t)L * (size_t)L;
    double *pos = malloc(nt * vpt * 3 * sizeof *pos);
    uint32_t *idx = malloc(nt * tpt * 3 * sizeof *idx);
    if (!pos || !idx) {
        free(pos);
        free(idx);
        return lr_err_set(e, LR_ENOMEM, "transrad: surface %d: out of memory (refining)", s);
    }
    size_t nv = 0, ni = 0;
    for (size_t i = 0; i < nt; i++) {
        lr_vec3 p[3];
        lr_mesh_triangle(m, i, p);
        size_t base = nv;
        /* Vertex (a, b) with a + b <= L: weights (L - a - b, a, b) / L. */
        for (int a = 0; a <= L; a++)
            for (int b = 0; a + b <= L; b++) {
                int c0 = L - a - b;
                pos[3 * nv + 0] = (p[0].x * c0 + p[1].x * a + p[2].x * b) / L;
                pos[3 * nv + 1] = (p[0].y * c0 + p[1].y * a + p[2].y * b) / L;
                pos[3 * nv + 2] = (p[0].z * c0 + p[1].z * a + p[2].z * b) / L;
                nv++;
            }
#define VID(a, b) ((uint32_t)(base + (size_t)(a) * (size_t)(2 * L + 3 - (a)) / 2 + (size_t)(b)))
        for (int a = 0; a < L; a++)
            for (int b = 0; a + b < L; b++) {
                idx[ni++] = VID(a, b);
                idx[ni++] = VID(a + 1, b);
                idx[ni++] = VID(a, b + 1);
                if (a + b + 2 <= L) {
                    idx[ni++] = VID(a + 1, b);
                    idx[ni++] = VID(a + 1, b + 1);
                    idx[ni++] = VID(a, b + 1);
                }
            }
#undef VID
    }
    lr_mesh_desc d = {.name = lr_mesh_name(m), .vertex_count = nv, .positions = pos,
                      .triangle_count = ni / 3, .indices = idx,
                      .checks = {.flags = LR_MESH_OPEN_OK | LR_MESH_KEEP_WINDING}};
    int rc = lr_mesh_create(&d, &sf->own_mesh, e);
    free(pos);
    free(idx);
    if (rc)
        return rc;
    rc = lr_bvh_create(sf->own_mesh, &sf->own_bvh, e);
    if (rc)
        return rc;
    sf->d.mesh = sf->own_mesh;
    sf->d.bvh = sf->own_bvh;
    return LR_OK;
}
