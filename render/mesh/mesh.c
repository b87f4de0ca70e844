/* Mesh creation: validation and repair of whatever a generator or a file handed over. */
#include "render/mesh/mesh_internal.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A triangle is degenerate when its height is below this fraction of its longest edge. Float
 * positions carry a relative rounding of 6e-8, so three points that were collinear before
 * rounding come out with heights of a few 1e-8 of the edge: 1e-6 catches those with margin,
 * while a sliver of aspect 1:10^5 (far thinner than any shade rim) is kept. Such a triangle
 * has no meaningful normal and contributes nothing to area. */
#define LR_DEGENERATE_HEIGHT 1e-6

typedef struct origin_fmt {
    const lr_mesh_desc *d;
    const char *name;
    char buf[LR_ERR_MSG_MAX / 2];
} origin_fmt;

/* Where input triangle t came from: "NAME:12" (a text file's line), "NAME: face 12" (a binary
 * file's element) or "NAME: triangle 12". */
static const char *where_tri(origin_fmt *o, size_t t)
{
    if (o->d->origin && o->d->origin_is_line)
        snprintf(o->buf, sizeof o->buf, "%s:%u", o->name, (unsigned)o->d->origin[t]);
    else if (o->d->origin)
        snprintf(o->buf, sizeof o->buf, "%s: face %u", o->name, (unsigned)o->d->origin[t]);
    else
        snprintf(o->buf, sizeof o->buf, "%s: triangle %zu", o->name, t);
    return o->buf;
}

static lr_vec3 fpos(const float *pos, uint32_t v)
{
    return lr_v3(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]);
}

static lr_vec3 tri_cross(const float *pos, const uint32_t *t)
{
    lr_vec3 a = fpos(pos, t[0]), b = fpos(pos, t[1]), c = fpos(pos, t[2]);
    return lr_v3_cross(lr_v3_sub(b, a), lr_v3_sub(c, a));
}

static bool is_degenerate(const float *pos, const uint32_t *weld, const uint32_t *t)
{
    if (weld[t[0]] == weld[t[1]] || weld[t[1]] == weld[t[2]] || weld[t[0]] == weld[t[2]])
        return true;
    lr_vec3 a = fpos(pos, t[0]), b = fpos(pos, t[1]), c = fpos(pos, t[2]);
    double l0 = lr_v3_len(lr_v3_sub(b, a)), l1 = lr_v3_len(lr_v3_sub(c, b)),
           l2 = lr_v3_len(lr_v3_sub(a, c));
    double lmax = fmax(l0, fmax(l1, l2));
    double twice_area = lr_v3_len(tri_cross(pos, t));
    return twice_area <= LR_DEGENERATE_HEIGHT * lmax * lmax;
}

typedef struct dup_key {
    uint32_t k[3];
    uint32_t t;
} dup_key;

static int cmp_dup(const void *pa, const void *pb)
{
    const dup_key *a = pa, *b = pb;
    for (int i = 0; i < 3; i++)
        if (a->k[i] != b->k[i])
            return a->k[i] < b->k[i] ? -1 : 1;
    return (a->t > b->t) - (a->t < b->t);
}

static void sort3(uint32_t k[3])
{
    uint32_t t;
    if (k[0] > k[1]) { t = k[0]; k[0] = k[1]; k[1] = t; }
    if (k[1] > k[2]) { t = k[1]; k[1] = k[2]; k[2] = t; }
    if (k[0] > k[1]) { t = k[0]; k[0] = k[1]; k[1] = t; }
}

/* Whether the ray from o along a fixed, generic direction crosses the triangles of closed
 * pieces other than `self` an odd number of times (Moller-Trumbore). */
