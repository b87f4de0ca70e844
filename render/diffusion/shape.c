/* lamprig — shapes the diffusion grid is built over: sphere and slab (closed forms in the
 * tests) and closed meshes (through the BVH). */
#include <math.h>

#include "render/diffusion/dgrid.h"

static bool sphere_inside(const void *ctx, lr_vec3 p)
{
    const lr_dsphere *s = ctx;
    return lr_v3_len(lr_v3_sub(p, s->c)) < s->r;
}

static bool sphere_closest(const void *ctx, lr_vec3 p, double max_dist, lr_vec3 *b, lr_vec3 *n)
{
    const lr_dsphere *s = ctx;
    lr_vec3 d = lr_v3_sub(p, s->c);
    double l = lr_v3_len(d);
    lr_vec3 u = l > 0.0 ? lr_v3_scale(d, 1.0 / l) : lr_v3(0.0, 0.0, 1.0);
    *b = lr_v3_add(s->c, lr_v3_scale(u, s->r));
    *n = u;
    return fabs(l - s->r) <= max_dist;
}

lr_dshape lr_dshape_sphere(const lr_dsphere *s)
{
    lr_vec3 r = lr_v3(s->r, s->r, s->r);
    return (lr_dshape){sphere_inside, sphere_closest, s, lr_v3_sub(s->c, r), lr_v3_add(s->c, r),
                       NULL};
}

static bool slab_inside(const void *ctx, lr_vec3 p)
{
    const lr_dslab *s = ctx;
    return p.z > 0.0 && p.z < s->thickness;
}

static bool slab_closest(const void *ctx, lr_vec3 p, double max_dist, lr_vec3 *b, lr_vec3 *n)
{
    const lr_dslab *s = ctx;
    bool lower = p.z < 0.5 * s->thickness;
    *b = lr_v3(p.x, p.y, lower ? 0.0 : s->thickness);
    *n = lr_v3(0.0, 0.0, lower ? -1.0 : 1.0);
    return fabs(p.z - b->z) <= max_dist;
}

lr_dshape lr_dshape_slab(const lr_dslab *s)
{
    return (lr_dshape){slab_inside, slab_closest, s, lr_v3(0.0, 0.0, 0.0),
                       lr_v3(0.0, 0.0, s->thickness), NULL};
}

static bool box_inside(const void *ctx, lr_vec3 p)
{
    const lr_dbox *b = ctx;
    return p.x > b->lo.x && p.x < b->hi.x && p.y > b->lo.y && p.y < b->hi.y && p.z > b->lo.z &&
           p.z < b->hi.z;
}

static bool box_closest(const void *ctx, lr_vec3 p, double max_dist, lr_vec3 *out, lr_vec3 *n)
{
    const lr_dbox *b = ctx;
    double pc[3] = {p.x, p.y, p.z}, lo[3] = {b->lo.x, b->lo.y, b->lo.z},
           hi[3] = {b->hi.x, b->hi.y, b->hi.z}, q[3], nn[3] = {0, 0, 0};
    if (box_inside(ctx, p)) {
        /* the nearest face */
        int best = 0;
        double bd = INFINITY, side = 1.0;
        for (int a = 0; a < 3; a++) {
            if (pc[a] - lo[a] < bd)
                bd = pc[a] - lo[a], best = a, side = -1.0;
            if (hi[a] - pc[a] < bd)
                bd = hi[a] - pc[a], best = a, side = 1.0;
        }
        for (int a = 0; a < 3; a++)
            q[a] = pc[a];
        q[best] = side > 0 ? hi[best] : lo[best];
        nn[best] = side;
    } else {
        int best = 0;
        double worst = -1.0;
        for (int a = 0; a < 3; a++) {
            q[a] = fmin(hi[a], fmax(lo[a], pc[a]));
            double v = fabs(pc[a] - q[a]);
            if (v > worst)
                worst = v, best = a;
        }
        if (!(worst > 0.0)) {
            /* on the surface: the face it lies on */
            double bd = INFINITY;
            for (int a = 0; a < 3; a++) {
                double d = fmin(pc[a] - lo[a], hi[a] - pc[a]);
                if (d < bd)
                    bd = d, best = a;
            }
        }
        nn[best] = pc[best] >= 0.5 * (lo[best] + hi[best]) ? 1.0 : -1.0;
    }
    *out = lr_v3(q[0], q[1], q[2]);
    *n = lr_v3(nn[0], nn[1], nn[2]);
    return lr_v3_len(lr_v3_sub(p, *out)) <= max_dist;
}

lr_dshape lr_dshape_box(const lr_dbox *b)
{
    return (lr_dshape){box_inside, box_closest, b, b->lo, b->hi, NULL};
}

/* Parity of crossings along a direction tilted off the axes, so that a ray through a grid
 * column does not run along the mesh's (often axis-aligned) edges. */
static bool mesh_inside(const void *ctx, lr_vec3 p)
{
    const lr_bvh *bvh = ctx;
    const lr_vec3 d = lr_v3_normalize(lr_v3(0.0123456, 0.0078901, 1.0));
    double tmin = 0.0;
    int crossings = 0;
    lr_hit hit;
    while (crossings < 100000 && lr_bvh_intersect(bvh, p, d, tmin, INFINITY, &hit)) {
        crossings++;
        /* A ray through an edge hits both faces at the same t: step past it once. */
        tmin = hit.t + 1e-7 * (1.0 + hit.t);
    }
    return (crossings & 1) != 0;
}

static bool mesh_closest(const void *ctx, lr_vec3 p, double max_dist, lr_vec3 *b, lr_vec3 *n)
{
    const lr_bvh *bvh = ctx;
    lr_closest c;
    if (!lr_bvh_closest(bvh, p, max_dist, &c))
        return false;
    *b = c.point;
    *n = lr_mesh_triangle_normal(lr_bvh_mesh(bvh), c.triangle);
    return true;
}

static int mesh_column(const void *ctx, double x, double y, double *z, int max)
{
    const lr_bvh *bvh = ctx;
    lr_vec3 lo, hi;
    lr_mesh_bounds(lr_bvh_mesh(bvh), &lo, &hi);
    /* A hair off the node's column, so that a column through a vertex or an edge of a
     * generated mesh (revolved at regular angles) is not hit twice or grazed. */
    lr_vec3 o = lr_v3(x + 1.234567e-7 * (1.0 + fabs(x)), y + 7.654321e-8 * (1.0 + fabs(y)),
                      lo.z - 1.0);
    const lr_vec3 d = lr_v3(0.0, 0.0, 1.0);
    double tmin = 0.0;
    int n = 0;
    lr_hit hit;
    while (n < max && lr_bvh_intersect(bvh, o, d, tmin, INFINITY, &hit)) {
        z[n++] = o.z + hit.t;
        tmin = hit.t + 1e-9 * (1.0 + hit.t);
    }
    return n;
}

lr_dshape lr_dshape_mesh(const lr_bvh *bvh)
{
    lr_dshape s = {mesh_inside, mesh_closest, bvh, lr_v3(0, 0, 0), lr_v3(0, 0, 0), mesh_column};
    lr_mesh_bounds(lr_bvh_mesh(bvh), &s.lo, &s.hi);
    return s;
}
