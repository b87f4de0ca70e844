/* Conforming midpoint refinement of a triangle mesh (render/mesh/refine.h). */
#include "render/mesh/refine.h"
#include "render/mesh/lattice.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

typedef struct tri {
    uint32_t v[3];
    uint32_t parent;
    float uv[3][2];
} tri;

typedef struct build {
    float *pos, *nrm;
    size_t nv, cap_v;
    tri *t;
    size_t nt, cap_t;
    /* Edge (lo, hi) -> midpoint vertex + 1 (0: empty slot); open addressing. */
    uint64_t *key;
    uint32_t *mid;
    size_t slots;
} build;

static uint64_t edge_key(uint32_t a, uint32_t b)
{
    return a < b ? ((uint64_t)a << 32 | b) : ((uint64_t)b << 32 | a);
}

static size_t slot_of(const build *b, uint64_t k)
{
    uint64_t h = k * 0x9E3779B97F4A7C15ull;
    size_t i = (size_t)(h >> 17) & (b->slots - 1);
    while (b->key[i] && b->key[i] != k + 1)
        i = (i + 1) & (b->slots - 1);
    return i;
}

/* The midpoint of edge (a, b), made if new; UINT32_MAX when out of memory. */
static uint32_t midpoint(build *b, uint32_t a, uint32_t c)
{
    uint64_t k = edge_key(a, c);
    size_t i = slot_of(b, k);
    if (b->key[i])
        return b->mid[i];
    if (b->nv == b->cap_v) {
        size_t cap = b->cap_v * 2;
        float *p = realloc(b->pos, cap * 3 * sizeof *p);
        if (p)
            b->pos = p;
        float *n = p ? realloc(b->nrm, cap * 3 * sizeof *n) : NULL;
        if (!n)
            return UINT32_MAX;
        b->nrm = n;
        b->cap_v = cap;
    }
    uint32_t m = (uint32_t)b->nv++;
    for (int j = 0; j < 3; j++) {
        b->pos[3 * m + j] = (float)(0.5 * ((double)b->pos[3 * a + j] + b->pos[3 * c + j]));
        b->nrm[3 * m + j] = (float)(0.5 * ((double)b->nrm[3 * a + j] + b->nrm[3 * c + j]));
    }
    b->key[i] = k + 1;
    b->mid[i] = m;
    return m;
}

static uint32_t find_mid(const build *b, uint32_t a, uint32_t c)
{
    size_t i = slot_of(b, edge_key(a, c));
    return b->key[i] ? b->mid[i] : UINT32_MAX;
}

static double edge_len2(const build *b, uint32_t a, uint32_t c)
{
    double s = 0.0;
    for (int j = 0; j < 3; j++) {
        double d = (double)b->pos[3 * a + j] - b->pos[3 * c + j];
        s += d * d;
    }
    return s;
}

static int push(build *b, tri *out, size_t *n, const tri *parent, const uint32_t v[3],
                const float uv[3][2])
{
    (void)b;
    tri t = {.v = {v[0], v[1], v[2]}, .parent = parent->parent};
    memcpy(t.uv, uv, sizeof t.uv);
    out[(*n)++] = t;
    return 0;
}

/* Splits t by the midpoints m[i] of its edges (v[i], v[i+1]) (UINT32_MAX: not split) into
 * out, keeping the winding. */
