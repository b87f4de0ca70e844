/* lamprig — the finite-difference system of seed 001 Eq. 1-2 on a diffusion grid (dgrid.h).
 *
 * Row of an inside node i (7-point form of div(D grad phi) - mu phi = 0, seed 001 Eq. 8, face
 * coefficient the mean of the two nodes' D, times -1 so that the diagonal is positive):
 *     sum_j (D_i + D_j) / (2 h^2) (phi_i - phi_j) + mu_i phi_i = 0,
 * over the six neighbours j that are unknowns (a neighbour beyond the array is a zero-flux
 * face: the 1-D slab's x/y ends). Row of a ghost g (boundary condition of seed 001 Eq. 2 at its
 * closest surface point b, s the depth along -n): with phi(s) the quadratic through
 * (-t, phi_g), (h, phi(b - h n)), (2 h, phi(b - 2 h n)), the latter two triquadratic
 * (trilinear where the 27-point stencil leaves the unknowns),
 *     phi(0) - 2 A D_b phi'(0) = 4 q(b) / (1 - F_dr),
 * D_b the D of the ghost's owner (the inside node nearest b).
 *
 * Every matrix entry is a constant plus a sum of coefficients times parameters (D_p, mu_p):
 * the terms list below, from which the values are rebuilt when the parameters change and the
 * adjoint gradient is read (lr_dsystem_grad).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/diffusion/dgrid.h"
#include "render/diffusion/dgrid_internal.h"
#include "render/optics/optics.h"

typedef struct trip {
    size_t r, c;
    double a;    /* constant part */
    long k;      /* parameter index in [D..., mu...], or -1 */
    double coef; /* times parameter k */
} trip;

typedef struct term {
    size_t entry;
    size_t k;
    double coef;
} term;

/* phi(b) and the ghost row as weights over unknowns, kept per ghost (lr_dsystem_ghost_phi). */
typedef struct ghost_row {
    size_t off, count; /* into gw_idx / gw_phi */
} ghost_row;

struct lr_dsystem {
    const lr_dgrid *g;
    double A, Fdr;
    size_t n, nnz, n_terms;
    size_t *row_start; /* n + 1 */
    size_t *col;
    double *a;   /* constant parts */
    double *val; /* current values */
    double *diag_inv;
    term *terms;
    double *P; /* D (n_in) then mu (n_in) */
    ghost_row *gr;
    size_t *gw_idx;
    double *gw_phi;
};

typedef struct trip_buf {
    trip *t;
    size_t n, cap;
} trip_buf;

static int push(trip_buf *b, size_t r, size_t c, double a, long k, double coef)
{
    if (b->n == b->cap) {
        size_t cap = b->cap ? 2 * b->cap : 1024;
        trip *t = realloc(b->t, cap * sizeof *t);
        if (!t)
            return -1;
        b->t = t;
        b->cap = cap;
    }
    b->t[b->n++] = (trip){r, c, a, k, coef};
    return 0;
}

static int cmp_trip(const void *x, const void *y)
{
    const trip *a = x, *b = y;
    if (a->r != b->r)
        return a->r < b->r ? -1 : 1;
    if (a->c != b->c)
        return a->c < b->c ? -1 : 1;
    return 0;
}

/* Orders the triplets by (row, column), keeping the push order of equal ones (the order their
 * constants are summed in). assemble pushes whole rows in increasing order, so each row's
 * few dozen entries are sorted in place by insertion: a full sort of the ~5 million triplets
 * of a 110 000-node grid took most of a cold build. Any other order falls back to a stable
 * merge sort over everything. */
static void sort_trips(trip_buf *tb)
{
    bool rows_ordered = true;
    for (size_t q = 1; q < tb->n && rows_ordered; q++)
        rows_ordered = tb->t[q].r >= tb->t[q - 1].r;
    if (!rows_ordered) {
        qsort(tb->t, tb->n, sizeof *tb->t, cmp_trip); /* glibc's qsort: a merge sort */
        return;
    }
    for (size_t q = 1; q < tb->n; q++) {
        trip x = tb->t[q];
        size_t p = q;
        while (p > 0 && tb->t[p - 1].r == x.r && tb->t[p - 1].c > x.c) {
            tb->t[p] = tb->t[p - 1];
            p--;
        }
        tb->t[p] = x;
    }
}