static bool odd_crossings(const float *pos, const uint32_t *idx, size_t nt, const uint32_t *piece,
                          const uint8_t *pclosed, uint32_t self, lr_vec3 o)
{
    const lr_vec3 d = lr_v3_normalize(lr_v3(0.5773, 0.5801, 0.5749));
    unsigned count = 0;
    for (size_t t = 0; t < nt; t++) {
        if (piece[t] == self || !pclosed[piece[t]])
            continue;
        lr_vec3 a = fpos(pos, idx[3 * t]), b = fpos(pos, idx[3 * t + 1]);
        lr_vec3 c = fpos(pos, idx[3 * t + 2]);
        lr_vec3 e1 = lr_v3_sub(b, a), e2 = lr_v3_sub(c, a), p = lr_v3_cross(d, e2);
        double det = lr_v3_dot(e1, p);
        if (fabs(det) < 1e-300)
            continue;
        lr_vec3 s = lr_v3_sub(o, a);
        double u = lr_v3_dot(s, p) / det;
        if (u < 0.0 || u > 1.0)
            continue;
        lr_vec3 q = lr_v3_cross(s, e1);
        double v = lr_v3_dot(d, q) / det;
        if (v < 0.0 || u + v > 1.0)
            continue;
        if (lr_v3_dot(e2, q) / det > 0.0)
            count++;
    }
    return count & 1u;
}

/* Turns faces over so that neighbours agree (breadth-first over two-face edges; each piece
 * keeps the orientation most of its faces already had), then turns closed pieces with negative
 * volume inside out, except those nested inside an odd number of other closed pieces (the
 * inner wall of a hollow object), which get negative volume. Returns the number of faces
 * flipped, or (size_t)-1 on allocation failure.
 */
