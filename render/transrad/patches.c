/* lamprig — translucent radiosity: patches, points on them, rays against every surface.
 *
 * Mesh surfaces are clustered: a triangle joins the patch of the cubic cell (edge patch_mm) its
 * centroid falls in and of the dominant signed axis of its normal, so that the two faces of a
 * thin wall (opposite normals) never share a patch while a smooth face is cut into patches of
 * about patch_mm. Planes are a grid of cells. Seed 000 uses the mesh's polygons as patches;
 * clustering keeps the dense matrices of a finely tessellated object at a fixed size. */
#include "render/transrad/tr_priv.h"

#include <math.h>
#include <stdlib.h>

#include "render/optics/optics.h"

typedef struct tri_key {
    uint64_t key;
    size_t tri;
} tri_key;

static int key_cmp(const void *a, const void *b)
{
    const tri_key *x = a, *y = b;
    if (x->key != y->key)
        return x->key < y->key ? -1 : 1;
    return x->tri < y->tri ? -1 : x->tri > y->tri;
}

static int axis_bucket(lr_vec3 n)
{
    double ax = fabs(n.x), ay = fabs(n.y), az = fabs(n.z);
    if (ax >= ay && ax >= az)
        return n.x >= 0 ? 0 : 1;
    if (ay >= az)
        return n.y >= 0 ? 2 : 3;
    return n.z >= 0 ? 4 : 5;
}

static int cluster_mesh(lr_tr *t, int s, size_t *np_out, lr_tr_patch **pp, size_t *cap,
                        size_t *tri_used, lr_err *e)
{
    lr_tr_surf *sf = &t->surf[s];
    const lr_mesh *m = sf->d.mesh;
    size_t nt = lr_mesh_triangle_count(m);
    double h = sf->d.patch_mm > 0 ? sf->d.patch_mm : t->set.patch_mm;
    lr_vec3 lo, hi;
    lr_mesh_bounds(m, &lo, &hi);
    tri_key *k = malloc(nt * sizeof *k);
    sf->tri_patch = malloc(nt * sizeof *sf->tri_patch);
    if (!k || !sf->tri_patch) {
        free(k);
        return lr_err_set(e, LR_ENOMEM, "transrad: surface %d: out of memory (%zu triangles)",
                          s, nt);
    }
    for (size_t i = 0; i < nt; i++) {
        lr_vec3 p[3];
        lr_mesh_triangle(m, i, p);
        lr_vec3 c = lr_v3_scale(lr_v3_add(lr_v3_add(p[0], p[1]), p[2]), 1.0 / 3.0);
        uint64_t ix = (uint64_t)floor((c.x - lo.x) / h) & 0xFFFFF;
        uint64_t iy = (uint64_t)floor((c.y - lo.y) / h) & 0xFFFFF;
        uint64_t iz = (uint64_t)floor((c.z - lo.z) / h) & 0xFFFFF;
        uint64_t b = (uint64_t)axis_bucket(lr_mesh_triangle_normal(m, i));
        k[i] = (tri_key){(ix << 43) | (iy << 23) | (iz << 3) | b, i};
    }
    qsort(k, nt, sizeof *k, key_cmp);
    sf->first = *np_out;
    for (size_t i = 0; i < nt;) {
        size_t j = i;
        while (j < nt && k[j].key == k[i].key)
            j++;
        if (*np_out == *cap) {
            size_t nc = *cap ? 2 * *cap : 256;
            lr_tr_patch *np = realloc(*pp, nc * sizeof *np);
            if (!np) {
                free(k);
                return lr_err_set(e, LR_ENOMEM, "transrad: out of memory (patches)");
            }
            *pp = np;
            *cap = nc;
        }
        lr_tr_patch *pa = &(*pp)[*np_out];
        *pa = (lr_tr_patch){.surface = s, .tri0 = *tri_used, .ntri = j - i};
        lr_vec3 cs = lr_v3(0, 0, 0), ns = lr_v3(0, 0, 0);
        for (size_t q = i; q < j; q++) {
            size_t tri = k[q].tri;
            lr_vec3 p[3];
            lr_mesh_triangle(m, tri, p);
            double a = lr_mesh_triangle_area(m, tri);
            lr_vec3 c = lr_v3_scale(lr_v3_add(lr_v3_add(p[0], p[1]), p[2]), 1.0 / 3.0);
            cs = lr_v3_add(cs, lr_v3_scale(c, a));
            ns = lr_v3_add(ns, lr_v3_scale(lr_mesh_triangle_normal(m, tri), a));
            pa->area += a;
            t->tris[(*tri_used)++] = tri;
            sf->tri_patch[tri] = *np_out;
        }
        pa->c = lr_v3_scale(cs, 1.0 / pa->area);
        pa->n = lr_v3_len(ns) > 0 ? lr_v3_normalize(ns) : lr_mesh_triangle_normal(m, k[i].tri);
        (*np_out)++;
        i = j;
    }
    sf->count = *np_out - sf->first;
    free(k);
    return LR_OK;
}