/* Quadratic (or, with two points, linear) Lagrange value and derivative weights at s = 0. */
static void lagrange0(const double *s, int m, double *L, double *dL)
{
    for (int k = 0; k < m; k++) {
        double den = 1.0, num = 1.0, dnum = 0.0;
        for (int j = 0; j < m; j++) {
            if (j == k)
                continue;
            den *= s[k] - s[j];
            num *= -s[j];
        }
        for (int j = 0; j < m; j++) {
            if (j == k)
                continue;
            double p = 1.0;
            for (int l = 0; l < m; l++)
                if (l != k && l != j)
                    p *= -s[l];
            dnum += p;
        }
        L[k] = num / den;
        dL[k] = dnum / den;
    }
}

static const int dirs[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};

static int assemble(lr_dsystem *s, trip_buf *tb, lr_err *e)
{
    const lr_dgrid *g = s->g;
    const size_t n_in = g->n_in;
    const double ih2 = 0.5 / (g->h * g->h);
    for (size_t u = 0; u < n_in; u++) {
        size_t node = g->unknown_node[u];
        int i = (int)(node % (size_t)g->n[0]);
        int j = (int)((node / (size_t)g->n[0]) % (size_t)g->n[1]);
        int k = (int)(node / ((size_t)g->n[0] * (size_t)g->n[1]));
        for (int d = 0; d < 6; d++) {
            int a = i + dirs[d][0], b = j + dirs[d][1], c = k + dirs[d][2];
            if (a < 0 || b < 0 || c < 0 || a >= g->n[0] || b >= g->n[1] || c >= g->n[2])
                continue;
            size_t nb = ((size_t)c * (size_t)g->n[1] + (size_t)b) * (size_t)g->n[0] + (size_t)a;
            long un = g->unknown[nb];
            if (un < 0)
                continue; /* outside and beyond the band: cannot happen for a closed shape */
            long kj = g->param[nb] >= 0 ? g->param[nb] : (long)u;
            if (push(tb, u, u, 0.0, (long)u, ih2) || push(tb, u, u, 0.0, kj, ih2) ||
                push(tb, u, (size_t)un, 0.0, (long)u, -ih2) || push(tb, u, (size_t)un, 0.0, kj, -ih2))
                return lr_err_set(e, LR_ENOMEM, "diffusion system: out of memory");
        }
        if (push(tb, u, u, 0.0, (long)(n_in + u), 1.0))
            return lr_err_set(e, LR_ENOMEM, "diffusion system: out of memory");
    }
    size_t gw_cap = LR_DGHOST_MAX_W * (g->n_ghost ? g->n_ghost : 1);
    s->gr = calloc(g->n_ghost ? g->n_ghost : 1, sizeof *s->gr);
    s->gw_idx = malloc(gw_cap * sizeof *s->gw_idx);
    s->gw_phi = malloc(gw_cap * sizeof *s->gw_phi);
    if (!s->gr || !s->gw_idx || !s->gw_phi)
        return lr_err_set(e, LR_ENOMEM, "diffusion system: out of memory");
    size_t gw_n = 0;
    const double h = g->h;
    for (size_t q = 0; q < g->n_ghost; q++) {
        size_t ug = n_in + q;
        lr_vec3 b = g->ghost_b[q], nrm = g->ghost_n[q];
        double t = g->ghost_t[q];
        size_t idx[2][27];
        double w[2][27];
        int m[2];
        lr_vec3 p1 = lr_v3_sub(b, lr_v3_scale(nrm, h));
        lr_vec3 p2 = lr_v3_sub(b, lr_v3_scale(nrm, 2.0 * h));
        for (int pt = 0; pt < 2; pt++) {
            lr_vec3 pp = pt ? p2 : p1;
            m[pt] = lr_dgrid_triquadratic(g, pp, idx[pt], w[pt]);
            if (m[pt] == 0)
                m[pt] = lr_dgrid_trilinear(g, pp, idx[pt], w[pt]);
        }
        double sv[3] = {-t, h, 2.0 * h}, L[3], dL[3];
        int pts = 3;
        if (m[0] == 0) {
            /* A sliver thinner than the grid: the owner node stands in, first order. */
            long own = g->param[g->ghost_node[q]];
            if (own < 0)
                return lr_err_set(e, LR_EINVAL,
                                  "diffusion system: ghost at (%g, %g, %g) mm has no inside node "
                                  "near it (object thinner than h = %g mm there)",
                                  b.x, b.y, b.z, h);
            idx[0][0] = (size_t)own;
            w[0][0] = 1.0;
            m[0] = 1;
            sv[1] = fmax(lr_v3_len(lr_v3_sub(lr_dgrid_param_pos(g, (size_t)own), b)), 0.25 * h);
            pts = 2;
        } else if (m[1] == 0) {
            pts = 2;
        }
        lagrange0(sv, pts, L, dL);
        long own = g->param[g->ghost_node[q]];
        if (own < 0)
            own = (long)idx[0][0] < (long)n_in ? (long)idx[0][0] : 0;
        const double twoA = 2.0 * s->A;
        if (push(tb, ug, ug, L[0], own, -twoA * dL[0]))
            return lr_err_set(e, LR_ENOMEM, "diffusion system: out of memory");
        s->gr[q].off = gw_n;
        s->gw_idx[gw_n] = ug;
        s->gw_phi[gw_n++] = L[0];
        for (int p = 1; p < pts; p++)
            for (int c = 0; c < m[p - 1]; c++) {
                double wc = w[p - 1][c];
                if (push(tb, ug, idx[p - 1][c], wc * L[p], own, -twoA * dL[p] * wc))
                    return lr_err_set(e, LR_ENOMEM, "diffusion system: out of memory");
                s->gw_idx[gw_n] = idx[p - 1][c];
                s->gw_phi[gw_n++] = wc * L[p];
            }
        s->gr[q].count = gw_n - s->gr[q].off;
    }
    return LR_OK;
}

