/* Median-split BVH over triangles, and the brute-force loops it must agree with. */
#include "render/mesh/bvh.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "render/mesh/triangle.h"

#define LEAF_MAX 4
#define STACK_MAX 96 /* median splits: depth <= log2(2^32 / LEAF_MAX) + 1 */

typedef struct node {
    double lo[3], hi[3];
    uint32_t first, count; /* leaf when count > 0: order[first .. first + count) */
    uint32_t right;        /* internal: left child is the next node */
} node;

struct lr_bvh {
    const lr_mesh *mesh;
    node *nodes;
    size_t nnodes;
    uint32_t *order;
    double *cent; /* 3 per triangle */
    /* The triangles' corners in leaf order (tri[3 i + k]: corner k of triangle order[i]), as
     * lr_mesh_triangle gives them (float to double is exact): the leaves read them in one
     * sweep instead of three index lookups and conversions per triangle. */
    lr_vec3 *tri;
};

const lr_mesh *lr_bvh_mesh(const lr_bvh *b) { return b->mesh; }

void lr_bvh_destroy(lr_bvh *b)
{
    if (!b)
        return;
    free(b->nodes);
    free(b->order);
    free(b->cent);
    free(b->tri);
    free(b);
}

/* Quickselect: order[lo..hi) partially sorted so that order[k] has the k-th centroid along
 * axis, smaller ones before it, larger after. */
static void select_kth(uint32_t *order, const double *cent, int axis, size_t lo, size_t hi,
                       size_t k)
{
    while (hi - lo > 1) {
        double pivot = cent[3 * order[lo + (hi - lo) / 2] + axis];
        size_t i = lo, j = hi - 1;
        while (i <= j) {
            while (cent[3 * order[i] + axis] < pivot)
                i++;
            while (cent[3 * order[j] + axis] > pivot)
                j--;
            if (i <= j) {
                uint32_t t = order[i];
                order[i] = order[j];
                order[j] = t;
                i++;
                if (j == 0)
                    break;
                j--;
            }
        }
        if (k <= j)
            hi = j + 1;
        else if (k >= i)
            lo = i;
        else
            return;
    }
}

static void tri_bounds(const lr_mesh *m, uint32_t t, double lo[3], double hi[3])
{
    lr_vec3 p[3];
    lr_mesh_triangle(m, t, p);
    for (int k = 0; k < 3; k++) {
        double v[3] = {p[k].x, p[k].y, p[k].z};
        for (int a = 0; a < 3; a++) {
            if (k == 0 || v[a] < lo[a])
                lo[a] = v[a];
            if (k == 0 || v[a] > hi[a])
                hi[a] = v[a];
        }
    }
}

static uint32_t build(lr_bvh *b, size_t begin, size_t end)
{
    uint32_t me = (uint32_t)b->nnodes++;
    node *n = &b->nodes[me];
    double clo[3] = {INFINITY, INFINITY, INFINITY}, chi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = begin; i < end; i++) {
        double lo[3], hi[3];
        tri_bounds(b->mesh, b->order[i], lo, hi);
        for (int a = 0; a < 3; a++) {
            n->lo[a] = i == begin ? lo[a] : fmin(n->lo[a], lo[a]);
            n->hi[a] = i == begin ? hi[a] : fmax(n->hi[a], hi[a]);
            double c = b->cent[3 * b->order[i] + a];
            clo[a] = fmin(clo[a], c);
            chi[a] = fmax(chi[a], c);
        }
    }
    /* Pad by far more than the rounding of the slab and distance tests (~1e-16 relative), so
     * that no hit or closest point inside the box can be pruned; costs nothing measurable. */
    double scale = 0.0;
    for (int a = 0; a < 3; a++)
        scale = fmax(scale, fmax(fabs(n->lo[a]), fabs(n->hi[a])));
    for (int a = 0; a < 3; a++) {
        n->lo[a] -= 1e-9 * scale + 1e-300;
        n->hi[a] += 1e-9 * scale + 1e-300;
    }
    int axis = 0;
    for (int a = 1; a < 3; a++)
        if (chi[a] - clo[a] > chi[axis] - clo[axis])
            axis = a;
    size_t count = end - begin;
    if (count <= LEAF_MAX || !(chi[axis] > clo[axis])) {
        n->first = (uint32_t)begin;
        n->count = (uint32_t)count;
        return me;
    }
    size_t mid = begin + count / 2;
    select_kth(b->order, b->cent, axis, begin, end, mid);
    n->count = 0;
    build(b, begin, mid);
    uint32_t r = build(b, mid, end);
    b->nodes[me].right = r; /* nodes is preallocated: n stays valid */
    return me;
}

