/* lamprig — coarse-to-fine diffusion solve for one object, warm-started per light (dgrid.h).
 *
 * Seed 001 Sec. 5.3: solve on the coarsest grid, use its fluence to initialise the next finer
 * one, and so on to the finest; when the light or material changes gradually, the last frame's
 * solution initialises the finest grid directly. Each grid level is its own voxelisation of the
 * shape (spacing h 2^l), with the material sampled at its nodes.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/diffusion/dgrid.h"
#include "render/diffusion/dgrid_internal.h"

#define LR_DSOLVER_MAX_LEVELS 4

struct lr_dsolver {
    int levels;
    lr_dgrid *grid[LR_DSOLVER_MAX_LEVELS];          /* 0: finest */
    lr_dsystem *sys[LR_DSOLVER_MAX_LEVELS][3];
    double *phi[LR_DSOLVER_SLOTS][3];               /* finest level */
    bool has[LR_DSOLVER_SLOTS];
    int last_iters;
    const lr_cancel *cancel; /* polled by the solves (lr_dsolver_set_cancel) */
};

void lr_dsolver_destroy(lr_dsolver *s)
{
    if (!s)
        return;
    for (int l = 0; l < LR_DSOLVER_MAX_LEVELS; l++) {
        for (int c = 0; c < 3; c++)
            lr_dsystem_destroy(s->sys[l][c]);
        lr_dgrid_destroy(s->grid[l]);
    }
    for (int k = 0; k < LR_DSOLVER_SLOTS; k++)
        for (int c = 0; c < 3; c++)
            free(s->phi[k][c]);
    free(s);
}

static int set_material(lr_dsystem *sys, const lr_dgrid *g, const lr_dmaterial *m, int band,
                        lr_err *e)
{
    size_t n = lr_dgrid_inside_count(g);
    double *D = malloc(2 * n * sizeof *D);
    if (!D)
        return lr_err_set(e, LR_ENOMEM, "diffusion solver: out of memory");
    double *mu = D + n;
    for (size_t p = 0; p < n; p++) {
        double sa[3], ss[3];
        if (m->volume) {
            lr_dvolume_at(m->volume, lr_dgrid_param_pos(g, p), sa, ss);
        } else {
            memcpy(sa, m->sigma_a, sizeof sa);
            memcpy(ss, m->sigma_s_prime, sizeof ss);
        }
        /* D = 1 / (3 sigma_t'), mu = sigma_a (seed 001 Sec. 3). */
        D[p] = 1.0 / (3.0 * (sa[band] + ss[band]));
        mu[p] = sa[band];
    }
    int rc = lr_dsystem_set_params(sys, D, mu, e);
    free(D);
    return rc;
}