static void rebuild_values(lr_dsystem *s)
{
    memcpy(s->val, s->a, s->nnz * sizeof *s->val);
    for (size_t t = 0; t < s->n_terms; t++)
        s->val[s->terms[t].entry] += s->terms[t].coef * s->P[s->terms[t].k];
    for (size_t r = 0; r < s->n; r++) {
        double d = 0.0;
        for (size_t q = s->row_start[r]; q < s->row_start[r + 1]; q++)
            if (s->col[q] == r)
                d = s->val[q];
        s->diag_inv[r] = d != 0.0 ? 1.0 / d : 1.0;
    }
}

void lr_dsystem_destroy(lr_dsystem *s)
{
    if (!s)
        return;
    free(s->row_start);
    free(s->col);
    free(s->a);
    free(s->val);
    free(s->diag_inv);
    free(s->terms);
    free(s->P);
    free(s->gr);
    free(s->gw_idx);
    free(s->gw_phi);
    free(s);
}

int lr_dsystem_create(const lr_dgrid *g, double eta, lr_dsystem **out, lr_err *e)
{
    *out = NULL;
    if (!isfinite(eta) || eta < LR_ETA_MIN || eta > LR_ETA_MAX)
        return lr_err_set(e, LR_EINVAL, "diffusion system: eta = %g: must be in [%g, %g]", eta,
                          LR_ETA_MIN, LR_ETA_MAX);
    lr_dsystem *s = calloc(1, sizeof *s);
    if (!s)
        return lr_err_set(e, LR_ENOMEM, "diffusion system: out of memory");
    s->g = g;
    s->Fdr = lr_fresnel_diffuse_reflectance(eta);
    s->A = (1.0 + s->Fdr) / (1.0 - s->Fdr);
    s->n = g->n_unknown;
    /* 25 triplets per inside row, up to 1 + 2 x 27 per ghost row: one allocation. */
    trip_buf tb = {0};
    tb.cap = 25 * g->n_in + 32 * g->n_ghost + 1024;
    if (!(tb.t = malloc(tb.cap * sizeof *tb.t))) {
        lr_dsystem_destroy(s);
        return lr_err_set(e, LR_ENOMEM, "diffusion system: out of memory");
    }
    int rc = assemble(s, &tb, e);
    if (rc) {
        free(tb.t);
        lr_dsystem_destroy(s);
        return rc;
    }
    sort_trips(&tb);
    size_t nnz = 0, n_terms = 0;
    for (size_t q = 0; q < tb.n; q++) {
        if (q == 0 || cmp_trip(&tb.t[q], &tb.t[q - 1]) != 0)
            nnz++;
        if (tb.t[q].k >= 0)
            n_terms++;
    }
    s->nnz = nnz;
    s->n_terms = n_terms;
    s->row_start = calloc(s->n + 1, sizeof *s->row_start);
    s->col = malloc(nnz * sizeof *s->col);
    s->a = calloc(nnz, sizeof *s->a);
    s->val = malloc(nnz * sizeof *s->val);
    s->diag_inv = malloc(s->n * sizeof *s->diag_inv);
    s->terms = malloc((n_terms ? n_terms : 1) * sizeof *s->terms);
    s->P = calloc(2 * g->n_in, sizeof *s->P);
    if (!s->row_start || !s->col || !s->a || !s->val || !s->diag_inv || !s->terms || !s->P) {
        free(tb.t);
        lr_dsystem_destroy(s);
        return lr_err_set(e, LR_ENOMEM, "diffusion system: out of memory");
    }
    size_t ent = (size_t)-1, nt = 0;
    for (size_t q = 0; q < tb.n; q++) {
        if (q == 0 || cmp_trip(&tb.t[q], &tb.t[q - 1]) != 0) {
            ent++;
            s->col[ent] = tb.t[q].c;
            s->row_start[tb.t[q].r + 1]++;
        }
        s->a[ent] += tb.t[q].a;
        if (tb.t[q].k >= 0)
            s->terms[nt++] = (term){ent, (size_t)tb.t[q].k, tb.t[q].coef};
    }
    for (size_t r = 0; r < s->n; r++)
        s->row_start[r + 1] += s->row_start[r];
    free(tb.t);
    /* Placeholder parameters until set: D = 1, mu = 0 keeps the values finite. */
    for (size_t p = 0; p < g->n_in; p++)
        s->P[p] = 1.0;
    rebuild_values(s);
    *out = s;
    return LR_OK;
}