static size_t reorient(const float *pos, uint32_t *idx, size_t nt, const lr_mesh_edge *ed)
{
    size_t ne = 3 * nt;
    /* Adjacency over manifold edges: for triangle t, a list of (neighbour, same-direction). */
    size_t *start = calloc(nt + 1, sizeof *start);
    uint32_t *nb = malloc((ne ? ne : 1) * sizeof *nb);
    uint8_t *same = malloc(ne ? ne : 1);
    uint8_t *open = calloc(nt ? nt : 1, 1); /* touches a boundary or non-manifold edge */
    int8_t *flip = malloc(nt ? nt : 1);
    uint32_t *queue = malloc((nt ? nt : 1) * sizeof *queue); /* also: the piece's faces */
    uint32_t *piece = malloc((nt ? nt : 1) * sizeof *piece);
    uint32_t *pseed = malloc((nt ? nt : 1) * sizeof *pseed);
    uint8_t *pclosed = malloc(nt ? nt : 1), *pinvert = malloc(nt ? nt : 1);
    size_t flipped = (size_t)-1;
    if (!start || !nb || !same || !open || !flip || !queue || !piece || !pseed || !pclosed ||
        !pinvert)
        goto done;
    for (size_t i = 0; i < ne;) {
        size_t j = i + 1;
        while (j < ne && ed[j].a == ed[i].a && ed[j].b == ed[i].b)
            j++;
        if (j - i == 2) {
            start[ed[i].t + 1]++;
            start[ed[i + 1].t + 1]++;
        } else {
            for (size_t k = i; k < j; k++)
                open[ed[k].t] = 1;
        }
        i = j;
    }
    for (size_t t = 0; t < nt; t++)
        start[t + 1] += start[t];
    {
        size_t *fill = calloc(nt ? nt : 1, sizeof *fill);
        if (!fill)
            goto done;
        for (size_t i = 0; i < ne;) {
            size_t j = i + 1;
            while (j < ne && ed[j].a == ed[i].a && ed[j].b == ed[i].b)
                j++;
            if (j - i == 2) {
                uint32_t t0 = ed[i].t, t1 = ed[i + 1].t;
                uint8_t s = ed[i].forward == ed[i + 1].forward;
                nb[start[t0] + fill[t0]] = t1;
                same[start[t0] + fill[t0]++] = s;
                nb[start[t1] + fill[t1]] = t0;
                same[start[t1] + fill[t1]++] = s;
            }
            i = j;
        }
        free(fill);
    }
    memset(flip, -1, nt);
    flipped = 0;
    /* Pass 1: pieces (consistent orientation inside each; piece[t], its closedness and the
     * inversion that gives it positive volume). */
    size_t npiece = 0;
    for (size_t seed = 0; seed < nt; seed++) {
        if (flip[seed] >= 0)
            continue;
        size_t head = 0, tail = 0, nflip = 0;
        bool closed = true;
        flip[seed] = 0;
        queue[tail++] = (uint32_t)seed;
        while (head < tail) {
            uint32_t t = queue[head++];
            piece[t] = (uint32_t)npiece;
            if (open[t])
                closed = false;
            for (size_t k = start[t]; k < start[t + 1]; k++) {
                uint32_t u = nb[k];
                if (flip[u] >= 0)
                    continue; /* a conflict here means a non-orientable piece: left as is */
                flip[u] = (int8_t)(flip[t] ^ same[k]);
                nflip += (size_t)flip[u];
                queue[tail++] = u;
            }
        }
        size_t n = tail;
        bool invert = nflip * 2 > n; /* keep the majority's orientation */
        if (closed) {
            /* Volume of the piece as it will be: turn it inside out when negative. */
            double vol = 0.0;
            for (size_t i = 0; i < n; i++) {
                uint32_t *tri = &idx[3 * queue[i]];
                lr_vec3 a = fpos(pos, tri[0]), b = fpos(pos, tri[1]), c = fpos(pos, tri[2]);
                double v = lr_v3_dot(a, lr_v3_cross(b, c));
                vol += (flip[queue[i]] ^ invert) ? -v : v;
            }
            if (vol < 0.0)
                invert = !invert;
        }
        pclosed[npiece] = closed;
        pinvert[npiece] = invert;
        pseed[npiece] = (uint32_t)seed;
        npiece++;
    }
    /* Pass 2: a closed piece inside an odd number of other closed pieces bounds a cavity (the
     * inner wall of a hollow sphere): its normals point into the cavity, out of the material,
     * so its volume is negative. Nesting by ray parity from a point of the piece. */
    size_t nclosed = 0;
    for (size_t p = 0; p < npiece; p++)
        nclosed += pclosed[p];
    if (nclosed > 1)
        for (size_t p = 0; p < npiece; p++) {
            if (!pclosed[p])
                continue;
            uint32_t *tri = &idx[3 * pseed[p]];
            lr_vec3 o = lr_v3_scale(lr_v3_add(fpos(pos, tri[0]), lr_v3_add(fpos(pos, tri[1]),
                                                                       fpos(pos, tri[2]))),
                                    1.0 / 3.0);
            if (odd_crossings(pos, idx, nt, piece, pclosed, (uint32_t)p, o))
                pinvert[p] = !pinvert[p];
        }
    for (size_t t = 0; t < nt; t++) {
        if (flip[t] ^ pinvert[piece[t]]) {
            uint32_t tmp = idx[3 * t + 1];
            idx[3 * t + 1] = idx[3 * t + 2];
            idx[3 * t + 2] = tmp;
            flipped++;
        }
    }
done:
    free(piece);
    free(pseed);
    free(pclosed);
    free(pinvert);
    free(start);
    free(nb);
    free(same);
    free(open);
    free(flip);
    free(queue);
    return flipped;
}

void lr_mesh_destroy(lr_mesh *m)
{
    if (!m)
        return;
    free(m->name);
    free(m->pos);
    free(m->nrm);
    free(m->idx);
    free(m);
}

static int oom(const char *name, lr_err *e)
{
    return lr_err_set(e, LR_ENOMEM, "%s: out of memory", name);
}