int lr_dsolver_create(const lr_dshape *shape, double h, int levels, const lr_dmaterial *m,
                      lr_dsolver **out, lr_err *e)
{
    *out = NULL;
    if (levels < 1 || levels > LR_DSOLVER_MAX_LEVELS)
        return lr_err_set(e, LR_EINVAL, "diffusion solver: levels = %d: must be 1..%d", levels,
                          LR_DSOLVER_MAX_LEVELS);
    if (!m)
        return lr_err_set(e, LR_EINVAL, "diffusion solver: no material");
    if (!m->volume)
        for (int c = 0; c < 3; c++)
            if (!isfinite(m->sigma_a[c]) || m->sigma_a[c] < 0.0 || !isfinite(m->sigma_s_prime[c]) ||
                !(m->sigma_a[c] + m->sigma_s_prime[c] > 0.0))
                return lr_err_set(e, LR_EINVAL,
                                  "diffusion solver: band %d: sigma_a = %g, sigma_s' = %g", c,
                                  m->sigma_a[c], m->sigma_s_prime[c]);
    lr_dsolver *s = calloc(1, sizeof *s);
    if (!s)
        return lr_err_set(e, LR_ENOMEM, "diffusion solver: out of memory");
    int rc = LR_OK;
    for (int l = 0; l < levels && !rc; l++) {
        lr_err sub = {0};
        rc = lr_dgrid_create(shape, h * (double)(1 << l), &s->grid[l], &sub);
        if (rc) {
            if (l == 0) {
                if (e)
                    *e = sub;
                break;
            }
            rc = LR_OK; /* a coarse level with no inside node: fewer levels */
            break;
        }
        s->levels = l + 1;
        /* The system's pattern and terms do not depend on the band's coefficients: assembled
         * once, copied for the other two (a third of the cold build, which dominates it:
         * candle 1.3 s -> 0.6 s with the row-wise sort of system.c). */
        for (int c = 0; c < 3 && !rc; c++) {
            rc = c == 0 ? lr_dsystem_create(s->grid[l], m->eta, &s->sys[l][c], e)
                        : lr_dsystem_clone(s->sys[l][0], &s->sys[l][c], e);
            if (!rc)
                rc = set_material(s->sys[l][c], s->grid[l], m, c, e);
        }
    }
    size_t n = s->grid[0] ? lr_dgrid_unknown_count(s->grid[0]) : 0;
    for (int k = 0; k < LR_DSOLVER_SLOTS && !rc; k++)
        for (int c = 0; c < 3 && !rc; c++)
            if (!(s->phi[k][c] = calloc(n ? n : 1, sizeof(double))))
                rc = lr_err_set(e, LR_ENOMEM, "diffusion solver: out of memory");
    if (rc) {
        lr_dsolver_destroy(s);
        return rc;
    }
    *out = s;
    return LR_OK;
}

int lr_dsolver_set_material(lr_dsolver *s, const lr_dmaterial *m, lr_err *e)
{
    for (int l = 0; l < s->levels; l++)
        for (int c = 0; c < 3; c++) {
            int rc = set_material(s->sys[l][c], s->grid[l], m, c, e);
            if (rc)
                return rc;
        }
    return LR_OK;
}

const lr_dgrid *lr_dsolver_grid(const lr_dsolver *s) { return s->grid[0]; }
const lr_dsystem *lr_dsolver_system(const lr_dsolver *s, int band) { return s->sys[0][band]; }
const double *lr_dsolver_phi(const lr_dsolver *s, int slot, int band)
{
    return s->phi[slot][band];
}
int lr_dsolver_last_iters(const lr_dsolver *s) { return s->last_iters; }
void lr_dsolver_set_cancel(lr_dsolver *s, const lr_cancel *cancel) { s->cancel = cancel; }

void lr_dsolver_reset(lr_dsolver *s, int slot)
{
    if (slot >= 0 && slot < LR_DSOLVER_SLOTS)
        s->has[slot] = false;
}

/* The right-hand side per band: the source at the ghosts' surface points (one evaluation per
 * ghost for the three bands). */
static int ghost_rhs(const lr_dsystem *const sys[3], lr_dirradiance_rgb_fn q, const void *qctx,
                     double *rhs[3], lr_err *e)
{
    const lr_dgrid *g = lr_dsystem_grid(sys[0]);
    size_t ng = lr_dgrid_ghost_count(g);
    double *qg[3];
    for (int c = 0; c < 3; c++)
        qg[c] = malloc((ng ? ng : 1) * sizeof *qg[c]);
    if (!qg[0] || !qg[1] || !qg[2]) {
        for (int c = 0; c < 3; c++)
            free(qg[c]);
        return lr_err_set(e, LR_ENOMEM, "diffusion solver: out of memory");
    }
    for (size_t k = 0; k < ng; k++) {
        lr_vec3 b, n;
        size_t u;
        lr_dgrid_ghost_at(g, k, &b, &n, &u);
        double v[3];
        q(qctx, b, n, v);
        for (int c = 0; c < 3; c++)
            qg[c][k] = isfinite(v[c]) && v[c] >= 0.0 ? v[c] : 0.0;
    }
    for (int c = 0; c < 3; c++) {
        lr_dsystem_rhs(sys[c], qg[c], rhs[c]);
        free(qg[c]);
    }
    return LR_OK;
}