static void *dup_array(const void *src, size_t count, size_t size, bool *ok)
{
    void *d = malloc((count ? count : 1) * size);
    if (!d)
        *ok = false;
    else if (count)
        memcpy(d, src, count * size);
    return d;
}

int lr_dsystem_clone(const lr_dsystem *s, lr_dsystem **out, lr_err *e)
{
    *out = NULL;
    lr_dsystem *c = calloc(1, sizeof *c);
    if (!c)
        return lr_err_set(e, LR_ENOMEM, "diffusion system: out of memory");
    *c = *s;
    const lr_dgrid *g = s->g;
    size_t n_gw = g->n_ghost ? s->gr[g->n_ghost - 1].off + s->gr[g->n_ghost - 1].count : 0;
    bool ok = true;
    c->row_start = dup_array(s->row_start, s->n + 1, sizeof *s->row_start, &ok);
    c->col = dup_array(s->col, s->nnz, sizeof *s->col, &ok);
    c->a = dup_array(s->a, s->nnz, sizeof *s->a, &ok);
    c->val = dup_array(s->val, s->nnz, sizeof *s->val, &ok);
    c->diag_inv = dup_array(s->diag_inv, s->n, sizeof *s->diag_inv, &ok);
    c->terms = dup_array(s->terms, s->n_terms, sizeof *s->terms, &ok);
    c->P = dup_array(s->P, 2 * g->n_in, sizeof *s->P, &ok);
    c->gr = dup_array(s->gr, g->n_ghost, sizeof *s->gr, &ok);
    c->gw_idx = dup_array(s->gw_idx, n_gw, sizeof *s->gw_idx, &ok);
    c->gw_phi = dup_array(s->gw_phi, n_gw, sizeof *s->gw_phi, &ok);
    if (!ok) {
        lr_dsystem_destroy(c);
        return lr_err_set(e, LR_ENOMEM, "diffusion system: out of memory");
    }
    *out = c;
    return LR_OK;
}

const lr_dgrid *lr_dsystem_grid(const lr_dsystem *s) { return s->g; }
double lr_dsystem_A(const lr_dsystem *s) { return s->A; }
double lr_dsystem_Fdr(const lr_dsystem *s) { return s->Fdr; }
const double *lr_dsystem_D(const lr_dsystem *s) { return s->P; }
const double *lr_dsystem_mu(const lr_dsystem *s) { return s->P + s->g->n_in; }

