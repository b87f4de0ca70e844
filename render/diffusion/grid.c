/* lamprig — the diffusion grid: nodes classified inside / ghost / outside (dgrid.h). */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "render/diffusion/dgrid.h"
#include "render/diffusion/dgrid_internal.h"

/* Ghost band half-width in h: every trilinear cell that touches the surface has its corners
 * within sqrt(3) h of it, so all of them are unknowns (dgrid.h). */
#define LR_DGRID_BAND 1.75

void lr_dgrid_destroy(lr_dgrid *g)
{
    if (!g)
        return;
    free(g->kind);
    free(g->unknown);
    free(g->param);
    free(g->unknown_node);
    free(g->param_node);
    free(g->ghost_node);
    free(g->ghost_b);
    free(g->ghost_n);
    free(g->ghost_t);
    free(g->band_node);
    free(g->band_b);
    free(g->band_n);
    free(g);
}

static size_t node_index(const lr_dgrid *g, int i, int j, int k)
{
    return ((size_t)k * (size_t)g->n[1] + (size_t)j) * (size_t)g->n[0] + (size_t)i;
}

static void node_ijk(const lr_dgrid *g, size_t node, int ijk[3])
{
    ijk[0] = (int)(node % (size_t)g->n[0]);
    ijk[1] = (int)((node / (size_t)g->n[0]) % (size_t)g->n[1]);
    ijk[2] = (int)(node / ((size_t)g->n[0] * (size_t)g->n[1]));
}

lr_vec3 lr_dgrid_node_pos(const lr_dgrid *g, size_t node)
{
    int ijk[3];
    node_ijk(g, node, ijk);
    return lr_v3(g->origin.x + g->h * ijk[0], g->origin.y + g->h * ijk[1],
                 g->origin.z + g->h * ijk[2]);
}

/* The owner of a ghost: the inside node nearest to its surface point, searched in the 5^3
 * block around it (the ghost band is 1.75 h wide, so one is always that close for a surface
 * with inside nodes on its side; a sliver thinner than the grid has none and returns -1). */
static long nearest_inside(const lr_dgrid *g, lr_vec3 b)
{
    int c[3] = {(int)lround((b.x - g->origin.x) / g->h), (int)lround((b.y - g->origin.y) / g->h),
                (int)lround((b.z - g->origin.z) / g->h)};
    long best = -1;
    double best_d = DBL_MAX;
    for (int dk = -2; dk <= 2; dk++)
        for (int dj = -2; dj <= 2; dj++)
            for (int di = -2; di <= 2; di++) {
                int i = c[0] + di, j = c[1] + dj, k = c[2] + dk;
                if (i < 0 || j < 0 || k < 0 || i >= g->n[0] || j >= g->n[1] || k >= g->n[2])
                    continue;
                size_t node = node_index(g, i, j, k);
                if (g->kind[node] != LR_DNODE_IN)
                    continue;
                double d = lr_v3_len(lr_v3_sub(lr_dgrid_node_pos(g, node), b));
                if (d < best_d) {
                    best_d = d;
                    best = (long)node;
                }
            }
    return best;
}

