/* lamprig — inverse diffusion: adjoint gradients and conjugate gradients (inverse.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/diffusion/dgrid_internal.h"
#include "render/diffusion/inverse.h"

struct lr_dinv {
    lr_dsystem *sys;
    const lr_dgrid *g;
    const lr_dinv_pattern *pat;
    int M, G;
    int *group;
    double lambda, tol;
    size_t n, n_in, ng;
    double **phi;        /* per pattern, warm start of the forward solves */
    double **lam;        /* per pattern, warm start of the adjoint solves */
    double *rhs, *src, *gD, *gmu, *D, *mu;
    size_t (*pairs)[2];  /* grid-adjacent inside node pairs (by parameter) */
    size_t n_pairs;
};

void lr_dinv_destroy(lr_dinv *v)
{
    if (!v)
        return;
    for (int m = 0; m < v->M; m++) {
        if (v->phi)
            free(v->phi[m]);
        if (v->lam)
            free(v->lam[m]);
    }
    free(v->phi);
    free(v->lam);
    free(v->group);
    free(v->rhs);
    free(v->src);
    free(v->gD);
    free(v->gmu);
    free(v->D);
    free(v->mu);
    free(v->pairs);
    free(v);
}

int lr_dinv_create(const lr_dinv_desc *d, lr_dinv **out, lr_err *e)
{
    *out = NULL;
    if (!d || !d->sys || !d->patterns || d->n_patterns < 1)
        return lr_err_set(e, LR_EINVAL, "inverse diffusion: no system or no patterns");
    lr_dinv *v = calloc(1, sizeof *v);
    if (!v)
        return lr_err_set(e, LR_ENOMEM, "inverse diffusion: out of memory");
    v->sys = d->sys;
    v->g = lr_dsystem_grid(d->sys);
    v->pat = d->patterns;
    v->M = d->n_patterns;
    v->lambda = d->lambda;
    v->tol = d->tol > 0.0 ? d->tol : 1e-10;
    v->n = lr_dgrid_unknown_count(v->g);
    v->n_in = lr_dgrid_inside_count(v->g);
    v->ng = lr_dgrid_ghost_count(v->g);
    v->G = d->group ? d->n_groups : (int)v->n_in;
    v->group = malloc(v->n_in * sizeof *v->group);
    v->phi = calloc((size_t)v->M, sizeof *v->phi);
    v->lam = calloc((size_t)v->M, sizeof *v->lam);
    v->rhs = malloc(v->n * sizeof *v->rhs);
    v->src = malloc(v->n * sizeof *v->src);
    v->gD = malloc(v->n_in * sizeof *v->gD);
    v->gmu = malloc(v->n_in * sizeof *v->gmu);
    v->D = malloc(v->n_in * sizeof *v->D);
    v->mu = malloc(v->n_in * sizeof *v->mu);
    v->pairs = malloc(3 * v->n_in * sizeof *v->pairs);
    if (!v->group || !v->phi || !v->lam || !v->rhs || !v->src || !v->gD || !v->gmu || !v->D ||
        !v->mu || !v->pairs) {
        lr_dinv_destroy(v);
        return lr_err_set(e, LR_ENOMEM, "inverse diffusion: out of memory");
    }
    for (int m = 0; m < v->M; m++)
        if (!(v->phi[m] = calloc(v->n, sizeof(double))) || !(v->lam[m] = calloc(v->n, sizeof(double)))) {
            lr_dinv_destroy(v);
            return lr_err_set(e, LR_ENOMEM, "inverse diffusion: out of memory");
        }
    for (size_t p = 0; p < v->n_in; p++) {
        int gr = d->group ? d->group[p] : (int)p;
        if (gr < 0 || gr >= v->G) {
            lr_dinv_destroy(v);
            return lr_err_set(e, LR_EINVAL, "inverse diffusion: node %zu: group %d outside 0..%d", p,
                              gr, v->G - 1);
        }
        v->group[p] = gr;
    }
    /* Regulariser pairs: +x, +y, +z neighbours that are both inside. */
    const lr_dgrid *g = v->g;
    for (size_t p = 0; p < v->n_in; p++) {
        size_t node = g->param_node[p];
        int ijk[3] = {(int)(node % (size_t)g->n[0]), (int)((node / (size_t)g->n[0]) % (size_t)g->n[1]),
                      (int)(node / ((size_t)g->n[0] * (size_t)g->n[1]))};
        size_t stride[3] = {1, (size_t)g->n[0], (size_t)g->n[0] * (size_t)g->n[1]};
        for (int a = 0; a < 3; a++) {
            if (ijk[a] + 1 >= g->n[a])
                continue;
            size_t nb = node + stride[a];
            if (g->kind[nb] == LR_DNODE_IN) {
                v->pairs[v->n_pairs][0] = p;
                v->pairs[v->n_pairs++][1] = (size_t)g->param[nb];
            }
        }
    }
    *out = v;
    return LR_OK;
}

