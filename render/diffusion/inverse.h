/* lamprig — inverse diffusion (seed 001 Sec. 4): per-voxel D (kappa) and mu from the light
 * leaving a sample under several illumination patterns.
 *
 * Objective (seed 001 Eq. 4 with its regulariser, per band):
 *     f(theta) = sum_m sum_g (B_m,g - y_m,g)^2 / sum y^2  +  lambda sum_(p,p') |theta_p - theta_p'|^2
 * over the observed surface points g (ghosts of the grid, dgrid.h) and patterns m, B from the
 * forward solve (dgrid.h: B = (phi - 2 q) / (2 A)), the regulariser over grid-adjacent inside
 * nodes. The unknowns are theta = (log D, log mu) per group of nodes (a group per node for the
 * heterogeneous fit, one group for the homogeneous fit the paper starts from); logarithms keep
 * both positive.
 *
 * Gradient by the adjoint method (seed 001 Eq. 5-7, Appendix A, in its discrete form): with
 * M phi_m = s_m, solve M^T lambda_m = df/dphi_m, then df/dD_p = -sum_m lambda_m^T (dM/dD_p) phi_m
 * (same for mu): two solves per pattern whatever the number of unknowns. The discrete adjoint
 * is the exact gradient of the discrete objective (tests/diffusion/test_diffusion_inverse.c:
 * against central differences to 1e-4).
 *
 * Minimisation: nonlinear conjugate gradients, Polak-Ribiere directions, golden-section line
 * search (seed 001 Table I).
 */
#ifndef LR_DINVERSE_H
#define LR_DINVERSE_H

#include "render/diffusion/dgrid.h"

typedef struct lr_dinv_pattern {
    const double *q;        /* ghost_count values: the pattern's transmitted irradiance */
    const double *y;        /* ghost_count values: measured B (read where observed) */
    const unsigned char *observed; /* ghost_count flags; NULL: every ghost */
} lr_dinv_pattern;

typedef struct lr_dinv_desc {
    lr_dsystem *sys;        /* the grid's system for one band (its parameters are overwritten) */
    const lr_dinv_pattern *patterns;
    int n_patterns;
    const int *group;       /* inside_count entries in [0, n_groups); NULL: one group per node */
    int n_groups;           /* with group == NULL: ignored */
    double lambda;          /* regularisation weight (seed 001: 1e-5 order) */
    double tol;             /* relative residual of the solves; 0: 1e-10 */
} lr_dinv_desc;

typedef struct lr_dinv lr_dinv;

int lr_dinv_create(const lr_dinv_desc *d, lr_dinv **out, lr_err *e);
void lr_dinv_destroy(lr_dinv *v);
/* Unknowns: 2 n_groups (log D per group, then log mu per group). */
int lr_dinv_unknowns(const lr_dinv *v);
/* f at theta, and its gradient (2 n_groups) when grad != NULL. */
int lr_dinv_eval(lr_dinv *v, const double *theta, double *f, double *grad, lr_err *e);
/* The data term alone (no regulariser) at theta for other patterns (held-out lighting). */
int lr_dinv_misfit(lr_dinv *v, const double *theta, const lr_dinv_pattern *p, int n, double *f,
                   lr_err *e);

typedef struct lr_dinv_report {
    int iterations, evaluations;
    double f0, f;
} lr_dinv_report;
/* Conjugate gradients from theta (updated in place) for at most max_iter iterations or until
 * f falls below f_stop. */
int lr_dinv_fit(lr_dinv *v, double *theta, int max_iter, double f_stop, lr_dinv_report *rep,
                lr_err *e);

#endif