int lr_dgrid_create_box(const lr_dshape *s, lr_vec3 origin, double h, const int n[3],
                        lr_dgrid **out, lr_err *e)
{
    *out = NULL;
    if (!s || !s->inside || !s->closest)
        return lr_err_set(e, LR_EINVAL, "diffusion grid: no shape");
    if (!isfinite(h) || !(h > 0.0))
        return lr_err_set(e, LR_EINVAL, "diffusion grid: h = %g: must be finite and > 0", h);
    if (!lr_v3_isfinite(origin))
        return lr_err_set(e, LR_EINVAL, "diffusion grid: origin not finite");
    double total = 1.0;
    for (int a = 0; a < 3; a++) {
        if (n[a] < 1)
            return lr_err_set(e, LR_EINVAL, "diffusion grid: dims[%d] = %d: must be >= 1", a, n[a]);
        total *= n[a];
    }
    if (total > LR_DGRID_MAX_NODES)
        return lr_err_set(e, LR_EINVAL,
                          "diffusion grid: h = %g mm gives %.0f nodes (at most %u): raise h", h,
                          total, LR_DGRID_MAX_NODES);
    lr_dgrid *g = calloc(1, sizeof *g);
    if (!g)
        return lr_err_set(e, LR_ENOMEM, "diffusion grid: out of memory");
    g->h = h;
    g->origin = origin;
    for (int a = 0; a < 3; a++)
        g->n[a] = n[a];
    size_t N = (size_t)total;
    g->count = N;
    g->kind = calloc(N, 1);
    g->unknown = malloc(N * sizeof *g->unknown);
    g->param = malloc(N * sizeof *g->param);
    bool *in_band = calloc(N, sizeof *in_band);
    lr_vec3 *bb = malloc(N * sizeof *bb), *bn = malloc(N * sizeof *bn);
    if (!g->kind || !g->unknown || !g->param || !in_band || !bb || !bn) {
        free(in_band), free(bb), free(bn);
        lr_dgrid_destroy(g);
        return lr_err_set(e, LR_ENOMEM, "diffusion grid: out of memory (%zu nodes)", N);
    }
    /* Inside: one vertical cast per column when the shape offers it (parity of the crossings
     * below each node), else the shape's own test per node. */
    if (s->column) {
        double z[256];
        for (int j = 0; j < n[1]; j++)
            for (int i = 0; i < n[0]; i++) {
                int m = s->column(s->ctx, origin.x + h * i, origin.y + h * j, z, 256);
                int below = 0;
                for (int k = 0; k < n[2]; k++) {
                    double zk = origin.z + h * k;
                    while (below < m && z[below] < zk)
                        below++;
                    g->kind[node_index(g, i, j, k)] = (m < 256 && (below & 1)) ? 1 : 0;
                }
            }
    }
    else
        for (size_t node = 0; node < N; node++)
            g->kind[node] = s->inside(s->ctx, lr_dgrid_node_pos(g, node)) ? 1 : 0;
    /* Closest points only near the surface: a node within 1.75 h of a (locally flat) surface
     * has a node of the other side within 3 steps along each axis (3 h (|nx|+|ny|+|nz|) >= 3 h
     * across it), so nodes whose 7^3 block is all one side are skipped. Max and min filters,
     * one axis at a time. */
    uint8_t *mx = malloc(N), *mn = malloc(N), *tmp = malloc(N);
    if (!mx || !mn || !tmp) {
        free(mx), free(mn), free(tmp), free(in_band), free(bb), free(bn);
        lr_dgrid_destroy(g);
        return lr_err_set(e, LR_ENOMEM, "diffusion grid: out of memory (%zu nodes)", N);
    }
    memcpy(mx, g->kind, N);
    memcpy(mn, g->kind, N);
    size_t stride[3] = {1, (size_t)n[0], (size_t)n[0] * (size_t)n[1]};
    for (int a = 0; a < 3; a++)
        for (int pass = 0; pass < 2; pass++) {
            uint8_t *f = pass ? mn : mx;
            memcpy(tmp, f, N);
            for (size_t node = 0; node < N; node++) {
                int c = (int)((node / stride[a]) % (size_t)n[a]);
                uint8_t v = f[node];
                for (int d = -3; d <= 3; d++) {
                    if (c + d < 0 || c + d >= n[a])
                        continue;
                    uint8_t w = f[(size_t)((long)node + d * (long)stride[a])];
                    v = pass ? (w < v ? w : v) : (w > v ? w : v);
                }
                tmp[node] = v;
            }
            memcpy(f, tmp, N);
        }
    size_t n_in = 0, n_ghost = 0, n_band = 0;
    for (size_t node = 0; node < N; node++) {
        lr_vec3 p = lr_dgrid_node_pos(g, node);
        bool inside = g->kind[node] == 1;
        lr_vec3 b, nf;
        if (mx[node] != mn[node] && s->closest(s->ctx, p, LR_DGRID_BAND * h, &b, &nf)) {
            lr_vec3 d = lr_v3_sub(p, b);
            double l = lr_v3_len(d);
            in_band[node] = true;
            bb[node] = b;
            /* Off the surface the closest point's normal direction is exact; on it (or within
             * rounding) the face normal. */
            bn[node] = l > 1e-9 * h ? lr_v3_scale(d, (inside ? -1.0 : 1.0) / l) : nf;
            n_band++;
        }
        g->kind[node] = inside ? LR_DNODE_IN : (in_band[node] ? LR_DNODE_GHOST : LR_DNODE_OUT);
        if (inside)
            n_in++;
        else if (in_band[node])
            n_ghost++;
    }
    free(mx), free(mn), free(tmp);
    if (n_in == 0) {
        free(in_band), free(bb), free(bn);
        lr_dgrid_destroy(g);
        return lr_err_set(e, LR_EINVAL,
                          "diffusion grid: h = %g mm: no grid node inside the object (lower h)", h);
    }
    g->n_in = n_in;
    g->n_ghost = n_ghost;
    g->n_unknown = n_in + n_ghost;
    g->n_band = n_band;
    g->unknown_node = malloc(g->n_unknown * sizeof *g->unknown_node);
    g->param_node = malloc(n_in * sizeof *g->param_node);
    g->ghost_node = malloc((n_ghost ? n_ghost : 1) * sizeof *g->ghost_node);
    g->ghost_b = malloc((n_ghost ? n_ghost : 1) * sizeof *g->ghost_b);
    g->ghost_n = malloc((n_ghost ? n_ghost : 1) * sizeof *g->ghost_n);
    g->ghost_t = malloc((n_ghost ? n_ghost : 1) * sizeof *g->ghost_t);
    g->band_node = malloc((n_band ? n_band : 1) * sizeof *g->band_node);
    g->band_b = malloc((n_band ? n_band : 1) * sizeof *g->band_b);
    g->band_n = malloc((n_band ? n_band : 1) * sizeof *g->band_n);
    if (!g->unknown_node || !g->param_node || !g->ghost_node || !g->ghost_b || !g->ghost_n ||
        !g->ghost_t || !g->band_node || !g->band_b || !g->band_n) {
        free(in_band), free(bb), free(bn);
        lr_dgrid_destroy(g);
        return lr_err_set(e, LR_ENOMEM, "diffusion grid: out of memory");
    }
    /* Unknowns: inside nodes first (their unknown index is their parameter index), then ghosts. */
    size_t u = 0, gi = 0, bi = 0;
    for (size_t node = 0; node < N; node++) {
        g->unknown[node] = -1;
        g->param[node] = -1;
        if (g->kind[node] == LR_DNODE_IN) {
            g->param[node] = (long)u;
            g->param_node[u] = node;
            g->unknown_node[u] = node;
            g->unknown[node] = (long)u++;
        }
    }
    for (size_t node = 0; node < N; node++) {
        if (in_band[node]) {
            g->band_node[bi] = node;
            g->band_b[bi] = bb[node];
            g->band_n[bi++] = bn[node];
        }
        if (g->kind[node] != LR_DNODE_GHOST)
            continue;
        g->unknown_node[u] = node;
        g->unknown[node] = (long)u++;
        g->ghost_node[gi] = node;
        g->ghost_b[gi] = bb[node];
        g->ghost_n[gi] = bn[node];
        g->ghost_t[gi] = lr_v3_len(lr_v3_sub(lr_dgrid_node_pos(g, node), bb[node]));
        long own = nearest_inside(g, bb[node]);
        g->param[node] = own >= 0 ? g->param[own] : -1;
        gi++;
    }
    free(in_band), free(bb), free(bn);
    *out = g;
    return LR_OK;
}

