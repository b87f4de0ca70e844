/* lamprig — translucent radiosity: the part of a plane receiver a closed body stands on.
 *
 * A candle stands on the table: the table's cells under its foot are partly inside the body.
 * That part is not a surface: no light reaches it and none leaves it. Counted as surface, F's
 * rays from points inside the body all end on its inner faces (absorbed), the direct light's
 * points there are shadowed, and a cell half under the foot reads half the light its open half
 * gets: the bounce written bilinear between cell centres then darkens the table's ring around
 * the foot (the candle's foot read 0.78 of the reference, render/bounce/README.md).
 *
 * So a plane cell's quantities are over its open part: a point of a plane cell is covered
 * when it lies inside a surface marked `covers` (a closed body), told by the first hit of
 * that surface along the plane's normal being a back face (the ray leaves the body); F's
 * rows and E's means skip covered points, and the cell's open fraction (over F's own origin
 * points) lets a caller write the cells' values out weighted by it. With the cell's radiosity
 * over its open part, another cell's rays (which can only hit the open part) gather the
 * light the cell really sends: the reciprocity A_p f_p F_pq = A_q F_qp holds with the open
 * area A_p f_p. Only cells that overlap a covering body's bounds are tested. */
#include "render/transrad/tr_priv.h"

#include <math.h>
#include <stdlib.h>

#include "render/base/rng.h"

void lr_tr_ff_jitter(const lr_tr *t, size_t p, double j[4])
{
    lr_rng rng = lr_rng_init(lr_rng_key(t->set.seed, 0xF0F0, p, 0));
    for (int k = 0; k < 4; k++)
        j[k] = lr_rng_next(&rng);
}

/* Whether plane cell p's rectangle meets covering surface s's bounds (grown by the ray
 * offset): the box test of the cell's four corners' bounds against the body's. */
static bool cell_meets(const lr_tr *t, size_t p, int s, double eps)
{
    const lr_tr_patch *pa = &t->p[p];
    const lr_tr_surf *sf = &t->surf[pa->surface];
    double cw = sf->d.size_u / sf->nu, ch = sf->d.size_v / sf->nv;
    lr_vec3 lo, hi;
    lr_mesh_bounds(t->surf[s].d.mesh, &lo, &hi);
    double clo[3] = {INFINITY, INFINITY, INFINITY}, chi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int k = 0; k < 4; k++) {
        lr_vec3 x = lr_v3_add(pa->c, lr_v3_add(lr_v3_scale(sf->a, ((k & 1) - 0.5) * cw),
                                                lr_v3_scale(sf->b, ((k >> 1) - 0.5) * ch)));
        double c[3] = {x.x, x.y, x.z};
        for (int i = 0; i < 3; i++) {
            clo[i] = fmin(clo[i], c[i]);
            chi[i] = fmax(chi[i], c[i]);
        }
    }
    double blo[3] = {lo.x, lo.y, lo.z}, bhi[3] = {hi.x, hi.y, hi.z};
    for (int i = 0; i < 3; i++)
        if (chi[i] < blo[i] - 2 * eps || clo[i] > bhi[i] + 2 * eps)
            return false;
    return true;
}

bool lr_tr_point_covered(const lr_tr *t, size_t p, lr_vec3 x)
{
    if (!t->cover_check || !t->cover_check[p])
        return false;
    lr_vec3 n = t->p[p].n;
    double eps = lr_tr_eps(t);
    lr_vec3 o = lr_v3_add(x, lr_v3_scale(n, eps));
    for (int s = 0; s < t->nsurf; s++) {
        const lr_tr_surf *sf = &t->surf[s];
        if (!sf->d.covers || sf->d.kind == LR_TR_PLANE || s == t->p[p].surface)
            continue;
        lr_hit h;
        if (lr_bvh_intersect(sf->d.bvh, o, n, 0.0, INFINITY, &h) &&
            lr_v3_dot(lr_mesh_triangle_normal(sf->d.mesh, h.triangle), n) > 0)
            return true;
    }
    return false;
}

int lr_tr_build_cover(lr_tr *t, lr_err *e)
{
    bool any = false;
    for (int s = 0; s < t->nsurf; s++)
        any = any || (t->surf[s].d.covers && t->surf[s].d.kind != LR_TR_PLANE);
    if (!any || t->n == 0)
        return LR_OK;
    t->cover_check = calloc(t->n, sizeof *t->cover_check);
    t->open = malloc(t->n * sizeof *t->open);
    if (!t->cover_check || !t->open)
        return lr_err_set(e, LR_ENOMEM, "transrad: out of memory (covered cells)");
    double eps = lr_tr_eps(t);
    for (size_t p = 0; p < t->n; p++) {
        t->open[p] = 1;
        if (t->surf[t->p[p].surface].d.kind != LR_TR_PLANE)
            continue;
        for (int s = 0; s < t->nsurf && !t->cover_check[p]; s++)
            t->cover_check[p] = t->surf[s].d.covers && t->surf[s].d.kind != LR_TR_PLANE &&
                                cell_meets(t, p, s, eps);
        if (!t->cover_check[p])
            continue;
        /* Over F's own origin points (formfactor.c), so that the fraction is the one F's
         * rows were normalised by. */
        unsigned R = (unsigned)t->set.rays_per_patch, open = 0;
        double j[4];
        lr_tr_ff_jitter(t, p, j);
        for (unsigned k = 0; k < R; k++) {
            lr_vec3 x, n;
            lr_tr_patch_point(t, p, k, R, j[0], j[1], &x, &n);
            open += !lr_tr_point_covered(t, p, x);
        }
        t->open[p] = (double)open / R;
    }
    return LR_OK;
}

const double *lr_tr_open_fractions(const lr_tr *t) { return t ? t->open : NULL; }

double lr_tr_open_fraction(const lr_tr *t, size_t p)
{
    return t && t->open && p < t->n ? t->open[p] : 1.0;
}

bool lr_tr_plane_point_covered(const lr_tr *t, int s, double fu, double fv)
{
    if (!t || !t->cover_check || s < 0 || s >= t->nsurf || t->surf[s].d.kind != LR_TR_PLANE)
        return false;
    const lr_tr_surf *sf = &t->surf[s];
    int u = (int)floor(fu * sf->nu), v = (int)floor(fv * sf->nv);
    u = u < 0 ? 0 : u >= sf->nu ? sf->nu - 1 : u;
    v = v < 0 ? 0 : v >= sf->nv ? sf->nv - 1 : v;
    size_t p = sf->first + (size_t)v * (size_t)sf->nu + (size_t)u;
    lr_vec3 x = lr_v3_add(sf->d.center, lr_v3_add(lr_v3_scale(sf->a, (fu - 0.5) * sf->d.size_u),
                                                  lr_v3_scale(sf->b, (fv - 0.5) * sf->d.size_v)));
    return lr_tr_point_covered(t, p, x);
}
