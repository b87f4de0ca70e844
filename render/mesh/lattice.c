/* Lattice refinement (render/mesh/lattice.h). */
#include "render/mesh/lattice.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Vertex (i, j) of a lattice of resolution R, counted from the triangle's first. */
static size_t lat_vertex(size_t R, size_t i, size_t j)
{
    return j * (2 * R + 3 - j) / 2 + i; /* rows 0..j-1 hold R + 1, R, ... points */
}

/* Sub-triangle (i, j, upper) of a lattice of resolution R, counted from the triangle's first. */
static size_t lat_tri(size_t R, size_t i, size_t j, int upper)
{
    return 2 * R * j - j * j + 2 * i + (size_t)upper;
}

static double longest_edge(const float *p, const uint32_t *ix)
{
    double L2 = 0.0;
    for (int k = 0; k < 3; k++) {
        const float *a = p + 3 * ix[k], *b = p + 3 * ix[(k + 1) % 3];
        double s = 0.0;
        for (int c = 0; c < 3; c++)
            s += ((double)a[c] - b[c]) * ((double)a[c] - b[c]);
        L2 = s > L2 ? s : L2;
    }
    return sqrt(L2);
}

int lr_refine_lattice(const lr_mesh *m, double h, size_t max_vertices, lr_refined *out,
                      lr_err *e)
{
    memset(out, 0, sizeof *out);
    if (!(h > 0.0) || !isfinite(h))
        return lr_err_set(e, LR_EINVAL, "mesh %s: lattice edge bound %g: must be > 0",
                          lr_mesh_name(m), h);
    size_t nt = lr_mesh_triangle_count(m);
    const float *P = lr_mesh_positions(m), *N = lr_mesh_normals(m);
    const uint32_t *ix = lr_mesh_indices(m);
    lr_refined r = {.n_parents = nt};
    r.lat_R = malloc((nt ? nt : 1) * sizeof *r.lat_R);
    r.lat_base = malloc((nt ? nt : 1) * sizeof *r.lat_base);
    r.first = calloc(nt + 1, sizeof *r.first);
    if (!r.lat_R || !r.lat_base || !r.first) {
        lr_refined_free(&r);
        return lr_err_set(e, LR_ENOMEM, "mesh lattice: out of memory");
    }
    size_t nv = 0, ntr = 0;
    for (size_t t = 0; t < nt; t++) {
        double R = ceil(longest_edge(P, ix + 3 * t) / h);
        R = R < 1.0 ? 1.0 : R;
        size_t verts = (size_t)((R + 1.0) * (R + 2.0) / 2.0);
        if (R > 65535.0 || (max_vertices && nv + verts > max_vertices) ||
            nv + verts >= UINT32_MAX) {
            lr_refined_free(&r);
            return lr_err_set(e, LR_EUNSUPPORTED,
                              "mesh %s: lattice of edges %.3g mm would exceed %zu vertices",
                              lr_mesh_name(m), h, max_vertices ? max_vertices : (size_t)UINT32_MAX);
        }
        r.lat_R[t] = (uint32_t)R;
        r.lat_base[t] = (uint32_t)nv;
        nv += verts;
        ntr += (size_t)R * (size_t)R;
        r.first[t + 1] = ntr;
    }
    r.nv = nv;
    r.nt = ntr;
    r.pos = malloc((nv ? nv : 1) * 3 * sizeof *r.pos);
    r.nrm = malloc((nv ? nv : 1) * 3 * sizeof *r.nrm);
    r.idx = malloc((ntr ? ntr : 1) * 3 * sizeof *r.idx);
    r.parent = malloc((ntr ? ntr : 1) * sizeof *r.parent);
    r.uv = malloc((ntr ? ntr : 1) * 6 * sizeof *r.uv);
    if (!r.pos || !r.nrm || !r.idx || !r.parent || !r.uv) {
        lr_refined_free(&r);
        return lr_err_set(e, LR_ENOMEM, "mesh lattice: out of memory");
    }
    for (size_t t = 0; t < nt; t++) {
        size_t R = r.lat_R[t], base = r.lat_base[t];
        const uint32_t *c = ix + 3 * t;
        for (size_t j = 0; j <= R; j++)
            for (size_t i = 0; i + j <= R; i++) {
                /* The parent's linear interpolation at (u, v) = (i, j) / R. */
                double u = (double)i / (double)R, v = (double)j / (double)R, w0 = 1.0 - u - v;
                size_t k = base + lat_vertex(R, i, j);
                for (int a = 0; a < 3; a++) {
                    r.pos[3 * k + a] = (float)(w0 * P[3 * c[0] + a] + u * P[3 * c[1] + a] +
                                               v * P[3 * c[2] + a]);
                    r.nrm[3 * k + a] = (float)(w0 * N[3 * c[0] + a] + u * N[3 * c[1] + a] +
                                               v * N[3 * c[2] + a]);
                }
            }
        for (size_t j = 0; j < R; j++)
            for (size_t i = 0; i + j < R; i++)
                for (int up = 0; up < 2 && (up == 0 || i + j + 2 <= R); up++) {
                    size_t q = r.first[t] + lat_tri(R, i, j, up);
                    /* Corners as (i, j) offsets: lower (0,0) (1,0) (0,1),
                     * upper (1,0) (1,1) (0,1). */
                    static const int off[2][3][2] = {{{0, 0}, {1, 0}, {0, 1}},
                                                     {{1, 0}, {1, 1}, {0, 1}}};
                    for (int a = 0; a < 3; a++) {
                        size_t ci = i + (size_t)off[up][a][0], cj = j + (size_t)off[up][a][1];
                        r.idx[3 * q + a] = (uint32_t)(base + lat_vertex(R, ci, cj));
                        r.uv[6 * q + 2 * a] = (float)((double)ci / (double)R);
                        r.uv[6 * q + 2 * a + 1] = (float)((double)cj / (double)R);
                    }
                    r.parent[q] = (uint32_t)t;
                }
    }
    *out = r;
    return LR_OK;
}

size_t lr_lattice_locate(const lr_refined *r, size_t t, double u, double v, double w[3])
{
    double R = (double)r->lat_R[t];
    double x = u * R, y = v * R;
    /* Cell (i, j) with i, j >= 0 and i + j <= R - 1; the fractions clamped into it. */
    double i = floor(x), j = floor(y);
    i = i < 0.0 ? 0.0 : (i > R - 1.0 ? R - 1.0 : i);
    j = j < 0.0 ? 0.0 : (j > R - 1.0 - i ? R - 1.0 - i : j);
    double fx = x - i, fy = y - j;
    int upper = fx + fy > 1.0 && i + j <= R - 2.0;
    if (upper) { /* corners (i+1, j), (i+1, j+1), (i, j+1) */
        w[0] = 1.0 - fy;
        w[1] = fx + fy - 1.0;
        w[2] = 1.0 - fx;
    } else { /* corners (i, j), (i+1, j), (i, j+1) */
        w[0] = 1.0 - fx - fy;
        w[1] = fx;
        w[2] = fy;
    }
    return r->first[t] + lat_tri((size_t)R, (size_t)i, (size_t)j, upper);
}
