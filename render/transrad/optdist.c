/* lamprig — translucent radiosity: in-object (optical) distances between the patches of one
 * object, so that the diffusion profile is indexed by how far light travels through the
 * material, never across air (seed 000 Sec. 4 indexes S by distance; a concave object, a shade's
 * two walls facing each other across its hollow, or a candle's rim across the melt pool would
 * otherwise exchange light through the gap).
 *
 * Each patch has an inner point p_i = c_i - delta n_i, delta below the wall's half thickness and
 * above a cluster's sagitta, so inner points lie in the material. Two patches whose segment
 * p_i p_j crosses no surface of the object are joined by material: their distance is the
 * Euclidean |c_i - c_j|. Otherwise light must go around: a graph joins each inner point to its
 * nearest (up to 16) neighbours it sees through material, Dijkstra gives the shortest in-material
 * path g_ij, and the distance is |c_i - c_j| + (g_ij - |p_i - p_j|), the detour added to the
 * straight distance. The nodes are the patches' inner points rather than voxels: the same
 * shortest path through the material at the patches' own resolution, without a voxel grid
 * fine enough for a 1.5 mm wall. */
#include "render/transrad/tr_priv.h"

#include <math.h>
#include <stdlib.h>

#include "render/base/parallel.h"

#define OD_NEIGHBOURS 16
#define OD_CANDIDATES 32

typedef struct od_ctx {
    const lr_tr *t;
    int s;
    size_t first, ns;
    lr_vec3 *pin;
    uint32_t *adj;  /* ns x OD_NEIGHBOURS, UINT32_MAX: none */
    double *adjw;
    double *out;    /* ns x ns */
    double cutoff;
    int failed;
} od_ctx;

static bool see(const od_ctx *c, size_t i, size_t j)
{
    lr_vec3 d = lr_v3_sub(c->pin[j], c->pin[i]);
    return !lr_bvh_occluded(c->t->surf[c->s].d.bvh, c->pin[i], d, 1e-9, 1.0);
}

static void neighbours_item(void *vctx, long item)
{
    od_ctx *c = vctx;
    size_t i = (size_t)item;
    size_t cand[OD_CANDIDATES];
    double cd[OD_CANDIDATES];
    int nc = 0;
    for (size_t j = 0; j < c->ns; j++) {
        if (j == i)
            continue;
        double d = lr_v3_len(lr_v3_sub(c->pin[j], c->pin[i]));
        if (nc < OD_CANDIDATES || d < cd[nc - 1]) {
            int k = nc < OD_CANDIDATES ? nc++ : nc - 1;
            while (k > 0 && cd[k - 1] > d) {
                cd[k] = cd[k - 1];
                cand[k] = cand[k - 1];
                k--;
            }
            cd[k] = d;
            cand[k] = j;
        }
    }
    int w = 0;
    for (int k = 0; k < nc && w < OD_NEIGHBOURS; k++)
        if (see(c, i, cand[k])) {
            c->adj[i * OD_NEIGHBOURS + (size_t)w] = (uint32_t)cand[k];
            c->adjw[i * OD_NEIGHBOURS + (size_t)w] = cd[k];
            w++;
        }
    for (; w < OD_NEIGHBOURS; w++)
        c->adj[i * OD_NEIGHBOURS + (size_t)w] = UINT32_MAX;
}

/* Binary heap of (distance, node). */
typedef struct heap {
    double *d;
    uint32_t *v;
    size_t n;
} heap;

static void heap_push(heap *h, double d, uint32_t v)
{
    size_t i = h->n++;
    while (i > 0) {
        size_t p = (i - 1) / 2;
        if (h->d[p] <= d)
            break;
        h->d[i] = h->d[p];
        h->v[i] = h->v[p];
        i = p;
    }
    h->d[i] = d;
    h->v[i] = v;
}

static void heap_pop(heap *h, double *d, uint32_t *v)
{
    *d = h->d[0];
    *v = h->v[0];
    double ld = h->d[--h->n];
    uint32_t lv = h->v[h->n];
    size_t i = 0;
    for (;;) {
        size_t l = 2 * i + 1, r = l + 1, m = i;
        double md = ld;
        if (l < h->n && h->d[l] < md) {
            m = l;
            md = h->d[l];
        }
        if (r < h->n && h->d[r] < md)
            m = r;
        if (m == i)
            break;
        h->d[i] = h->d[m];
        h->v[i] = h->v[m];
        i = m;
    }
    h->d[i] = ld;
    h->v[i] = lv;
}