int lr_dsystem_set_params(lr_dsystem *s, const double *D, const double *mu, lr_err *e)
{
    size_t n_in = s->g->n_in;
    for (size_t p = 0; p < n_in; p++) {
        if (!isfinite(D[p]) || !(D[p] > 0.0) || !isfinite(mu[p]) || mu[p] < 0.0) {
            lr_vec3 x = lr_dgrid_param_pos(s->g, p);
            return lr_err_set(e, LR_EINVAL,
                              "diffusion system: node %zu at (%g, %g, %g) mm: D = %g, mu = %g "
                              "(need D > 0, mu >= 0, finite)",
                              p, x.x, x.y, x.z, D[p], mu[p]);
        }
    }
    memcpy(s->P, D, n_in * sizeof *D);
    memcpy(s->P + n_in, mu, n_in * sizeof *mu);
    rebuild_values(s);
    return LR_OK;
}

void lr_dsystem_rhs(const lr_dsystem *s, const double *q_ghost, double *rhs)
{
    const lr_dgrid *g = s->g;
    memset(rhs, 0, s->n * sizeof *rhs);
    double k = 4.0 / (1.0 - s->Fdr);
    for (size_t q = 0; q < g->n_ghost; q++)
        rhs[g->n_in + q] = k * q_ghost[q];
}

/* The matrix arrays in locals: y may alias nothing of s (restrict), so the loops keep them in
 * registers instead of reloading s->val, s->col and s->row_start after every store. These two
 * products are most of a grid solve's time (BiCGSTAB: two per iteration). */
void lr_dsystem_apply(const lr_dsystem *s, const double *restrict x, double *restrict y)
{
    const size_t n = s->n, *restrict row = s->row_start, *restrict col = s->col;
    const double *restrict val = s->val;
    size_t q = row[0];
    for (size_t r = 0; r < n; r++) {
        size_t end = row[r + 1];
        double acc = 0.0;
        for (; q < end; q++)
            acc += val[q] * x[col[q]];
        y[r] = acc;
    }
}

void lr_dsystem_apply_t(const lr_dsystem *s, const double *restrict x, double *restrict y)
{
    const size_t n = s->n, *restrict row = s->row_start, *restrict col = s->col;
    const double *restrict val = s->val;
    memset(y, 0, n * sizeof *y);
    size_t q = row[0];
    for (size_t r = 0; r < n; r++) {
        size_t end = row[r + 1];
        double xr = x[r];
        for (; q < end; q++)
            y[col[q]] += val[q] * xr;
    }
}

void lr_dsystem_grad(const lr_dsystem *s, const double *lambda, const double *phi,
                     double *grad_D, double *grad_mu)
{
    /* Row index of each entry: walk the rows once. */
    size_t n_in = s->g->n_in;
    size_t r = 0;
    /* terms are in entry order (built from sorted triplets), so rows advance monotonically */
    for (size_t t = 0; t < s->n_terms; t++) {
        size_t ent = s->terms[t].entry;
        while (s->row_start[r + 1] <= ent)
            r++;
        double v = -s->terms[t].coef * lambda[r] * phi[s->col[ent]];
        size_t k = s->terms[t].k;
        if (k < n_in)
            grad_D[k] += v;
        else
            grad_mu[k - n_in] += v;
    }
}

double lr_dsystem_ghost_phi(const lr_dsystem *s, size_t ghost, const double *phi)
{
    const ghost_row *gr = &s->gr[ghost];
    double v = 0.0;
    for (size_t q = 0; q < gr->count; q++)
        v += s->gw_phi[gr->off + q] * phi[s->gw_idx[gr->off + q]];
    return v;
}

int lr_dsystem_ghost_phi_weights(const lr_dsystem *s, size_t ghost, size_t idx[LR_DGHOST_MAX_W],
                                 double w[LR_DGHOST_MAX_W])
{
    const ghost_row *gr = &s->gr[ghost];
    for (size_t q = 0; q < gr->count; q++) {
        idx[q] = s->gw_idx[gr->off + q];
        w[q] = s->gw_phi[gr->off + q];
    }
    return (int)gr->count;
}

static double dot(const double *a, const double *b, size_t n)
{
    double s = 0.0;
    for (size_t i = 0; i < n; i++)
        s += a[i] * b[i];
    return s;
}

