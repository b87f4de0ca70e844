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
    lr_vec3 x = lr_v3_add(o, lr_v3_scale(d, dist));
    lr_vec3 r = lr_v3_sub(x, sf->d.center);
    size_t cell[4];
    double w[4];
    lr_tr_plane_cells(lr_v3_dot(r, sf->a) / sf->d.size_u + 0.5,
                      lr_v3_dot(r, sf->b) / sf->d.size_v + 0.5, sf->nu, sf->nv,
                      t->open ? t->open + sf->first : NULL, cell, w);
    for (int k = 0; k < 4; k++) {
        if (!(w[k] > 0.0))
            continue;
        h->patch[h->n] = sf->first + cell[k];
        h->w[h->n++] = w[k];
    }
    return true;
}

double lr_tr_ray_eps(const lr_tr *t) { return lr_tr_eps(t); }

void lr_tr_plane_cells(double fu, double fv, int nu, int nv, const double *open, size_t cell[4],
                       double w[4])
{
    double u = fu * nu - 0.5, v = fv * nv - 0.5;
    u = u < 0 ? 0 : u > nu - 1 ? nu - 1 : u;
    v = v < 0 ? 0 : v > nv - 1 ? nv - 1 : v;
    int u0 = (int)floor(u), v0 = (int)floor(v);
    int u1 = u0 + 1 < nu ? u0 + 1 : u0, v1 = v0 + 1 < nv ? v0 + 1 : v0;
    double du = u - u0, dv = v - v0, ws = 0;
    const int cu[4] = {u0, u1, u0, u1}, cv[4] = {v0, v0, v1, v1};
    const double b[4] = {(1 - du) * (1 - dv), du * (1 - dv), (1 - du) * dv, du * dv};
    for (int k = 0; k < 4; k++) {
        cell[k] = (size_t)cv[k] * (size_t)nu + (size_t)cu[k];
        /* A cell mostly under a body's foot holds its open part's mean over little area, so
         * it pulls the points around it in proportion (cover.c). */
        w[k] = b[k] * (open ? open[cell[k]] : 1.0);
        ws += w[k];
    }
    for (int k = 0; k < 4; k++)
        w[k] = ws > 0 ? w[k] / ws : 0;
}