int lr_bvh_create(const lr_mesh *m, lr_bvh **out, lr_err *e)
{
    *out = NULL;
    size_t nt = lr_mesh_triangle_count(m);
    lr_bvh *b = calloc(1, sizeof *b);
    if (!b)
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory for the BVH", lr_mesh_name(m));
    b->mesh = m;
    b->nodes = malloc(2 * nt * sizeof *b->nodes); /* a binary tree with <= nt leaves */
    b->order = malloc(nt * sizeof *b->order);
    b->cent = malloc(3 * nt * sizeof *b->cent);
    if (!b->nodes || !b->order || !b->cent) {
        lr_bvh_destroy(b);
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory for the BVH", lr_mesh_name(m));
    }
    for (size_t t = 0; t < nt; t++) {
        lr_vec3 p[3];
        lr_mesh_triangle(m, t, p);
        lr_vec3 c = lr_v3_scale(lr_v3_add(p[0], lr_v3_add(p[1], p[2])), 1.0 / 3.0);
        b->cent[3 * t] = c.x;
        b->cent[3 * t + 1] = c.y;
        b->cent[3 * t + 2] = c.z;
        b->order[t] = (uint32_t)t;
    }
    build(b, 0, nt);
    b->tri = malloc((nt ? 3 * nt : 1) * sizeof *b->tri);
    if (!b->tri) {
        lr_bvh_destroy(b);
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory for the BVH", lr_mesh_name(m));
    }
    for (size_t i = 0; i < nt; i++)
        lr_mesh_triangle(m, b->order[i], &b->tri[3 * i]);
    *out = b;
    return LR_OK;
}

/* One axis of the slab test: narrows [*t0, *t1] to the ray's span inside the box's slab along
 * that axis; false when it leaves nothing. A zero direction component: inside the slab or not
 * (no division). Scalars in and out, so the sanitizers' checks stay on the node's six loads. */
static inline bool slab_axis(double lo, double hi, double o, double inv, bool zero, double *t0,
                             double *t1)
{
    if (zero)
        return !(o < lo || o > hi);
    double ta = (lo - o) * inv, tb = (hi - o) * inv;
    if (ta > tb) {
        double s = ta;
        ta = tb;
        tb = s;
    }
    /* Ize 2013: widening the exit by 2 gamma(3) makes the test conservative. */
    tb *= 1.0 + 2.0 * (3.0 * 1.1102230246251565e-16);
    *t0 = ta > *t0 ? ta : *t0;
    *t1 = tb < *t1 ? tb : *t1;
    return !(*t0 > *t1);
}

/* Ray-box slab test; false when the ray misses the box or leaves it before tmin or enters
 * after tmax. *tenter receives the entry parameter. */
static bool slab(const node *n, const double o[3], const double inv[3], const bool zero[3],
                 double tmin, double tmax, double *tenter)
{
    double t0 = tmin, t1 = tmax;
    if (!slab_axis(n->lo[0], n->hi[0], o[0], inv[0], zero[0], &t0, &t1) ||
        !slab_axis(n->lo[1], n->hi[1], o[1], inv[1], zero[1], &t0, &t1) ||
        !slab_axis(n->lo[2], n->hi[2], o[2], inv[2], zero[2], &t0, &t1))
        return false;
    *tenter = t0;
    return true;
}