int lr_dgrid_create(const lr_dshape *s, double h, lr_dgrid **out, lr_err *e)
{
    *out = NULL;
    if (!s)
        return lr_err_set(e, LR_EINVAL, "diffusion grid: no shape");
    if (!isfinite(h) || !(h > 0.0))
        return lr_err_set(e, LR_EINVAL, "diffusion grid: h = %g: must be finite and > 0", h);
    const int margin = 3;
    double lo[3] = {s->lo.x, s->lo.y, s->lo.z}, hi[3] = {s->hi.x, s->hi.y, s->hi.z};
    int n[3];
    double o[3];
    for (int a = 0; a < 3; a++) {
        double span = hi[a] - lo[a];
        if (!isfinite(span) || span < 0.0)
            return lr_err_set(e, LR_EINVAL, "diffusion grid: shape bounds not finite");
        double cells = ceil(span / h);
        if (cells > 4096.0)
            return lr_err_set(e, LR_EINVAL, "diffusion grid: h = %g mm: %.0f cells across (raise h)",
                              h, cells);
        n[a] = (int)cells + 1 + 2 * margin;
        /* Centre the nodes on the object. */
        o[a] = 0.5 * (lo[a] + hi[a]) - 0.5 * h * (n[a] - 1);
    }
    return lr_dgrid_create_box(s, lr_v3(o[0], o[1], o[2]), h, n, out, e);
}

double lr_dgrid_h(const lr_dgrid *g) { return g->h; }
void lr_dgrid_dims(const lr_dgrid *g, int n[3])
{
    for (int a = 0; a < 3; a++)
        n[a] = g->n[a];
}
lr_vec3 lr_dgrid_origin(const lr_dgrid *g) { return g->origin; }
size_t lr_dgrid_node_count(const lr_dgrid *g) { return g->count; }
size_t lr_dgrid_inside_count(const lr_dgrid *g) { return g->n_in; }
size_t lr_dgrid_unknown_count(const lr_dgrid *g) { return g->n_unknown; }
size_t lr_dgrid_ghost_count(const lr_dgrid *g) { return g->n_ghost; }
enum lr_dnode_kind lr_dgrid_kind(const lr_dgrid *g, size_t node)
{
    return (enum lr_dnode_kind)g->kind[node];
}
long lr_dgrid_unknown(const lr_dgrid *g, size_t node) { return g->unknown[node]; }
size_t lr_dgrid_unknown_node(const lr_dgrid *g, size_t u) { return g->unknown_node[u]; }
long lr_dgrid_param(const lr_dgrid *g, size_t node) { return g->param[node]; }
lr_vec3 lr_dgrid_param_pos(const lr_dgrid *g, size_t p)
{
    return lr_dgrid_node_pos(g, g->param_node[p]);
}