static void dijkstra_item(void *vctx, long item)
{
    od_ctx *c = vctx;
    size_t src = (size_t)item, ns = c->ns;
    double *g = c->out + src * ns;
    size_t cap = ns * OD_NEIGHBOURS + 1;
    heap h = {malloc(cap * sizeof(double)), malloc(cap * sizeof(uint32_t)), 0};
    if (!h.d || !h.v) {
        c->failed = 1;
        free(h.d);
        free(h.v);
        return;
    }
    for (size_t j = 0; j < ns; j++)
        g[j] = INFINITY;
    g[src] = 0;
    heap_push(&h, 0, (uint32_t)src);
    while (h.n) {
        double d;
        uint32_t v;
        heap_pop(&h, &d, &v);
        if (d > g[v] || d > c->cutoff)
            continue;
        for (int k = 0; k < OD_NEIGHBOURS; k++) {
            uint32_t u = c->adj[(size_t)v * OD_NEIGHBOURS + (size_t)k];
            if (u == UINT32_MAX)
                break;
            double nd = d + c->adjw[(size_t)v * OD_NEIGHBOURS + (size_t)k];
            if (nd < g[u] && h.n < cap) {
                g[u] = nd;
                heap_push(&h, nd, u);
            }
        }
    }
    free(h.d);
    free(h.v);
    /* Graph detours to distances: straight where the material joins the two inner points. */
    const lr_tr_patch *P = c->t->p + c->first;
    for (size_t j = 0; j < ns; j++) {
        double straight = lr_v3_len(lr_v3_sub(P[j].c, P[src].c));
        if (j == src) {
            g[j] = 0;
            continue;
        }
        if (straight > c->cutoff) {
            g[j] = INFINITY;
            continue;
        }
        double pin = lr_v3_len(lr_v3_sub(c->pin[j], c->pin[src]));
        if (see(c, src, j))
            g[j] = straight;
        else if (isfinite(g[j]))
            g[j] = straight + fmax(0.0, g[j] - pin);
    }
}

int lr_tr_optical_distances(const lr_tr *t, int s, double **out, lr_err *e)
{
    const lr_tr_surf *sf = &t->surf[s];
    od_ctx c = {.t = t, .s = s, .first = sf->first, .ns = sf->count};
    const lr_coeffs *co = sf->d.coeffs;
    double mfp = INFINITY, str = INFINITY;
    for (int b = 0; b < 3; b++) {
        mfp = fmin(mfp, co->mfp[b]);
        str = fmin(str, co->sigma_tr[b]);
    }
    double h = sf->d.patch_mm > 0 ? sf->d.patch_mm : t->set.patch_mm;
    double delta = fmax(mfp, 0.05 * h);
    if (sf->d.thickness_mm > 0)
        delta = fmin(delta, 0.4 * sf->d.thickness_mm);
    /* Beyond 14 diffusion lengths the profile is below e^-14 of its peak: not connected. */
    c.cutoff = str > 0 ? 14.0 / str : INFINITY;
    size_t ns = c.ns;
    c.pin = malloc((ns ? ns : 1) * sizeof *c.pin);
    c.adj = malloc((ns ? ns : 1) * OD_NEIGHBOURS * sizeof *c.adj);
    c.adjw = malloc((ns ? ns : 1) * OD_NEIGHBOURS * sizeof *c.adjw);
    c.out = malloc((ns ? ns * ns : 1) * sizeof *c.out);
    if (!c.pin || !c.adj || !c.adjw || !c.out) {
        free(c.pin);
        free(c.adj);
        free(c.adjw);
        free(c.out);
        return lr_err_set(e, LR_ENOMEM, "transrad: surface %d: out of memory (%zu^2 distances)",
                          s, ns);
    }
    for (size_t i = 0; i < ns; i++)
        c.pin[i] = lr_v3_sub(t->p[c.first + i].c, lr_v3_scale(t->p[c.first + i].n, delta));
    lr_parallel_for((long)ns, t->set.threads, neighbours_item, &c);
    lr_parallel_for((long)ns, t->set.threads, dijkstra_item, &c);
    free(c.pin);
    free(c.adj);
    free(c.adjw);
    if (c.failed) {
        free(c.out);
        return lr_err_set(e, LR_ENOMEM, "transrad: surface %d: out of memory (Dijkstra)", s);
    }
    *out = c.out;
    return LR_OK;
}
