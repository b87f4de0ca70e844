#include "calib/nelder_mead.h"

#include <math.h>
#include <string.h>

enum { INIT, REFLECT, EXPAND, CONTRACT_OUT, CONTRACT_IN, SHRINK };

static void sort_simplex(lr_nm *nm)
{
    for (int i = 1; i <= nm->n; i++)
        for (int j = i; j > 0 && nm->f[j] < nm->f[j - 1]; j--) {
            double t = nm->f[j];
            nm->f[j] = nm->f[j - 1];
            nm->f[j - 1] = t;
            double tx[LR_NM_MAX_DIM];
            memcpy(tx, nm->x[j], sizeof tx);
            memcpy(nm->x[j], nm->x[j - 1], sizeof tx);
            memcpy(nm->x[j - 1], tx, sizeof tx);
        }
}

static void build(lr_nm *nm, const double *x0)
{
    for (int i = 0; i <= nm->n; i++) {
        memcpy(nm->x[i], x0, sizeof(double) * (size_t)nm->n);
        if (i > 0)
            nm->x[i][i - 1] += nm->step[i - 1];
        nm->f[i] = INFINITY;
    }
    nm->phase = INIT;
    nm->k = 0;
}

void lr_nm_init(lr_nm *nm, int n, const double *x0, const double *step, double ftol,
                double xtol, int max_evals, int max_restarts)
{
    memset(nm, 0, sizeof *nm);
    nm->n = n < 1 ? 1 : n > LR_NM_MAX_DIM ? LR_NM_MAX_DIM : n;
    memcpy(nm->step, step, sizeof(double) * (size_t)nm->n);
    nm->ftol = ftol;
    nm->xtol = xtol;
    nm->max_evals = max_evals;
    nm->max_restarts = max_restarts;
    nm->f_restart = INFINITY;
    build(nm, x0);
}

/* A point c + t (p - c). */
static void along(const lr_nm *nm, const double *p, double t, double *out)
{
    for (int i = 0; i < nm->n; i++)
        out[i] = nm->c[i] + t * (p[i] - nm->c[i]);
}

static bool converged(const lr_nm *nm)
{
    double spread = nm->f[nm->n] - nm->f[0];
    if (!(spread <= nm->ftol * (fabs(nm->f[0]) + nm->ftol)))
        return false;
    for (int i = 1; i <= nm->n; i++)
        for (int d = 0; d < nm->n; d++)
            if (fabs(nm->x[i][d] - nm->x[0][d]) > nm->xtol)
                return false;
    return true;
}

/* Starts an iteration from a sorted simplex: convergence / restart, else the reflection. */
static void next_iteration(lr_nm *nm)
{
    sort_simplex(nm);
    nm->iterations++;
    if (nm->evals >= nm->max_evals) {
        nm->done = true;
        return;
    }
    if (converged(nm)) {
        /* a restart that did not help ends the run */
        bool improved = nm->f[0] < nm->f_restart - nm->ftol * (fabs(nm->f_restart) + nm->ftol);
        if (!improved || nm->restarts >= nm->max_restarts) {
            nm->done = true;
            return;
        }
        nm->restarts++;
        nm->f_restart = nm->f[0];
        double best[LR_NM_MAX_DIM], fb = nm->f[0];
        memcpy(best, nm->x[0], sizeof best);
        build(nm, best);
        nm->f[0] = fb; /* already known */
        nm->k = 1;
        return;
    }
    for (int d = 0; d < nm->n; d++) {
        nm->c[d] = 0;
        for (int i = 0; i < nm->n; i++)
            nm->c[d] += nm->x[i][d] / nm->n;
    }
    along(nm, nm->x[nm->n], -1, nm->trial);
    nm->phase = REFLECT;
}

bool lr_nm_ask(lr_nm *nm, double *x)
{
    if (nm->done)
        return false;
    if (nm->phase == INIT || nm->phase == SHRINK)
        memcpy(x, nm->x[nm->k], sizeof(double) * (size_t)nm->n);
    else
        memcpy(x, nm->trial, sizeof(double) * (size_t)nm->n);
    return true;
}

static void replace_worst(lr_nm *nm, const double *x, double f)
{
    memcpy(nm->x[nm->n], x, sizeof(double) * (size_t)nm->n);
    nm->f[nm->n] = f;
    next_iteration(nm);
}

static void start_shrink(lr_nm *nm)
{
    for (int i = 1; i <= nm->n; i++)
        for (int d = 0; d < nm->n; d++)
            nm->x[i][d] = nm->x[0][d] + 0.5 * (nm->x[i][d] - nm->x[0][d]);
    nm->phase = SHRINK;
    nm->k = 1;
}

void lr_nm_tell(lr_nm *nm, double f)
{
    if (nm->done)
        return;
    if (!isfinite(f))
        f = INFINITY;
    nm->evals++;
    int n = nm->n;
    switch (nm->phase) {
    case INIT:
    case SHRINK:
        nm->f[nm->k++] = f;
        if (nm->k > n) {
            next_iteration(nm);
        } else if (nm->evals >= nm->max_evals) {
            nm->done = true;
        }
        break;
    case REFLECT:
        memcpy(nm->xr, nm->trial, sizeof nm->xr);
        nm->fr = f;
        if (f < nm->f[0]) {
            along(nm, nm->x[n], -2, nm->trial);
            nm->phase = EXPAND;
        } else if (f < nm->f[n - 1]) {
            replace_worst(nm, nm->xr, f);
        } else if (f < nm->f[n]) {
            along(nm, nm->xr, 0.5, nm->trial);
            nm->phase = CONTRACT_OUT;
        } else {
            along(nm, nm->x[n], 0.5, nm->trial);
            nm->phase = CONTRACT_IN;
        }
        break;
    case EXPAND:
        if (f < nm->fr)
            replace_worst(nm, nm->trial, f);
        else
            replace_worst(nm, nm->xr, nm->fr);
        break;
    case CONTRACT_OUT:
        if (f <= nm->fr)
            replace_worst(nm, nm->trial, f);
        else
            start_shrink(nm);
        break;
    case CONTRACT_IN:
        if (f < nm->f[n])
            replace_worst(nm, nm->trial, f);
        else
            start_shrink(nm);
        break;
    }
}

double lr_nm_best(const lr_nm *nm, double *x)
{
    int b = 0;
    for (int i = 1; i <= nm->n; i++)
        if (nm->f[i] < nm->f[b])
            b = i;
    if (x)
        memcpy(x, nm->x[b], sizeof(double) * (size_t)nm->n);
    return nm->f[b];
}
