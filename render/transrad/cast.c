/* lamprig — translucent radiosity: a ray's first hit for callers outside the solver
 * (render/bounce/objlight.c: the receivers' light on the objects), through the solver's own
 * ray caster (lr_tr_trace, patches.c) so that visibility is the same as F's. */
#include "render/transrad/tr_priv.h"

#include <math.h>

bool lr_tr_cast(const lr_tr *t, lr_vec3 o, lr_vec3 d, lr_tr_cast_hit *h)
{
    h->n = 0;
    h->surface = -1;
    size_t q;
    double dist;
    if (!t || !lr_tr_trace(t, o, d, INFINITY, &q, &dist))
        return false;
    h->dist = dist;
    if (q == SIZE_MAX)
        return true; /* a back face: absorbed */
    const lr_tr_patch *p = &t->p[q];
    const lr_tr_surf *sf = &t->surf[p->surface];
    h->surface = p->surface;
    if (sf->d.kind != LR_TR_PLANE) {
        h->n = 1;
        h->patch[0] = q;
        h->w[0] = 1.0;
        return true;
    }
    /* Bilinear between the cells' centres, clamped at the plane's edges, the weights scaled
     * by the cells' open fractions (as lr_tr_plane_to_grid writes the receivers' grid: a cell
     * under a body's foot holds its open part's value over little area, cover.c). */
    lr_vec3 x = lr_v3_add(o, lr_v3_scale(d, dist));
    lr_vec3 r = lr_v3_sub(x, sf->d.center);
    double u = (lr_v3_dot(r, sf->a) / sf->d.size_u + 0.5) * sf->nu - 0.5;
    double v = (lr_v3_dot(r, sf->b) / sf->d.size_v + 0.5) * sf->nv - 0.5;
    u = u < 0 ? 0 : u > sf->nu - 1 ? sf->nu - 1 : u;
    v = v < 0 ? 0 : v > sf->nv - 1 ? sf->nv - 1 : v;
    int u0 = (int)floor(u), v0 = (int)floor(v);
    int u1 = u0 + 1 < sf->nu ? u0 + 1 : u0, v1 = v0 + 1 < sf->nv ? v0 + 1 : v0;
    double fu = u - u0, fv = v - v0;
    int cu[4] = {u0, u1, u0, u1}, cv[4] = {v0, v0, v1, v1};
    double w[4] = {(1 - fu) * (1 - fv), fu * (1 - fv), (1 - fu) * fv, fu * fv}, ws = 0;
    size_t pk[4];
    for (int k = 0; k < 4; k++) {
        pk[k] = sf->first + (size_t)cv[k] * (size_t)sf->nu + (size_t)cu[k];
        w[k] *= t->open ? t->open[pk[k]] : 1.0;
        ws += w[k];
    }
    for (int k = 0; k < 4; k++) {
        if (!(w[k] > 0.0))
            continue;
        h->patch[h->n] = pk[k];
        h->w[h->n++] = w[k] / ws;
    }
    return true;
}

double lr_tr_ray_eps(const lr_tr *t) { return lr_tr_eps(t); }