bool lr_dgrid_ghost(const lr_dgrid *g, size_t node, lr_vec3 *b, lr_vec3 *n, double *t)
{
    if (g->kind[node] != LR_DNODE_GHOST)
        return false;
    size_t k = (size_t)g->unknown[node] - g->n_in;
    *b = g->ghost_b[k];
    *n = g->ghost_n[k];
    *t = g->ghost_t[k];
    return true;
}

void lr_dgrid_ghost_at(const lr_dgrid *g, size_t k, lr_vec3 *b, lr_vec3 *n, size_t *unknown)
{
    *b = g->ghost_b[k];
    *n = g->ghost_n[k];
    *unknown = g->n_in + k;
}

/* Corner indices and weights along one axis; a one-node axis has both corners at 0. */
static void axis_weights(double f, int n, int c[2], double w[2])
{
    if (n == 1) {
        c[0] = c[1] = 0;
        w[0] = 1.0, w[1] = 0.0;
        return;
    }
    double fl = floor(f);
    int i = (int)fmax(0.0, fmin((double)(n - 2), fl));
    double t = fmin(1.0, fmax(0.0, f - i));
    c[0] = i, c[1] = i + 1;
    w[0] = 1.0 - t, w[1] = t;
}

int lr_dgrid_corners(const lr_dgrid *g, lr_vec3 p, size_t node[8], double w[8])
{
    double f[3] = {(p.x - g->origin.x) / g->h, (p.y - g->origin.y) / g->h,
                   (p.z - g->origin.z) / g->h};
    int c[3][2];
    double wa[3][2];
    for (int a = 0; a < 3; a++) {
        if (!isfinite(f[a]))
            return 0;
        axis_weights(f[a], g->n[a], c[a], wa[a]);
    }
    int m = 0;
    for (int k = 0; k < 2; k++)
        for (int j = 0; j < 2; j++)
            for (int i = 0; i < 2; i++) {
                node[m] = node_index(g, c[0][i], c[1][j], c[2][k]);
                w[m++] = wa[0][i] * wa[1][j] * wa[2][k];
            }
    return 8;
}

int lr_dgrid_trilinear(const lr_dgrid *g, lr_vec3 p, size_t idx[8], double w[8])
{
    size_t node[8];
    double wc[8];
    if (lr_dgrid_corners(g, p, node, wc) != 8)
        return 0;
    int m = 0;
    double sum = 0.0;
    for (int q = 0; q < 8; q++) {
        if (wc[q] <= 0.0 || g->unknown[node[q]] < 0)
            continue;
        idx[m] = (size_t)g->unknown[node[q]];
        w[m] = wc[q];
        sum += wc[q];
        m++;
    }
    if (!(sum > 0.0))
        return 0;
    for (int q = 0; q < m; q++)
        w[q] /= sum;
    return m;
}

int lr_dgrid_triquadratic(const lr_dgrid *g, lr_vec3 p, size_t idx[27], double w[27])
{
    double f[3] = {(p.x - g->origin.x) / g->h, (p.y - g->origin.y) / g->h,
                   (p.z - g->origin.z) / g->h};
    int c[3], m[3];
    double wa[3][3];
    for (int a = 0; a < 3; a++) {
        if (!isfinite(f[a]))
            return 0;
        if (g->n[a] == 1) {
            c[a] = 0, m[a] = 1, wa[a][0] = 1.0;
            continue;
        }
        if (g->n[a] < 3)
            return 0;
        c[a] = (int)fmax(1.0, fmin((double)(g->n[a] - 2), round(f[a]))) - 1;
        double x = f[a] - (c[a] + 1);
        if (fabs(x) > 1.0)
            return 0;
        m[a] = 3;
        wa[a][0] = 0.5 * x * (x - 1.0);
        wa[a][1] = (1.0 - x) * (1.0 + x);
        wa[a][2] = 0.5 * x * (x + 1.0);
    }
    int q = 0;
    for (int k = 0; k < m[2]; k++)
        for (int j = 0; j < m[1]; j++)
            for (int i = 0; i < m[0]; i++) {
                long u = g->unknown[node_index(g, c[0] + i, c[1] + j, c[2] + k)];
                if (u < 0)
                    return 0;
                idx[q] = (size_t)u;
                w[q++] = wa[0][i] * wa[1][j] * wa[2][k];
            }
    return q;
}

double lr_dgrid_sample(const lr_dgrid *g, const double *phi, lr_vec3 p)
{
    size_t idx[8];
    double w[8];
    int m = lr_dgrid_trilinear(g, p, idx, w);
    double v = 0.0;
    for (int q = 0; q < m; q++)
        v += w[q] * phi[idx[q]];
    return v;
}