/* Triangle t with corners p (the brute-force loops' from the mesh, the leaves' from b->tri). */
static bool tri_hit(const lr_vec3 p[3], size_t t, lr_vec3 o, lr_vec3 d, double tmin, double tmax,
                    lr_hit *h)
{
    double tt, u, v;
    if (!lr_ray_triangle(o, d, p[0], p[1], p[2], tmin, tmax, &tt, &u, &v))
        return false;
    *h = (lr_hit){tt, t, u, v};
    return true;
}

/* Better = nearer, or as near with a lower triangle index (the brute-force order). */
static bool better(const lr_hit *a, const lr_hit *b)
{
    return a->t < b->t || (a->t == b->t && a->triangle < b->triangle);
}

/* Each stack entry carries the node's entry parameter from the slab test made when it was
 * pushed: on pop, a node entered beyond the nearest hit found since is skipped without a
 * second box test (the slab test against the smaller tmax would reject exactly such nodes, and
 * a node entered at or before it may still hold a hit as near with a lower index). Leaves clip
 * the triangle test at the nearest hit so far: the test is inclusive (t <= tmax), so a tie is
 * still found and settled by better(). */
static bool traverse(const lr_bvh *b, lr_vec3 o, lr_vec3 d, double tmin, double tmax,
                     lr_hit *hit, bool any)
{
    double oo[3] = {o.x, o.y, o.z}, dd[3] = {d.x, d.y, d.z}, inv[3];
    bool zero[3];
    for (int a = 0; a < 3; a++) {
        zero[a] = dd[a] == 0.0;
        inv[a] = zero[a] ? 0.0 : 1.0 / dd[a];
    }
    uint32_t stack[STACK_MAX];
    double enter[STACK_MAX];
    int sp = 0;
    double te;
    if (!b->nnodes || !slab(&b->nodes[0], oo, inv, zero, tmin, tmax, &te))
        return false;
    stack[sp] = 0;
    enter[sp++] = te;
    bool found = false;
    lr_hit best = {INFINITY, SIZE_MAX, 0, 0};
    while (sp > 0) {
        --sp;
        if (found && enter[sp] > best.t)
            continue;
        const node *n = &b->nodes[stack[sp]];
        double bound = found ? best.t : tmax;
        if (n->count) {
            for (uint32_t i = 0; i < n->count; i++) {
                uint32_t k = n->first + i;
                lr_hit h;
                if (!tri_hit(&b->tri[3 * (size_t)k], b->order[k], o, d, tmin, bound, &h))
                    continue;
                if (!found || better(&h, &best)) {
                    best = h;
                    found = true;
                    bound = best.t;
                    if (any) {
                        *hit = best;
                        return true;
                    }
                }
            }
            continue;
        }
        /* Push the farther child first so that the nearer one is searched first. */
        uint32_t l = (uint32_t)(n - b->nodes) + 1, r = n->right;
        double tl = INFINITY, tr = INFINITY;
        bool hl = slab(&b->nodes[l], oo, inv, zero, tmin, bound, &tl);
        bool hr = slab(&b->nodes[r], oo, inv, zero, tmin, bound, &tr);
        if (hl && hr) {
            bool lfirst = tl <= tr;
            stack[sp] = lfirst ? r : l;
            enter[sp++] = lfirst ? tr : tl;
            stack[sp] = lfirst ? l : r;
            enter[sp++] = lfirst ? tl : tr;
        } else if (hl) {
            stack[sp] = l;
            enter[sp++] = tl;
        } else if (hr) {
            stack[sp] = r;
            enter[sp++] = tr;
        }
    }
    if (found)
        *hit = best;
    return found;
}

bool lr_bvh_intersect(const lr_bvh *b, lr_vec3 o, lr_vec3 d, double tmin, double tmax,
                      lr_hit *hit)
{
    lr_hit h;
    bool r = traverse(b, o, d, tmin, tmax, &h, false);
    if (r && hit)
        *hit = h;
    return r;
}

