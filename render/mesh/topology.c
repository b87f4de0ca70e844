/* Welding by position and edge topology: the facts every mesh check is built from. */
#include "render/mesh/mesh_internal.h"

#include <stdlib.h>
#include <string.h>

typedef struct weld_key {
    float x, y, z;
    uint32_t v;
} weld_key;

static int cmp_key(const void *pa, const void *pb)
{
    const weld_key *a = pa, *b = pb;
    if (a->x != b->x)
        return a->x < b->x ? -1 : 1;
    if (a->y != b->y)
        return a->y < b->y ? -1 : 1;
    if (a->z != b->z)
        return a->z < b->z ? -1 : 1;
    return (a->v > b->v) - (a->v < b->v);
}

uint32_t *lr_mesh_weld(const float *pos, size_t nv, size_t *classes)
{
    weld_key *k = malloc((nv ? nv : 1) * sizeof *k);
    uint32_t *w = malloc((nv ? nv : 1) * sizeof *w);
    if (!k || !w) {
        free(k);
        free(w);
        return NULL;
    }
    for (size_t v = 0; v < nv; v++)
        k[v] = (weld_key){pos[3 * v], pos[3 * v + 1], pos[3 * v + 2], (uint32_t)v};
    qsort(k, nv, sizeof *k, cmp_key);
    size_t c = 0;
    for (size_t i = 0; i < nv; i++) {
        if (i > 0 && !(k[i].x == k[i - 1].x && k[i].y == k[i - 1].y && k[i].z == k[i - 1].z))
            c++;
        w[k[i].v] = (uint32_t)c;
    }
    *classes = nv ? c + 1 : 0;
    free(k);
    return w;
}

static int cmp_edge(const void *pa, const void *pb)
{
    const lr_mesh_edge *a = pa, *b = pb;
    if (a->a != b->a)
        return a->a < b->a ? -1 : 1;
    if (a->b != b->b)
        return a->b < b->b ? -1 : 1;
    return (a->t > b->t) - (a->t < b->t);
}

static uint32_t uf_find(uint32_t *p, uint32_t x)
{
    while (p[x] != x) {
        p[x] = p[p[x]];
        x = p[x];
    }
    return x;
}

static void uf_union(uint32_t *p, uint32_t a, uint32_t b)
{
    a = uf_find(p, a);
    b = uf_find(p, b);
    if (a != b)
        p[a < b ? b : a] = a < b ? a : b;
}

int lr_mesh_topology(const uint32_t *weld, size_t nclasses, const uint32_t *idx, size_t nt,
                     lr_mesh_report *out, lr_mesh_edge **edges_out)
{
    size_t ne = 3 * nt;
    lr_mesh_edge *ed = malloc((ne ? ne : 1) * sizeof *ed);
    uint32_t *vset = malloc((nclasses ? nclasses : 1) * sizeof *vset);
    uint32_t *tset = malloc((nt ? nt : 1) * sizeof *tset);
    uint8_t *on_boundary = calloc(nclasses ? nclasses : 1, 1);
    if (!ed || !vset || !tset || !on_boundary) {
        free(ed);
        free(vset);
        free(tset);
        free(on_boundary);
        return -1;
    }
    for (size_t t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++) {
            uint32_t a = weld[idx[3 * t + k]], b = weld[idx[3 * t + (k + 1) % 3]];
            ed[3 * t + k] = (lr_mesh_edge){a < b ? a : b, a < b ? b : a, (uint32_t)t, a < b};
        }
    qsort(ed, ne, sizeof *ed, cmp_edge);
    for (size_t c = 0; c < nclasses; c++)
        vset[c] = (uint32_t)c;
    for (size_t t = 0; t < nt; t++)
        tset[t] = (uint32_t)t;

    size_t boundary = 0, nonmanifold = 0, inconsistent = 0;
    for (size_t i = 0; i < ne;) {
        size_t j = i + 1;
        while (j < ne && ed[j].a == ed[i].a && ed[j].b == ed[i].b)
            j++;
        size_t n = j - i;
        for (size_t k = i + 1; k < j; k++)
            uf_union(tset, ed[i].t, ed[k].t);
        if (n == 1) {
            boundary++;
            uf_union(vset, ed[i].a, ed[i].b);
            on_boundary[ed[i].a] = on_boundary[ed[i].b] = 1;
        } else if (n == 2) {
            if (ed[i].forward == ed[i + 1].forward)
                inconsistent++;
        } else {
            nonmanifold++;
        }
        i = j;
    }
    size_t loops = 0, components = 0;
    for (size_t c = 0; c < nclasses; c++)
        if (on_boundary[c] && uf_find(vset, (uint32_t)c) == c)
            loops++;
    for (size_t t = 0; t < nt; t++)
        if (uf_find(tset, (uint32_t)t) == t)
            components++;
    out->boundary_edges = boundary;
    out->boundary_loops = loops;
    out->nonmanifold_edges = nonmanifold;
    out->inconsistent_edges = inconsistent;
    out->components = components;
    out->closed = boundary == 0 && nonmanifold == 0;
    out->oriented = inconsistent == 0;
    free(vset);
    free(tset);
    free(on_boundary);
    if (edges_out)
        *edges_out = ed;
    else
        free(ed);
    return 0;
}