static int grid_plane(lr_tr *t, int s, size_t *np_out, lr_tr_patch **pp, size_t *cap,
                      lr_err *e)
{
    lr_tr_surf *sf = &t->surf[s];
    const lr_tr_surface_desc *d = &sf->d;
    lr_vec3 n = lr_v3_normalize(d->normal);
    lr_vec3 a = lr_v3_sub(d->u_dir, lr_v3_scale(n, lr_v3_dot(d->u_dir, n)));
    if (!(lr_v3_len(a) > 1e-9) || !(d->size_u > 0) || !(d->size_v > 0))
        return lr_err_set(e, LR_EINVAL,
                          "transrad: surface %d: field 'u_dir'/'size': a plane needs a "
                          "direction off its normal and positive sizes", s);
    sf->a = lr_v3_normalize(a);
    sf->b = lr_v3_cross(n, sf->a);
    double h = d->patch_mm > 0 ? d->patch_mm : t->set.receiver_mm;
    sf->nu = d->cells_u > 0 ? d->cells_u : (int)ceil(d->size_u / h);
    sf->nv = d->cells_v > 0 ? d->cells_v : (int)ceil(d->size_v / h);
    sf->nu = sf->nu < 1 ? 1 : sf->nu > 64 ? 64 : sf->nu;
    sf->nv = sf->nv < 1 ? 1 : sf->nv > 64 ? 64 : sf->nv;
    size_t cnt = (size_t)sf->nu * (size_t)sf->nv;
    if (*np_out + cnt > *cap) {
        size_t nc = *np_out + cnt + 256;
        lr_tr_patch *np = realloc(*pp, nc * sizeof *np);
        if (!np)
            return lr_err_set(e, LR_ENOMEM, "transrad: out of memory (patches)");
        *pp = np;
        *cap = nc;
    }
    sf->first = *np_out;
    double cw = d->size_u / sf->nu, ch = d->size_v / sf->nv;
    for (int v = 0; v < sf->nv; v++)
        for (int u = 0; u < sf->nu; u++) {
            lr_tr_patch *pa = &(*pp)[(*np_out)++];
            lr_vec3 c = lr_v3_add(d->center,
                                  lr_v3_add(lr_v3_scale(sf->a, ((u + 0.5) * cw - d->size_u / 2)),
                                            lr_v3_scale(sf->b, ((v + 0.5) * ch - d->size_v / 2))));
            *pa = (lr_tr_patch){.c = c, .n = n, .area = cw * ch, .surface = s, .cu = u, .cv = v};
        }
    sf->count = cnt;
    return LR_OK;
}

int lr_tr_build_patches(lr_tr *t, lr_err *e)
{
    size_t total_tris = 0;
    for (int s = 0; s < t->nsurf; s++)
        if (t->surf[s].d.kind != LR_TR_PLANE)
            total_tris += lr_mesh_triangle_count(t->surf[s].d.mesh);
    t->tris = malloc((total_tris ? total_tris : 1) * sizeof *t->tris);
    if (!t->tris)
        return lr_err_set(e, LR_ENOMEM, "transrad: out of memory (triangles)");
    size_t np = 0, cap = 0, used = 0;
    lr_tr_patch *p = NULL;
    for (int s = 0; s < t->nsurf; s++) {
        int rc = t->surf[s].d.kind == LR_TR_PLANE ? grid_plane(t, s, &np, &p, &cap, e)
                                                   : cluster_mesh(t, s, &np, &p, &cap, &used, e);
        if (rc) {
            free(p);
            return rc;
        }
    }
    t->p = p;
    t->n = np;
    return LR_OK;
}