static void split(build *b, const tri *t, const uint32_t m[3], tri *out, size_t *n)
{
    int cnt = (m[0] != UINT32_MAX) + (m[1] != UINT32_MAX) + (m[2] != UINT32_MAX);
    if (cnt == 0) {
        out[(*n)++] = *t;
        return;
    }
    /* Rotate so that edge 0 is split and, with two splits, edge 2 is the unsplit one. */
    int r = 0;
    for (int i = 0; i < 3; i++) {
        bool s0 = m[i] != UINT32_MAX, s1 = m[(i + 1) % 3] != UINT32_MAX,
             s2 = m[(i + 2) % 3] != UINT32_MAX;
        if (cnt == 1 && s0)
            r = i;
        if (cnt == 2 && s0 && s1 && !s2)
            r = i;
    }
    uint32_t a = t->v[r], bb = t->v[(r + 1) % 3], c = t->v[(r + 2) % 3];
    uint32_t m0 = m[r], m1 = m[(r + 1) % 3], m2 = m[(r + 2) % 3];
    float ua[2], ub[2], uc[2], u0[2], u1[2], u2[2];
    memcpy(ua, t->uv[r], sizeof ua);
    memcpy(ub, t->uv[(r + 1) % 3], sizeof ub);
    memcpy(uc, t->uv[(r + 2) % 3], sizeof uc);
    for (int j = 0; j < 2; j++) {
        u0[j] = 0.5f * (ua[j] + ub[j]);
        u1[j] = 0.5f * (ub[j] + uc[j]);
        u2[j] = 0.5f * (uc[j] + ua[j]);
    }
#define EMIT(A, B, C, UA, UB, UC)                                                          \
    do {                                                                                   \
        uint32_t v_[3] = {A, B, C};                                                        \
        float uv_[3][2] = {{UA[0], UA[1]}, {UB[0], UB[1]}, {UC[0], UC[1]}};                \
        push(b, out, n, t, v_, (const float(*)[2])uv_);                                   \
    } while (0)
    if (cnt == 1) {
        EMIT(a, m0, c, ua, u0, uc);
        EMIT(m0, bb, c, u0, ub, uc);
    } else if (cnt == 2) {
        EMIT(m0, bb, m1, u0, ub, u1);
        EMIT(a, m0, m1, ua, u0, u1);
        EMIT(a, m1, c, ua, u1, uc);
    } else {
        EMIT(a, m0, m2, ua, u0, u2);
        EMIT(m0, bb, m1, u0, ub, u1);
        EMIT(m2, m1, c, u2, u1, uc);
        EMIT(m0, m1, m2, u0, u1, u2);
    }
#undef EMIT
}

static void build_free(build *b)
{
    free(b->pos);
    free(b->nrm);
    free(b->t);
    free(b->key);
    free(b->mid);
}

void lr_refined_free(lr_refined *r)
{
    if (!r)
        return;
    free(r->pos);
    free(r->nrm);
    free(r->idx);
    free(r->parent);
    free(r->uv);
    free(r->first);
    free(r->lat_R);
    free(r->lat_base);
    memset(r, 0, sizeof *r);
}

/* The refined triangles grouped by parent (counting sort), into out. */
static int finish(build *b, size_t n_parents, lr_refined *out, lr_err *e)
{
    lr_refined r = {.nv = b->nv, .nt = b->nt, .n_parents = n_parents};
    r.idx = malloc(b->nt * 3 * sizeof *r.idx);
    r.parent = malloc(b->nt * sizeof *r.parent);
    r.uv = malloc(b->nt * 6 * sizeof *r.uv);
    r.first = calloc(n_parents + 1, sizeof *r.first);
    if (!r.idx || !r.parent || !r.uv || !r.first) {
        lr_refined_free(&r);
        return lr_err_set(e, LR_ENOMEM, "mesh refinement: out of memory");
    }
    for (size_t i = 0; i < b->nt; i++)
        r.first[b->t[i].parent + 1]++;
    for (size_t p = 0; p < n_parents; p++)
        r.first[p + 1] += r.first[p];
    size_t *at = malloc((n_parents + 1) * sizeof *at);
    if (!at) {
        lr_refined_free(&r);
        return lr_err_set(e, LR_ENOMEM, "mesh refinement: out of memory");
    }
    memcpy(at, r.first, (n_parents + 1) * sizeof *at);
    for (size_t i = 0; i < b->nt; i++) {
        const tri *t = &b->t[i];
        size_t k = at[t->parent]++;
        for (int j = 0; j < 3; j++) {
            r.idx[3 * k + j] = t->v[j];
            r.uv[6 * k + 2 * j] = t->uv[j][0];
            r.uv[6 * k + 2 * j + 1] = t->uv[j][1];
        }
        r.parent[k] = t->parent;
    }
    free(at);
    r.pos = b->pos;
    r.nrm = b->nrm;
    b->pos = b->nrm = NULL;
    *out = r;
    return LR_OK;
}

