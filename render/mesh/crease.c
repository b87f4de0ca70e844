/* Vertex normals for a mesh file that gives none, split along sharp edges (mesh_internal.h).
 *
 * Why: averaging every face around a vertex (lr_mesh_create's computed normals) bends the
 * normals of a whole wall when its vertices are shared with a floor or a rim at 90 degrees: on
 * configs/meshes/votive.obj (6 rings, 90-degree edges at the floor, the rim and the bottom) the
 * corner normals were up to 84 degrees from their facet on the rim, 69 on the floor and 22-23
 * on the walls (tilted toward the floor and the rim). The physical reference uses the faces'
 * geometric normals; the renderer's estimator, the light's G-buffer and the cavity closure use
 * these vertex normals, so a tilt changes which face the diffusion profile treats as "across
 * the wall" (the multipole's R or T) and the Fresnel factors. Modelling tools smooth only
 * across edges below an angle ("auto smooth"); this does the same.
 *
 * Corner (t, k) at vertex v gets sum_s A_s n_s over the triangles s around v whose unit normal
 * is within LR_MESH_CREASE_DEG of t's (A_s n_s = half the cross product: area-weighted, as
 * lr_mesh_create's normals), normalised; corners of v with equal sums (the same set of faces,
 * summed in the same order) share one output vertex. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/mesh/mesh_internal.h"

static lr_vec3 tri_cross_d(const double *pos, const uint32_t *t)
{
    const double *a = &pos[3 * t[0]], *b = &pos[3 * t[1]], *c = &pos[3 * t[2]];
    lr_vec3 u = lr_v3(b[0] - a[0], b[1] - a[1], b[2] - a[2]);
    lr_vec3 w = lr_v3(c[0] - a[0], c[1] - a[1], c[2] - a[2]);
    return lr_v3_cross(u, w);
}

int lr_mesh_crease_normals(const double *pos, size_t nv, uint32_t *idx, size_t nt,
                           double cos_crease, double **pos_out, double **nrm_out,
                           size_t *nv_out)
{
    *pos_out = *nrm_out = NULL;
    *nv_out = 0;
    size_t nc = 3 * nt;
    /* Input lr_mesh_create would refuse: left to it, so that its message names the problem. */
    for (size_t c = 0; c < nc; c++)
        if (idx[c] >= nv)
            return 1;
    for (size_t i = 0; i < 3 * nv; i++)
        if (!isfinite(pos[i]))
            return 1;
    lr_vec3 *fn = malloc((nt ? nt : 1) * sizeof *fn);   /* area-weighted face normals */
    lr_vec3 *fu = malloc((nt ? nt : 1) * sizeof *fu);   /* unit (0 for zero area) */
    size_t *start = calloc(nv + 1, sizeof *start);       /* CSR: corners around each vertex */
    size_t *fill = calloc(nv + 1, sizeof *fill);
    size_t *around = malloc((nc ? nc : 1) * sizeof *around);
    lr_vec3 *cn = malloc((nc ? nc : 1) * sizeof *cn);   /* per corner */
    uint32_t *out_of = malloc((nc ? nc : 1) * sizeof *out_of);
    double *op = malloc(3 * (nc ? nc : 1) * sizeof *op);
    double *on = malloc(3 * (nc ? nc : 1) * sizeof *on);
    int rc = -1;
    if (!fn || !fu || !start || !fill || !around || !cn || !out_of || !op || !on)
        goto done;
    for (size_t t = 0; t < nt; t++) {
        fn[t] = tri_cross_d(pos, &idx[3 * t]);
        double l = lr_v3_len(fn[t]);
        fu[t] = l > 0.0 && isfinite(l) ? lr_v3_scale(fn[t], 1.0 / l) : lr_v3(0, 0, 0);
    }
    for (size_t c = 0; c < nc; c++)
        start[idx[c] + 1]++;
    for (size_t v = 0; v < nv; v++)
        start[v + 1] += start[v];
    for (size_t c = 0; c < nc; c++)
        around[start[idx[c]] + fill[idx[c]]++] = c;
    for (size_t c = 0; c < nc; c++) {
        size_t t = c / 3, v = idx[c];
        lr_vec3 s = lr_v3(0, 0, 0);
        for (size_t i = start[v]; i < start[v + 1]; i++) {
            size_t u = around[i] / 3;
            if (lr_v3_dot(fu[t], fu[u]) >= cos_crease)
                s = lr_v3_add(s, fn[u]);
        }
        double l = lr_v3_len(s);
        /* Faces that cancel (or a zero-area corner's own face): its face's normal, else up;
         * lr_mesh_create drops zero-area triangles and unreferenced vertices afterwards. */
        cn[c] = l > 0.0 && isfinite(l) ? lr_v3_scale(s, 1.0 / l)
                : lr_v3_len(fu[t]) > 0.0 ? fu[t] : lr_v3(0, 0, 1);
    }
    /* Output vertices: per input vertex, one per distinct corner normal, in corner order. */
    size_t no = 0;
    for (size_t v = 0; v < nv; v++) {
        size_t first = no;
        for (size_t i = start[v]; i < start[v + 1]; i++) {
            size_t c = around[i], j = first;
            for (; j < no; j++)
                if (on[3 * j] == cn[c].x && on[3 * j + 1] == cn[c].y && on[3 * j + 2] == cn[c].z)
                    break;
            if (j == no) {
                memcpy(&op[3 * no], &pos[3 * v], 3 * sizeof(double));
                on[3 * no] = cn[c].x;
                on[3 * no + 1] = cn[c].y;
                on[3 * no + 2] = cn[c].z;
                no++;
            }
            out_of[c] = (uint32_t)j;
        }
    }
    for (size_t c = 0; c < nc; c++)
        idx[c] = out_of[c];
    *pos_out = op;
    *nrm_out = on;
    *nv_out = no;
    op = on = NULL;
    rc = 0;
done:
    free(fn);
    free(fu);
    free(start);
    free(fill);
    free(around);
    free(cn);
    free(out_of);
    free(op);
    free(on);
    return rc;
}
