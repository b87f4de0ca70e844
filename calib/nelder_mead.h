/* lamprig calib — Nelder-Mead downhill simplex (Nelder & Mead 1965; the standard
 * coefficients reflection 1, expansion 2, contraction 1/2, shrink 1/2, as in Lagarias et al.
 * 1998) in reverse-communication form: the caller asks for the next point, evaluates it and
 * tells the value. This lets the material fit run one optimiser per colour band in lockstep
 * and evaluate all three bands' proposals with one render (the bands are independent in the
 * model, so each band's objective only depends on its own parameters).
 *
 * Restarts: when the simplex has converged (spread of values below ftol x (|f_best| + ftol)
 * and every edge below xtol) it is rebuilt around the best point with the initial step
 * (a stalled or collapsed simplex is the known failure of the method, Lagarias et al.);
 * the run ends when a restart does not improve f_best by more than ftol relative, after
 * max_restarts restarts, or after max_evals evaluations.
 */
#ifndef LR_CALIB_NELDER_MEAD_H
#define LR_CALIB_NELDER_MEAD_H

#include <stdbool.h>

#define LR_NM_MAX_DIM 4

typedef struct lr_nm {
    int n;
    double step[LR_NM_MAX_DIM];
    double ftol, xtol;
    int max_evals, max_restarts;
    /* state */
    double x[LR_NM_MAX_DIM + 1][LR_NM_MAX_DIM], f[LR_NM_MAX_DIM + 1];
    double c[LR_NM_MAX_DIM], xr[LR_NM_MAX_DIM], fr, trial[LR_NM_MAX_DIM];
    int phase, k;
    int evals, iterations, restarts;
    double f_restart; /* best value when the last restart began */
    bool done;
} lr_nm;

/* x0: start; step: initial simplex edge per coordinate (> 0). */
void lr_nm_init(lr_nm *nm, int n, const double *x0, const double *step, double ftol,
                double xtol, int max_evals, int max_restarts);
/* The next point to evaluate into x; false when done (the best point is lr_nm_best). */
bool lr_nm_ask(lr_nm *nm, double *x);
/* The value at the point the last ask returned (+inf for a point outside the domain). */
void lr_nm_tell(lr_nm *nm, double f);
/* Best point and value so far. */
double lr_nm_best(const lr_nm *nm, double *x);

#endif