int lr_refine(const lr_mesh *m, double h, size_t max_vertices, lr_refined *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    if (!(h > 0.0) || !isfinite(h))
        return lr_err_set(e, LR_EINVAL, "mesh %s: refinement edge bound %g: must be > 0",
                          lr_mesh_name(m), h);
    size_t nv = lr_mesh_vertex_count(m), nt = lr_mesh_triangle_count(m);
    if (nt >= UINT32_MAX / 4 || nv >= UINT32_MAX / 4)
        return lr_err_set(e, LR_EUNSUPPORTED, "mesh %s: too large to refine", lr_mesh_name(m));
    build b = {.cap_v = nv > 16 ? nv : 16, .cap_t = nt > 16 ? nt : 16};
    b.pos = malloc(b.cap_v * 3 * sizeof *b.pos);
    b.nrm = malloc(b.cap_v * 3 * sizeof *b.nrm);
    b.t = malloc(b.cap_t * sizeof *b.t);
    if (!b.pos || !b.nrm || !b.t) {
        build_free(&b);
        return lr_err_set(e, LR_ENOMEM, "mesh refinement: out of memory");
    }
    memcpy(b.pos, lr_mesh_positions(m), nv * 3 * sizeof *b.pos);
    memcpy(b.nrm, lr_mesh_normals(m), nv * 3 * sizeof *b.nrm);
    b.nv = nv;
    const uint32_t *ix = lr_mesh_indices(m);
    static const float corner[3][2] = {{0, 0}, {1, 0}, {0, 1}}; /* (u, v) of p0, p1, p2 */
    for (size_t i = 0; i < nt; i++) {
        tri t = {.v = {ix[3 * i], ix[3 * i + 1], ix[3 * i + 2]}, .parent = (uint32_t)i};
        memcpy(t.uv, corner, sizeof t.uv);
        b.t[i] = t;
    }
    b.nt = nt;
    double h2 = h * h;
    int rc = LR_OK;
    for (;;) {
        /* Mark (make the midpoints of) every edge longer than h. */
        size_t slots = 16;
        while (slots < 6 * b.nt)
            slots *= 2;
        free(b.key);
        free(b.mid);
        b.slots = slots;
        b.key = calloc(slots, sizeof *b.key);
        b.mid = malloc(slots * sizeof *b.mid);
        if (!b.key || !b.mid) {
            rc = lr_err_set(e, LR_ENOMEM, "mesh refinement: out of memory");
            break;
        }
        size_t before = b.nv;
        bool oom = false;
        for (size_t i = 0; i < b.nt && !oom; i++)
            for (int j = 0; j < 3 && !oom; j++) {
                uint32_t a = b.t[i].v[j], c = b.t[i].v[(j + 1) % 3];
                if (edge_len2(&b, a, c) > h2)
                    oom = midpoint(&b, a, c) == UINT32_MAX;
            }
        if (oom) {
            rc = lr_err_set(e, LR_ENOMEM, "mesh refinement: out of memory");
            break;
        }
        if (b.nv == before)
            break;
        if (max_vertices && b.nv > max_vertices) {
            rc = lr_err_set(e, LR_EUNSUPPORTED,
                            "mesh %s: refined to edges of %.3g mm it would exceed %zu vertices",
                            lr_mesh_name(m), h, max_vertices);
            break;
        }
        /* Split: each triangle into at most 4. */
        tri *nt2 = malloc(4 * b.nt * sizeof *nt2);
        if (!nt2) {
            rc = lr_err_set(e, LR_ENOMEM, "mesh refinement: out of memory");
            break;
        }
        size_t n = 0;
        for (size_t i = 0; i < b.nt; i++) {
            uint32_t mm[3];
            for (int j = 0; j < 3; j++)
                mm[j] = find_mid(&b, b.t[i].v[j], b.t[i].v[(j + 1) % 3]);
            split(&b, &b.t[i], mm, nt2, &n);
        }
        free(b.t);
        b.t = nt2;
        b.nt = n;
        b.cap_t = n;
    }
    if (!rc)
        rc = finish(&b, nt, out, e);
    build_free(&b);
    return rc;
}

size_t lr_refined_locate(const lr_refined *r, size_t t, double u, double v, double w[3])
{
    if (r->lat_R)
        return lr_lattice_locate(r, t, u, v, w);
    size_t best = r->first[t];
    double best_out = INFINITY;
    for (size_t k = r->first[t]; k < r->first[t + 1]; k++) {
        const float *q = r->uv + 6 * k;
        /* Barycentrics of (u, v) in the child's (u, v) triangle. */
        double x0 = q[0], y0 = q[1], x1 = q[2], y1 = q[3], x2 = q[4], y2 = q[5];
        double det = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0);
        if (det == 0.0)
            continue;
        double b1 = ((u - x0) * (y2 - y0) - (x2 - x0) * (v - y0)) / det;
        double b2 = ((x1 - x0) * (v - y0) - (u - x0) * (y1 - y0)) / det;
        double b0 = 1.0 - b1 - b2;
        /* How far outside (0 inside): rounding may leave a hit just outside every child. */
        double out = fmax(0.0, -b0) + fmax(0.0, -b1) + fmax(0.0, -b2);
        if (out < best_out) {
            best_out = out;
            best = k;
            w[0] = b0;
            w[1] = b1;
            w[2] = b2;
        }
        if (out == 0.0)
            break;
    }
    if (best_out == INFINITY)
        w[0] = 1.0, w[1] = w[2] = 0.0;
    return best;
}