void lr_tr_patch_point(const lr_tr *t, size_t pi, unsigned k, unsigned m, double ju, double jv,
                       lr_vec3 *x, lr_vec3 *n)
{
    const lr_tr_patch *p = &t->p[pi];
    const lr_tr_surf *sf = &t->surf[p->surface];
    double s = (k + ju) / m;
    double r2 = lr_halton(k + 1, 3) + jv;
    r2 -= floor(r2);
    if (sf->d.kind == LR_TR_PLANE) {
        double cw = sf->d.size_u / sf->nu, ch = sf->d.size_v / sf->nv;
        *x = lr_v3_add(p->c, lr_v3_add(lr_v3_scale(sf->a, (s - 0.5) * cw),
                                       lr_v3_scale(sf->b, (r2 - 0.5) * ch)));
        *n = p->n;
        return;
    }
    /* Choose the triangle by cumulative area at s, reuse the remainder of s inside it. */
    const lr_mesh *mesh = sf->d.mesh;
    double target = s * p->area, acc = 0;
    size_t tri = t->tris[p->tri0];
    double r1 = s;
    for (size_t i = 0; i < p->ntri; i++) {
        size_t ti = t->tris[p->tri0 + i];
        double a = lr_mesh_triangle_area(mesh, ti);
        tri = ti;
        if (acc + a >= target || i + 1 == p->ntri) {
            r1 = a > 0 ? (target - acc) / a : 0.5;
            break;
        }
        acc += a;
    }
    r1 = r1 < 0 ? 0 : r1 > 1 ? 1 : r1;
    lr_vec3 q[3];
    lr_mesh_triangle(mesh, tri, q);
    double su = sqrt(r1);
    double b0 = 1 - su, b1 = su * (1 - r2), b2 = su * r2;
    *x = lr_v3_add(lr_v3_add(lr_v3_scale(q[0], b0), lr_v3_scale(q[1], b1)), lr_v3_scale(q[2], b2));
    *n = lr_mesh_triangle_normal(mesh, tri);
}

size_t lr_tr_patch_of(const lr_tr *t, int s, size_t triangle, lr_vec3 x)
{
    const lr_tr_surf *sf = &t->surf[s];
    if (sf->d.kind != LR_TR_PLANE)
        return sf->tri_patch[triangle];
    lr_vec3 r = lr_v3_sub(x, sf->d.center);
    double u = (lr_v3_dot(r, sf->a) / sf->d.size_u + 0.5) * sf->nu;
    double v = (lr_v3_dot(r, sf->b) / sf->d.size_v + 0.5) * sf->nv;
    int iu = (int)floor(u), iv = (int)floor(v);
    iu = iu < 0 ? 0 : iu >= sf->nu ? sf->nu - 1 : iu;
    iv = iv < 0 ? 0 : iv >= sf->nv ? sf->nv - 1 : iv;
    return sf->first + (size_t)iv * (size_t)sf->nu + (size_t)iu;
}

bool lr_tr_trace(const lr_tr *t, lr_vec3 o, lr_vec3 d, double tmax, size_t *patch, double *dist)
{
    double best = tmax;
    int bs = -1;
    lr_hit bh = {0};
    for (int s = 0; s < t->nsurf; s++) {
        lr_hit h;
        if (lr_bvh_intersect(t->surf[s].d.bvh, o, d, 0.0, best, &h) && h.t <= best) {
            best = h.t;
            bs = s;
            bh = h;
        }
    }
    if (bs < 0)
        return false;
    *dist = best;
    const lr_mesh *m = t->surf[bs].d.mesh;
    lr_vec3 x = lr_v3_add(o, lr_v3_scale(d, best));
    if (lr_v3_dot(lr_mesh_triangle_normal(m, bh.triangle), d) >= 0) {
        /* A back face: a one-sided receiver seen from behind, or a wall reached from inside
         * its material; it absorbs. */
        *patch = SIZE_MAX;
        return true;
    }
    *patch = lr_tr_patch_of(t, bs, bh.triangle, x);
    return true;
}

bool lr_tr_occluded(const lr_tr *t, lr_vec3 o, lr_vec3 d, double tmax)
{
    for (int s = 0; s < t->nsurf; s++)
        if (lr_bvh_occluded(t->surf[s].d.bvh, o, d, 0.0, tmax))
            return true;
    return false;
}

double lr_tr_eps(const lr_tr *t)
{
    double ext = 0;
    for (int s = 0; s < t->nsurf; s++) {
        lr_vec3 lo, hi;
        lr_mesh_bounds(t->surf[s].d.mesh, &lo, &hi);
        double l = lr_v3_len(lr_v3_sub(hi, lo));
        ext = l > ext ? l : ext;
    }
    return 2e-5 * (ext > 1 ? ext : 1);
}