int lr_dinv_unknowns(const lr_dinv *v) { return 2 * v->G; }

static int set_theta(lr_dinv *v, const double *theta, lr_err *e)
{
    for (size_t p = 0; p < v->n_in; p++) {
        v->D[p] = exp(theta[v->group[p]]);
        v->mu[p] = exp(theta[v->G + v->group[p]]);
    }
    return lr_dsystem_set_params(v->sys, v->D, v->mu, e);
}

/* Data term of one pattern after its forward solve; adds the adjoint source when src. */
static double data_term(const lr_dinv *v, const lr_dinv_pattern *pt, const double *phi,
                        double norm, double *src)
{
    double A2 = 2.0 * lr_dsystem_A(v->sys), f = 0.0;
    size_t idx[LR_DGHOST_MAX_W];
    double w[LR_DGHOST_MAX_W];
    for (size_t k = 0; k < v->ng; k++) {
        if (pt->observed && !pt->observed[k])
            continue;
        double B = (lr_dsystem_ghost_phi(v->sys, k, phi) - 2.0 * pt->q[k]) / A2;
        double r = B - pt->y[k];
        f += r * r / norm;
        if (src) {
            int c = lr_dsystem_ghost_phi_weights(v->sys, k, idx, w);
            for (int j = 0; j < c; j++)
                src[idx[j]] += 2.0 * r / norm * w[j] / A2;
        }
    }
    return f;
}

static double y_norm(const lr_dinv_pattern *p, int n, size_t ng)
{
    double s = 0.0;
    for (int m = 0; m < n; m++)
        for (size_t k = 0; k < ng; k++)
            if (!p[m].observed || p[m].observed[k])
                s += p[m].y[k] * p[m].y[k];
    return s > 0.0 ? s : 1.0;
}