bool lr_bvh_occluded(const lr_bvh *b, lr_vec3 o, lr_vec3 d, double tmin, double tmax)
{
    lr_hit h;
    return traverse(b, o, d, tmin, tmax, &h, true);
}

bool lr_mesh_intersect(const lr_mesh *m, lr_vec3 o, lr_vec3 d, double tmin, double tmax,
                       lr_hit *hit)
{
    bool found = false;
    lr_hit best = {INFINITY, SIZE_MAX, 0, 0};
    for (size_t t = 0; t < lr_mesh_triangle_count(m); t++) {
        lr_hit h;
        lr_vec3 p[3];
        lr_mesh_triangle(m, t, p);
        if (tri_hit(p, t, o, d, tmin, tmax, &h) && (!found || better(&h, &best))) {
            best = h;
            found = true;
        }
    }
    if (found && hit)
        *hit = best;
    return found;
}

static void tri_closest(const lr_vec3 q[3], size_t t, lr_vec3 p, lr_closest *c)
{
    c->point = lr_closest_on_triangle(p, q[0], q[1], q[2], c->w);
    c->distance = lr_v3_len(lr_v3_sub(p, c->point));
    c->triangle = t;
}

static bool closer(const lr_closest *a, const lr_closest *b)
{
    return a->distance < b->distance || (a->distance == b->distance && a->triangle < b->triangle);
}

static double box_distance(const node *n, lr_vec3 p)
{
    double pp[3] = {p.x, p.y, p.z}, s = 0.0;
    for (int a = 0; a < 3; a++) {
        double d = pp[a] < n->lo[a] ? n->lo[a] - pp[a] : pp[a] > n->hi[a] ? pp[a] - n->hi[a] : 0.0;
        s += d * d;
    }
    return sqrt(s);
}

/* As traverse: each stack entry carries its box distance from the push, so a pop compares it
 * with the closest point found since instead of measuring the box again. */
bool lr_bvh_closest(const lr_bvh *b, lr_vec3 p, double max_dist, lr_closest *out)
{
    uint32_t stack[STACK_MAX];
    double dist[STACK_MAX];
    int sp = 0;
    if (!b->nnodes)
        return false;
    stack[sp] = 0;
    dist[sp++] = box_distance(&b->nodes[0], p);
    bool found = false;
    lr_closest best = {.distance = INFINITY, .triangle = SIZE_MAX};
    while (sp > 0) {
        --sp;
        double bound = found ? best.distance : max_dist;
        if (dist[sp] > bound)
            continue;
        const node *n = &b->nodes[stack[sp]];
        if (n->count) {
            for (uint32_t i = 0; i < n->count; i++) {
                uint32_t k = n->first + i;
                lr_closest c;
                tri_closest(&b->tri[3 * (size_t)k], b->order[k], p, &c);
                if (c.distance <= max_dist && (!found || closer(&c, &best))) {
                    best = c;
                    found = true;
                }
            }
            continue;
        }
        uint32_t l = (uint32_t)(n - b->nodes) + 1, r = n->right;
        double dl = box_distance(&b->nodes[l], p), dr = box_distance(&b->nodes[r], p);
        bool lfirst = dl <= dr;
        stack[sp] = lfirst ? r : l;
        dist[sp++] = lfirst ? dr : dl;
        stack[sp] = lfirst ? l : r;
        dist[sp++] = lfirst ? dl : dr;
    }
    if (found && out)
        *out = best;
    return found;
}

bool lr_mesh_closest(const lr_mesh *m, lr_vec3 p, double max_dist, lr_closest *out)
{
    bool found = false;
    lr_closest best = {.distance = INFINITY, .triangle = SIZE_MAX};
    for (size_t t = 0; t < lr_mesh_triangle_count(m); t++) {
        lr_closest c;
        lr_vec3 q[3];
        lr_mesh_triangle(m, t, q);
        tri_closest(q, t, p, &c);
        if (c.distance <= max_dist && (!found || closer(&c, &best))) {
            best = c;
            found = true;
        }
    }
    if (found && out)
        *out = best;
    return found;
}