int lr_dsolver_solve(lr_dsolver *s, int slot, lr_dirradiance_fn q, const void *qctx, double tol,
                     lr_err *e)
{
    lr_dgrey g = {q, qctx};
    return lr_dsolver_solve_rgb(s, slot, lr_dgrey_q, &g, tol, e);
}

int lr_dsolver_solve_rgb(lr_dsolver *s, int slot, lr_dirradiance_rgb_fn q, const void *qctx,
                         double tol, lr_err *e)
{
    if (slot < 0 || slot >= LR_DSOLVER_SLOTS)
        return lr_err_set(e, LR_EINVAL, "diffusion solver: slot %d out of range", slot);
    if (!(tol > 0.0) || !(tol < 1.0))
        return lr_err_set(e, LR_EINVAL, "diffusion solver: tol = %g: must be in (0, 1)", tol);
    s->last_iters = 0;
    int first = s->has[slot] ? 0 : s->levels - 1;
    bool fine_started = false;
    double *xs[LR_DSOLVER_MAX_LEVELS] = {0}, *rhs[LR_DSOLVER_MAX_LEVELS][3] = {{0}};
    int rc = LR_OK;
    /* The right-hand side (the incident light at the ghosts' surface points, one ray cast
     * each for a light) once per level for the three bands. */
    for (int l = first; l >= 0 && !rc; l--) {
        for (int c = 0; c < 3 && !rc; c++)
            if (!(rhs[l][c] = malloc(lr_dgrid_unknown_count(s->grid[l]) * sizeof *rhs[l][c])))
                rc = lr_err_set(e, LR_ENOMEM, "diffusion solver: out of memory");
        if (!rc)
            rc = ghost_rhs((const lr_dsystem *const[3]){s->sys[l][0], s->sys[l][1], s->sys[l][2]},
                           q, qctx, rhs[l], e);
    }
    for (int c = 0; c < 3 && !rc; c++) {
        double *prev = NULL;
        for (int l = first; l >= 0 && !rc; l--) {
            const lr_dgrid *g = s->grid[l];
            size_t n = lr_dgrid_unknown_count(g);
            double *x = l == 0 ? s->phi[slot][c] : calloc(n, sizeof *x);
            if (!x) {
                rc = lr_err_set(e, LR_ENOMEM, "diffusion solver: out of memory");
                break;
            }
            if (l != 0)
                xs[l] = x;
            if (prev) {
                /* Prolongation: the coarser fluence, trilinear, at this level's unknowns. */
                for (size_t u = 0; u < n; u++)
                    x[u] = lr_dgrid_sample(s->grid[l + 1], prev,
                                           lr_dgrid_node_pos(g, lr_dgrid_unknown_node(g, u)));
            } else if (l != 0 || !s->has[slot]) {
                memset(x, 0, n * sizeof *x);
            }
            int it = 0;
            if (l == 0)
                fine_started = true;
            rc = lr_dsystem_solve_cancel(s->sys[l][c], false, rhs[l][c], x,
                                         l == 0 ? tol : fmax(tol, 1e-3), 20000, &it, s->cancel,
                                         e);
            if (l == 0)
                s->last_iters += it;
            prev = x;
        }
        for (int l = 1; l < LR_DSOLVER_MAX_LEVELS; l++) {
            free(xs[l]);
            xs[l] = NULL;
        }
    }
    for (int l = 0; l < LR_DSOLVER_MAX_LEVELS; l++)
        for (int c = 0; c < 3; c++)
            free(rhs[l][c]);
    /* A cut solve's fluence is a partial iterate, not a solution, but a fine start for the
     * next solve (BiCGSTAB takes any guess; this one is nearer the new state than the last
     * solution was): kept as the warm start when the finest level was reached or the slot had
     * one. A failed solve forgets the slot. */
    if (rc == LR_ECANCELED)
        s->has[slot] = s->has[slot] || fine_started;
    else
        s->has[slot] = rc == LR_OK;
    if (rc && rc != LR_ECANCELED)
        lr_err_prefix(e, "diffusion solver");
    return rc;
}