/* Area-weighted vertex normals; a vertex whose faces cancel takes its first face's normal. */
static void compute_normals(const float *pos, size_t nv, const uint32_t *idx, size_t nt,
                            float *nrm)
{
    double *acc = calloc(3 * (nv ? nv : 1), sizeof *acc);
    lr_vec3 *first = calloc(nv ? nv : 1, sizeof *first);
    if (!acc || !first) {
        free(acc);
        free(first);
        for (size_t v = 0; v < nv; v++) {
            nrm[3 * v] = nrm[3 * v + 1] = 0.0f;
            nrm[3 * v + 2] = 1.0f;
        }
        return;
    }
    for (size_t t = 0; t < nt; t++) {
        lr_vec3 c = tri_cross(pos, &idx[3 * t]); /* length = twice the area */
        for (int k = 0; k < 3; k++) {
            uint32_t v = idx[3 * t + k];
            acc[3 * v] += c.x;
            acc[3 * v + 1] += c.y;
            acc[3 * v + 2] += c.z;
            if (lr_v3_len(first[v]) == 0.0)
                first[v] = c;
        }
    }
    for (size_t v = 0; v < nv; v++) {
        lr_vec3 n = lr_v3_normalize(lr_v3(acc[3 * v], acc[3 * v + 1], acc[3 * v + 2]));
        if (lr_v3_len(n) < 0.5)
            n = lr_v3_normalize(first[v]);
        nrm[3 * v] = (float)n.x;
        nrm[3 * v + 1] = (float)n.y;
        nrm[3 * v + 2] = (float)n.z;
    }
    free(acc);
    free(first);
}