/* BiCGSTAB (van der Vorst 1992) with the Jacobi preconditioner on the right. */
int lr_dsystem_solve(const lr_dsystem *s, bool transpose, const double *b, double *x, double tol,
                     int max_iter, int *iters, lr_err *e)
{
    return lr_dsystem_solve_cancel(s, transpose, b, x, tol, max_iter, iters, NULL, e);
}

/* The cancellation poll every 4 iterations: one iteration is two matrix products over the
 * grid (~10 ms at the candle's 40k unknowns on the proxy), so a request waits ~40 ms at most. */
#define CANCEL_EVERY 4

int lr_dsystem_solve_cancel(const lr_dsystem *s, bool transpose, const double *b, double *x,
                            double tol, int max_iter, int *iters, const lr_cancel *cancel,
                            lr_err *e)
{
    size_t n = s->n;
    if (iters)
        *iters = 0;
    double bn = sqrt(dot(b, b, n));
    if (!(bn > 0.0)) {
        memset(x, 0, n * sizeof *x);
        return LR_OK;
    }
    double *w = malloc(7 * n * sizeof *w);
    if (!w)
        return lr_err_set(e, LR_ENOMEM, "diffusion solve: out of memory");
    double *r = w, *r0 = w + n, *p = w + 2 * n, *v = w + 3 * n, *y = w + 4 * n, *z = w + 5 * n,
           *t = w + 6 * n;
    void (*A)(const lr_dsystem *, const double *, double *) =
        transpose ? lr_dsystem_apply_t : lr_dsystem_apply;
    A(s, x, r);
    for (size_t i = 0; i < n; i++) {
        r[i] = b[i] - r[i];
        r0[i] = r[i];
        p[i] = v[i] = 0.0;
    }
    double rho = 1.0, alpha = 1.0, omega = 1.0, rn = sqrt(dot(r, r, n));
    int it = 0;
    int restarts = 0;
    while (rn > tol * bn && it < max_iter) {
        if (it % CANCEL_EVERY == 0 && lr_cancel_requested(cancel)) {
            free(w);
            if (iters)
                *iters = it;
            return lr_cancel_check(cancel, "diffusion solve", e);
        }
        double rho1 = dot(r0, r, n);
        if (fabs(rho1) < 1e-300 || !(fabs(omega) > 0.0)) {
            /* Breakdown: restart with the current residual as the shadow vector. */
            if (++restarts > 20)
                break;
            memcpy(r0, r, n * sizeof *r);
            for (size_t i = 0; i < n; i++)
                p[i] = v[i] = 0.0;
            rho = alpha = omega = 1.0;
            continue;
        }
        double beta = (rho1 / rho) * (alpha / omega);
        rho = rho1;
        for (size_t i = 0; i < n; i++) {
            p[i] = r[i] + beta * (p[i] - omega * v[i]);
            y[i] = p[i] * s->diag_inv[i];
        }
        A(s, y, v);
        double den = dot(r0, v, n);
        if (!(fabs(den) > 0.0)) {
            rho = 0.0;
            continue;
        }
        alpha = rho / den;
        for (size_t i = 0; i < n; i++)
            r[i] -= alpha * v[i]; /* r now holds s */
        for (size_t i = 0; i < n; i++)
            z[i] = r[i] * s->diag_inv[i];
        A(s, z, t);
        double tt = dot(t, t, n);
        omega = tt > 0.0 ? dot(t, r, n) / tt : 0.0;
        for (size_t i = 0; i < n; i++) {
            x[i] += alpha * y[i] + omega * z[i];
            r[i] -= omega * t[i];
        }
        rn = sqrt(dot(r, r, n));
        it++;
    }
    /* The recursive residual drifts from the true one over many iterations: report the true. */
    A(s, x, t);
    double tr = 0.0;
    for (size_t i = 0; i < n; i++)
        tr += (b[i] - t[i]) * (b[i] - t[i]);
    tr = sqrt(tr);
    free(w);
    if (iters)
        *iters = it;
    if (!(tr <= 10.0 * tol * bn))
        return lr_err_set(e, LR_EINVAL,
                          "diffusion solve: relative residual %.3g after %d iterations (wanted %g)",
                          tr / bn, it, tol);
    return LR_OK;
}