int lr_dinv_eval(lr_dinv *v, const double *theta, double *f, double *grad, lr_err *e)
{
    int rc = set_theta(v, theta, e);
    if (rc)
        return rc;
    double norm = y_norm(v->pat, v->M, v->ng), F = 0.0;
    if (grad) {
        memset(v->gD, 0, v->n_in * sizeof *v->gD);
        memset(v->gmu, 0, v->n_in * sizeof *v->gmu);
    }
    for (int m = 0; m < v->M; m++) {
        lr_dsystem_rhs(v->sys, v->pat[m].q, v->rhs);
        if ((rc = lr_dsystem_solve(v->sys, false, v->rhs, v->phi[m], v->tol, 50000, NULL, e)))
            return rc;
        if (grad)
            memset(v->src, 0, v->n * sizeof *v->src);
        F += data_term(v, &v->pat[m], v->phi[m], norm, grad ? v->src : NULL);
        if (!grad)
            continue;
        /* Adjoint (seed 001 Eq. 5-6): M^T lambda = df/dphi; then Eq. 7 in discrete form. */
        if ((rc = lr_dsystem_solve(v->sys, true, v->src, v->lam[m], v->tol, 50000, NULL, e)))
            return rc;
        lr_dsystem_grad(v->sys, v->lam[m], v->phi[m], v->gD, v->gmu);
    }
    if (grad) {
        memset(grad, 0, 2 * (size_t)v->G * sizeof *grad);
        for (size_t p = 0; p < v->n_in; p++) {
            grad[v->group[p]] += v->gD[p] * v->D[p]; /* d/d log D */
            grad[v->G + v->group[p]] += v->gmu[p] * v->mu[p];
        }
    }
    /* Regulariser on theta's differences between adjacent nodes (zero for one group). */
    for (size_t q = 0; q < v->n_pairs; q++) {
        int a = v->group[v->pairs[q][0]], b = v->group[v->pairs[q][1]];
        if (a == b)
            continue;
        for (int s = 0; s < 2; s++) {
            double d = theta[s * v->G + a] - theta[s * v->G + b];
            F += v->lambda * d * d;
            if (grad) {
                grad[s * v->G + a] += 2.0 * v->lambda * d;
                grad[s * v->G + b] -= 2.0 * v->lambda * d;
            }
        }
    }
    *f = F;
    return LR_OK;
}

int lr_dinv_misfit(lr_dinv *v, const double *theta, const lr_dinv_pattern *p, int n, double *f,
                   lr_err *e)
{
    int rc = set_theta(v, theta, e);
    if (rc)
        return rc;
    double norm = y_norm(p, n, v->ng), F = 0.0;
    for (int m = 0; m < n; m++) {
        lr_dsystem_rhs(v->sys, p[m].q, v->rhs);
        memset(v->src, 0, v->n * sizeof *v->src);
        if ((rc = lr_dsystem_solve(v->sys, false, v->rhs, v->src, v->tol, 50000, NULL, e)))
            return rc;
        F += data_term(v, &p[m], v->src, norm, NULL);
    }
    *f = F;
    return LR_OK;
}

/* f along theta + a dir. */
static int line_f(lr_dinv *v, const double *theta, const double *dir, double a, double *tmp,
                  double *f, int *evals, lr_err *e)
{
    int n = 2 * v->G;
    for (int i = 0; i < n; i++)
        tmp[i] = theta[i] + a * dir[i];
    (*evals)++;
    int rc = lr_dinv_eval(v, tmp, f, NULL, e);
    if (rc == LR_ENOMEM)
        return rc;
    if (rc) {
        /* A step so long that a solve fails (parameters out of range): treat as uphill. */
        *f = INFINITY;
        lr_err_clear(e);
        return LR_OK;
    }
    return LR_OK;
}