int lr_mesh_create(const lr_mesh_desc *d, lr_mesh **out, lr_err *e)
{
    *out = NULL;
    const char *name = d->name ? d->name : "mesh";
    const lr_warn_sink *warn = &d->checks.warn;
    bool open_ok = d->checks.flags & LR_MESH_OPEN_OK;
    origin_fmt of = {.d = d, .name = name};
    size_t nv = d->vertex_count, nt = d->triangle_count;
    if (nt == 0)
        return lr_err_set(e, LR_EINVAL, "%s: no triangles", name);
    if (nv == 0 || !d->positions || !d->indices)
        return lr_err_set(e, LR_EINVAL, "%s: no vertices", name);
    if (nv > UINT32_MAX || nt > UINT32_MAX / 3)
        return lr_err_set(e, LR_EINVAL, "%s: too many vertices or triangles", name);

    float *pos = malloc(3 * nv * sizeof *pos);
    uint32_t *idx = malloc(3 * nt * sizeof *idx);
    uint32_t *weld = NULL;
    lr_mesh_edge *ed = NULL;
    dup_key *keys = NULL;
    uint8_t *drop = NULL;
    uint32_t *remap = NULL;
    lr_mesh *m = NULL;
    int rc = LR_OK;
    if (!pos || !idx) {
        rc = oom(name, e);
        goto fail;
    }
    for (size_t v = 0; v < nv; v++)
        for (int k = 0; k < 3; k++) {
            double x = d->positions[3 * v + k];
            if (!isfinite(x)) {
                rc = lr_err_set(e, LR_EINVAL, "%s: vertex %zu: coordinate %c is %g", name, v,
                                "xyz"[k], x);
                goto fail;
            }
            if (fabs(x) > FLT_MAX) {
                rc = lr_err_set(e, LR_EINVAL,
                                "%s: vertex %zu: coordinate %c = %g mm overflows float", name, v,
                                "xyz"[k], x);
                goto fail;
            }
            pos[3 * v + k] = (float)x;
        }
    for (size_t t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++) {
            uint32_t i = d->indices[3 * t + k];
            if (i >= nv) {
                rc = lr_err_set(e, LR_EINVAL,
                                "%s: vertex index %u out of range (%zu vertices)",
                                where_tri(&of, t), (unsigned)i, nv);
                goto fail;
            }
            idx[3 * t + k] = i;
        }

    lr_mesh_report rep = {0};
    size_t nclasses = 0;
    weld = lr_mesh_weld(pos, nv, &nclasses);
    drop = calloc(nt, 1);
    keys = malloc(nt * sizeof *keys);
    if (!weld || !drop || !keys) {
        rc = oom(name, e);
        goto fail;
    }
    /* Degenerate triangles. */
    size_t first_degen = SIZE_MAX, first_dup = SIZE_MAX;
    for (size_t t = 0; t < nt; t++)
        if (is_degenerate(pos, weld, &idx[3 * t])) {
            drop[t] = 1;
            rep.degenerate_removed++;
            if (first_degen == SIZE_MAX)
                first_degen = t;
        }
    /* Duplicate faces: the same three points, in any order or winding; the first is kept. */
    size_t nk = 0;
    for (size_t t = 0; t < nt; t++) {
        if (drop[t])
            continue;
        dup_key k = {{weld[idx[3 * t]], weld[idx[3 * t + 1]], weld[idx[3 * t + 2]]}, (uint32_t)t};
        sort3(k.k);
        keys[nk++] = k;
    }
    qsort(keys, nk, sizeof *keys, cmp_dup);
    for (size_t i = 1; i < nk; i++)
        if (memcmp(keys[i].k, keys[i - 1].k, sizeof keys[i].k) == 0) {
            drop[keys[i].t] = 1;
            rep.duplicate_removed++;
            if (keys[i].t < first_dup)
                first_dup = keys[i].t;
        }
    if (rep.degenerate_removed)
        lr_warn(warn, "%s: removed %zu zero-area triangle%s (first at %s)", name,
                rep.degenerate_removed, rep.degenerate_removed == 1 ? "" : "s",
                where_tri(&of, first_degen));
    if (rep.duplicate_removed)
        lr_warn(warn, "%s: removed %zu duplicate face%s (first at %s)", name,
                rep.duplicate_removed, rep.duplicate_removed == 1 ? "" : "s",
                where_tri(&of, first_dup));
    size_t kt = 0;
    for (size_t t = 0; t < nt; t++)
        if (!drop[t]) {
            memmove(&idx[3 * kt], &idx[3 * t], 3 * sizeof *idx);
            kt++;
        }
    if (kt == 0) {
        rc = lr_err_set(e, LR_EINVAL, "%s: every triangle has zero area", name);
        goto fail;
    }
    nt = kt;

    /* Topology and winding. */
    if (lr_mesh_topology(weld, nclasses, idx, nt, &rep, &ed)) {
        rc = oom(name, e);
        goto fail;
    }
    if (rep.nonmanifold_edges) {
        /* Name the first such edge by position so that it can be found in a modeller. */
        lr_vec3 p = lr_v3(0, 0, 0);
        for (size_t i = 0; i + 2 < 3 * nt; i++)
            if (ed[i].a == ed[i + 2].a && ed[i].b == ed[i + 2].b) {
                const uint32_t *tri = &idx[3 * ed[i].t];
                for (int k = 0; k < 3; k++)
                    if (weld[tri[k]] == ed[i].a)
                        p = fpos(pos, tri[k]);
                break;
            }
        lr_warn(warn, "%s: %zu non-manifold edge%s (shared by more than two faces), first at "
                "(%g, %g, %g)", name, rep.nonmanifold_edges,
                rep.nonmanifold_edges == 1 ? "" : "s", p.x, p.y, p.z);
    }
    if (rep.boundary_edges && !open_ok)
        lr_warn(warn, "%s: open mesh: %zu boundary edge%s in %zu loop%s", name,
                rep.boundary_edges, rep.boundary_edges == 1 ? "" : "s", rep.boundary_loops,
                rep.boundary_loops == 1 ? "" : "s");
    size_t inconsistent_in = rep.inconsistent_edges;
    if (!(d->checks.flags & LR_MESH_KEEP_WINDING)) {
        size_t f = reorient(pos, idx, nt, ed);
        if (f == (size_t)-1) {
            rc = oom(name, e);
            goto fail;
        }
        rep.flipped = f;
        if (f) {
            lr_mesh_report after = rep;
            free(ed);
            ed = NULL;
            if (lr_mesh_topology(weld, nclasses, idx, nt, &after, NULL)) {
                rc = oom(name, e);
                goto fail;
            }
            rep.oriented = after.oriented;
        }
    }
    rep.inconsistent_edges = inconsistent_in;
    if (inconsistent_in)
        lr_warn(warn, "%s: inconsistent winding on %zu edge%s; %s", name, inconsistent_in,
                inconsistent_in == 1 ? "" : "s",
                (d->checks.flags & LR_MESH_KEEP_WINDING) ? "kept as is"
                : rep.oriented ? "faces turned to agree"
                               : "the surface is not orientable, kept as is");
    else if (rep.flipped)
        lr_warn(warn, "%s: closed surface was inside out; turned %zu faces", name, rep.flipped);

    /* Unreferenced vertices. */
    remap = malloc(nv * sizeof *remap);
    if (!remap) {
        rc = oom(name, e);
        goto fail;
    }
    for (size_t v = 0; v < nv; v++)
        remap[v] = UINT32_MAX;
    size_t kv = 0;
    for (size_t i = 0; i < 3 * nt; i++)
        if (remap[idx[i]] == UINT32_MAX)
            remap[idx[i]] = 0; /* mark; numbered below in input order */
    for (size_t v = 0; v < nv; v++)
        if (remap[v] != UINT32_MAX)
            remap[v] = (uint32_t)kv++;
    rep.unreferenced_removed = nv - kv;
    if (rep.unreferenced_removed)
        lr_warn(warn, "%s: dropped %zu unreferenced vert%s", name, rep.unreferenced_removed,
                rep.unreferenced_removed == 1 ? "ex" : "ices");

    m = calloc(1, sizeof *m);
    if (!m || !(m->name = strdup(name)) || !(m->pos = malloc(3 * kv * sizeof *m->pos)) ||
        !(m->nrm = malloc(3 * kv * sizeof *m->nrm)) ||
        !(m->idx = malloc(3 * nt * sizeof *m->idx))) {
        rc = oom(name, e);
        goto fail;
    }
    m->nv = kv;
    m->nt = nt;
    for (size_t v = 0; v < nv; v++)
        if (remap[v] != UINT32_MAX)
            memcpy(&m->pos[3 * remap[v]], &pos[3 * v], 3 * sizeof *pos);
    for (size_t i = 0; i < 3 * nt; i++)
        m->idx[i] = remap[idx[i]];

    /* Normals: the given ones when every used one is finite and non-zero. */
    bool use_given = d->normals != NULL;
    size_t bad_normal = SIZE_MAX;
    for (size_t v = 0; use_given && v < nv; v++) {
        if (remap[v] == UINT32_MAX)
            continue;
        lr_vec3 n = lr_v3(d->normals[3 * v], d->normals[3 * v + 1], d->normals[3 * v + 2]);
        double l = lr_v3_len(n);
        if (!lr_v3_isfinite(n) || !(l > 1e-30) || !isfinite(l)) {
            use_given = false;
            bad_normal = v;
            break;
        }
        n = lr_v3_scale(n, 1.0 / l);
        float *o = &m->nrm[3 * remap[v]];
        o[0] = (float)n.x;
        o[1] = (float)n.y;
        o[2] = (float)n.z;
    }
    if (d->normals && !use_given)
        lr_warn(warn, "%s: vertex %zu has a zero or non-finite normal; computing all normals",
                name, bad_normal);
    if (!use_given)
        compute_normals(m->pos, m->nv, m->idx, m->nt, m->nrm);
    rep.normals_computed = !use_given;

    if (d->checks.report)
        *d->checks.report = rep;
    *out = m;
    m = NULL;
fail:
    lr_mesh_destroy(m);
    free(pos);
    free(idx);
    free(weld);
    free(ed);
    free(keys);
    free(drop);
    free(remap);
    return rc;
}

const char *lr_mesh_name(const lr_mesh *m) { return m->name; }
size_t lr_mesh_vertex_count(const lr_mesh *m) { return m->nv; }
size_t lr_mesh_triangle_count(const lr_mesh *m) { return m->nt; }
const float *lr_mesh_positions(const lr_mesh *m) { return m->pos; }
const float *lr_mesh_normals(const lr_mesh *m) { return m->nrm; }
const uint32_t *lr_mesh_indices(const lr_mesh *m) { return m->idx; }

lr_vec3 lr_mesh_vertex(const lr_mesh *m, size_t v) { return fpos(m->pos, (uint32_t)v); }

void lr_mesh_triangle(const lr_mesh *m, size_t t, lr_vec3 p[3])
{
    for (int k = 0; k < 3; k++)
        p[k] = fpos(m->pos, m->idx[3 * t + k]);
}

lr_vec3 lr_mesh_triangle_normal(const lr_mesh *m, size_t t)
{
    return lr_v3_normalize(tri_cross(m->pos, &m->idx[3 * t]));
}

double lr_mesh_triangle_area(const lr_mesh *m, size_t t)
{
    return 0.5 * lr_v3_len(tri_cross(m->pos, &m->idx[3 * t]));
}

double lr_mesh_area(const lr_mesh *m)
{
    double a = 0.0;
    for (size_t t = 0; t < m->nt; t++)
        a += lr_mesh_triangle_area(m, t);
    return a;
}