int lr_dinv_fit(lr_dinv *v, double *theta, int max_iter, double f_stop, lr_dinv_report *rep,
                lr_err *e)
{
    int n = 2 * v->G, rc = LR_OK;
    double *g = malloc(4 * (size_t)n * sizeof *g);
    if (!g)
        return lr_err_set(e, LR_ENOMEM, "inverse diffusion: out of memory");
    double *gp = g + n, *dir = g + 2 * n, *tmp = g + 3 * n;
    lr_dinv_report r = {0};
    double f;
    if ((rc = lr_dinv_eval(v, theta, &f, g, e)))
        goto done;
    r.evaluations = 1;
    r.f0 = f;
    for (int i = 0; i < n; i++)
        dir[i] = -g[i];
    const double phi = 0.5 * (sqrt(5.0) - 1.0);
    double step = 1.0;
    for (r.iterations = 0; r.iterations < max_iter && f > f_stop; r.iterations++) {
        double gd = 0.0, dn = 0.0;
        for (int i = 0; i < n; i++) {
            gd += g[i] * dir[i];
            dn += dir[i] * dir[i];
        }
        if (!(gd < 0.0)) { /* not a descent direction: restart along -g */
            for (int i = 0; i < n; i++)
                dir[i] = -g[i];
            gd = 0.0;
            dn = 0.0;
            for (int i = 0; i < n; i++) {
                gd -= g[i] * g[i];
                dn += g[i] * g[i];
            }
            if (!(gd < 0.0))
                break;
        }
        /* Bracket: steps in theta of at most 1 (a factor e in D or mu) to start. */
        double a0 = 0.0, a1 = fmin(step, 1.0 / sqrt(dn)), fa1;
        if ((rc = line_f(v, theta, dir, a1, tmp, &fa1, &r.evaluations, e)))
            goto done;
        double a2, fa2;
        if (fa1 < f) {
            a2 = a1 * 2.618;
            if ((rc = line_f(v, theta, dir, a2, tmp, &fa2, &r.evaluations, e)))
                goto done;
            for (int k = 0; k < 20 && fa2 < fa1; k++) {
                a0 = a1;
                a1 = a2;
                fa1 = fa2;
                a2 = a1 * 2.618;
                if ((rc = line_f(v, theta, dir, a2, tmp, &fa2, &r.evaluations, e)))
                    goto done;
            }
        } else {
            a2 = a1;
            fa2 = fa1;
            a1 = a2 * phi;
            for (int k = 0; k < 30; k++) {
                if ((rc = line_f(v, theta, dir, a1, tmp, &fa1, &r.evaluations, e)))
                    goto done;
                if (fa1 < f)
                    break;
                a2 = a1;
                fa2 = fa1;
                a1 *= phi;
            }
            if (!(fa1 < f))
                break; /* no decrease along a descent direction: converged to rounding */
        }
        /* Golden section on [a0, a2] around a1 (seed 001 Table I). */
        double lo = a0, hi = a2;
        double x1 = hi - phi * (hi - lo), x2 = lo + phi * (hi - lo), f1, f2;
        if ((rc = line_f(v, theta, dir, x1, tmp, &f1, &r.evaluations, e)) ||
            (rc = line_f(v, theta, dir, x2, tmp, &f2, &r.evaluations, e)))
            goto done;
        for (int k = 0; k < 10; k++) {
            if (f1 < f2) {
                hi = x2;
                x2 = x1;
                f2 = f1;
                x1 = hi - phi * (hi - lo);
                if ((rc = line_f(v, theta, dir, x1, tmp, &f1, &r.evaluations, e)))
                    goto done;
            } else {
                lo = x1;
                x1 = x2;
                f1 = f2;
                x2 = lo + phi * (hi - lo);
                if ((rc = line_f(v, theta, dir, x2, tmp, &f2, &r.evaluations, e)))
                    goto done;
            }
        }
        double a = f1 < f2 ? x1 : x2, fb = fmin(f1, f2);
        if (fa1 < fb) {
            a = a1;
            fb = fa1;
        }
        if (!(fb < f))
            break;
        for (int i = 0; i < n; i++)
            theta[i] += a * dir[i];
        step = a * 2.0;
        memcpy(gp, g, (size_t)n * sizeof *g);
        if ((rc = lr_dinv_eval(v, theta, &f, g, e)))
            goto done;
        r.evaluations++;
        /* Polak-Ribiere (clamped at 0: a restart when it would point uphill). */
        double num = 0.0, den = 0.0;
        for (int i = 0; i < n; i++) {
            num += g[i] * (g[i] - gp[i]);
            den += gp[i] * gp[i];
        }
        double beta = den > 0.0 ? fmax(0.0, num / den) : 0.0;
        for (int i = 0; i < n; i++)
            dir[i] = -g[i] + beta * dir[i];
    }
    /* theta holds the best point; leave the system's parameters there too. */
    rc = lr_dinv_eval(v, theta, &f, NULL, e);
    r.f = f;
done:
    free(g);
    if (rep)
        *rep = r;
    return rc;
}