double lr_mesh_longest_edge(const lr_mesh *m)
{
    double longest = 0.0;
    for (size_t t = 0; t < m->nt; t++) {
        lr_vec3 p[3];
        lr_mesh_triangle(m, t, p);
        for (int k = 0; k < 3; k++)
            longest = fmax(longest, lr_v3_len(lr_v3_sub(p[k], p[(k + 1) % 3])));
    }
    return longest;
}

double lr_mesh_volume(const lr_mesh *m)
{
    /* Sum of signed tetrahedra (origin, a, b, c); taken about the first vertex instead of the
     * origin to keep the terms small when the mesh sits far from the origin. */
    lr_vec3 o = fpos(m->pos, 0);
    double v = 0.0;
    for (size_t t = 0; t < m->nt; t++) {
        lr_vec3 p[3];
        lr_mesh_triangle(m, t, p);
        lr_vec3 a = lr_v3_sub(p[0], o), b = lr_v3_sub(p[1], o), c = lr_v3_sub(p[2], o);
        v += lr_v3_dot(a, lr_v3_cross(b, c));
    }
    return v / 6.0;
}

void lr_mesh_bounds(const lr_mesh *m, lr_vec3 *lo, lr_vec3 *hi)
{
    lr_vec3 l = fpos(m->pos, 0), h = l;
    for (size_t v = 1; v < m->nv; v++) {
        lr_vec3 p = fpos(m->pos, (uint32_t)v);
        l = lr_v3(fmin(l.x, p.x), fmin(l.y, p.y), fmin(l.z, p.z));
        h = lr_v3(fmax(h.x, p.x), fmax(h.y, p.y), fmax(h.z, p.z));
    }
    *lo = l;
    *hi = h;
}

void lr_mesh_bounding_sphere(const lr_mesh *m, lr_vec3 *center, double *radius)
{
    lr_vec3 lo, hi;
    lr_mesh_bounds(m, &lo, &hi);
    lr_vec3 c = lr_v3_scale(lr_v3_add(lo, hi), 0.5);
    double r = 0.0;
    for (size_t v = 0; v < m->nv; v++)
        r = fmax(r, lr_v3_len(lr_v3_sub(fpos(m->pos, (uint32_t)v), c)));
    *center = c;
    *radius = r;
}

void lr_mesh_analyze(const lr_mesh *m, lr_mesh_report *out)
{
    memset(out, 0, sizeof *out);
    size_t nclasses = 0;
    uint32_t *weld = lr_mesh_weld(m->pos, m->nv, &nclasses);
    if (weld)
        lr_mesh_topology(weld, nclasses, m->idx, m->nt, out, NULL);
    free(weld);
}
