/* lamprig — translucent radiosity: the precomputed transfer for relighting (seed 000 Sec. 3:
 * with F and S fixed, B = (I - S F)^-1 S E, so a light move is a new E and one product with a
 * precomputed T = (I - S F)^-1 S).
 *
 * The system solve.c iterates is W = W0 + K W (per band), with W0 the light that leaves each
 * patch after its first interaction with the direct light and K one bounce:
 *   diffuse p:      W0_p = rho_p E_p,                        (K W)_p = rho_p (F W)_p
 *   translucent p:  W0_p = (E_p - Ein_p) + sum_r S_pr Ein_r,  (K W)_p = (1 - T_hem)(F W)_p
 *                                                              + sum_r S_pr T_hem (F W)_r
 * (Edir - Ein: the interface's reflection of the direct light; Ein and T_hem (F W): the light
 * that enters and scatters through S, Eq. 8). So W = (I - K)^-1 W0 and K = (D + S T_hem) F is
 * seed 000's S F with the interfaces' reflection in it. (I - K)^-1 is not formed: its LU
 * factors (partial pivoting) take the same n^2 numbers per band and the same 2 n^2 operations
 * per solve as the product T W0, for a third of the inverse's precomputation (2/3 n^3 per
 * band). A light move then costs E, one sparse S Ein for W0 and the two triangular solves,
 * and the result is exact to rounding rather than to the sweeps' tolerance.
 *
 * Memory: 3 n^2 doubles. The budget is lr_tr_settings.transfer_mb: 256 MB (a sixteenth of
 * the 4 GB target, beside the GL maps and the scene) admits n <= 3344 patches; above it
 * nothing is built and the warm-started sweeps of solve.c run instead. It is off by default:
 * the triangular solves read all 24 n^2 bytes per light move, while a warm start needs 2-4
 * sweeps over the sparse F and S (a few hundred entries per row), so on the votive (2006
 * patches, 92 MB) a 1 mm move took 318 ms against the sweeps' 44 ms, after 97 s more setup;
 * it pays only where the sweeps converge slowly and n is small (a closed cavity: sphere_shell,
 * 456 patches, 2-6 ms against 51 ms for a cold solve). */
#include "render/transrad/tr_priv.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/parallel.h"

size_t lr_tr_transfer_need(size_t n) { return 3 * n * n * sizeof(double) + 3 * n * sizeof(uint32_t); }

/* K's entries into the dense A = I - K of band b (row-major, n x n). */
static void assemble(const lr_tr *t, int b, double *A)
{
    size_t n = t->n;
    memset(A, 0, n * n * sizeof *A);
    for (size_t p = 0; p < n; p++) {
        const lr_tr_surf *sf = &t->surf[t->p[p].surface];
        double d = sf->d.kind == LR_TR_TRANSLUCENT ? 1 - sf->t_hem : sf->d.albedo[b];
        double *row = A + p * n;
        for (size_t k = t->F.row[p]; k < t->F.row[p + 1]; k++)
            row[t->F.col[k]] -= d * t->F.val[k];
        if (sf->d.kind != LR_TR_TRANSLUCENT)
            continue;
        /* Column p of S (stored as t->S's row p): what enters p leaves j. */
        for (size_t k = t->S.row[p]; k < t->S.row[p + 1]; k++) {
            size_t j = t->S.col[k];
            double s = (double)t->S.val[3 * k + (size_t)b] * sf->t_hem;
            double *rj = A + j * n;
            for (size_t m = t->F.row[p]; m < t->F.row[p + 1]; m++)
                rj[t->F.col[m]] -= s * t->F.val[m];
        }
    }
    for (size_t p = 0; p < n; p++)
        A[p * n + p] += 1;
}

typedef struct lu_ctx {
    double *A;
    size_t n, k;
} lu_ctx;

/* Rows k+1.. of the trailing update of step k (rows are independent). */
static void lu_rows(void *vctx, long item)
{
    lu_ctx *c = vctx;
    size_t n = c->n, k = c->k, lo = k + 1 + (size_t)item * 64, hi = lo + 64 < n ? lo + 64 : n;
    const double *rk = c->A + k * n;
    for (size_t i = lo; i < hi; i++) {
        double *ri = c->A + i * n;
        double l = ri[k] / rk[k];
        ri[k] = l;
        if (l == 0)
            continue;
        for (size_t j = k + 1; j < n; j++)
            ri[j] -= l * rk[j];
    }
}

/* In-place LU with partial pivoting (Golub & Van Loan Alg. 3.4.1): P A = L U. */
static int lu_factor(double *A, uint32_t *perm, size_t n, int threads)
{
    for (size_t i = 0; i < n; i++)
        perm[i] = (uint32_t)i;
    for (size_t k = 0; k < n; k++) {
        size_t piv = k;
        double best = fabs(A[k * n + k]);
        for (size_t i = k + 1; i < n; i++)
            if (fabs(A[i * n + k]) > best) {
                best = fabs(A[i * n + k]);
                piv = i;
            }
        if (!(best > 0) || !isfinite(best))
            return -1;
        if (piv != k) {
            for (size_t j = 0; j < n; j++) {
                double tmp = A[k * n + j];
                A[k * n + j] = A[piv * n + j];
                A[piv * n + j] = tmp;
            }
            uint32_t tp = perm[k];
            perm[k] = perm[piv];
            perm[piv] = tp;
        }
        if (k + 1 < n) {
            lu_ctx c = {A, n, k};
            long blocks = (long)((n - k - 1 + 63) / 64);
            lr_parallel_for(blocks, blocks > 4 ? threads : 1, lu_rows, &c);
        }
    }
    return 0;
}

int lr_tr_transfer_build(lr_tr *t, lr_err *e)
{
    size_t n = t->n;
    if (t->set.transfer_mb <= 0 || n == 0 ||
        lr_tr_transfer_need(n) > (size_t)t->set.transfer_mb * 1024 * 1024)
        return LR_OK; /* over the budget: solve.c's sweeps */
    for (int b = 0; b < 3; b++) {
        t->X.lu[b] = malloc(n * n * sizeof *t->X.lu[b]);
        t->X.perm[b] = malloc(n * sizeof *t->X.perm[b]);
        if (!t->X.lu[b] || !t->X.perm[b])
            return lr_err_set(e, LR_ENOMEM, "transrad: out of memory (transfer, %zu patches)",
                              n);
        assemble(t, b, t->X.lu[b]);
        if (lu_factor(t->X.lu[b], t->X.perm[b], n, t->set.threads))
            return lr_err_set(e, LR_EINVAL,
                              "transrad: field 'transfer': I - S F is singular in band %d", b);
    }
    t->X.built = true;
    return LR_OK;
}

void lr_tr_transfer_free(lr_tr_transfer *x)
{
    for (int b = 0; b < 3; b++) {
        free(x->lu[b]);
        free(x->perm[b]);
    }
    *x = (lr_tr_transfer){0};
}

size_t lr_tr_transfer_bytes(const lr_tr *t)
{
    return t && t->X.built ? lr_tr_transfer_need(t->n) : 0;
}

/* W = (I - K)^-1 W0 by the factors: L y = P W0, U W = y. w0 and W are n x 3 interleaved. */
static void lu_solve(const lr_tr *t, int b, const double *w0, double *y, double *W)
{
    size_t n = t->n;
    const double *A = t->X.lu[b];
    const uint32_t *perm = t->X.perm[b];
    for (size_t i = 0; i < n; i++) {
        const double *ri = A + i * n;
        double s = w0[3 * (size_t)perm[i] + (size_t)b];
        for (size_t j = 0; j < i; j++)
            s -= ri[j] * y[j];
        y[i] = s;
    }
    for (size_t i = n; i-- > 0;) {
        const double *ri = A + i * n;
        double s = y[i];
        for (size_t j = i + 1; j < n; j++)
            s -= ri[j] * W[3 * j + (size_t)b];
        W[3 * i + (size_t)b] = s / ri[i];
    }
}

int lr_tr_transfer_solve(lr_tr *t, lr_tr_slot *sl, lr_tr_stats *st, lr_err *e)
{
    size_t n = t->n, n3 = 3 * (n ? n : 1);
    double *w0 = calloc(n3, sizeof *w0), *y = malloc((n ? n : 1) * sizeof *y);
    double *phi = calloc(n3, sizeof *phi);
    if (!w0 || !y || !phi) {
        free(w0);
        free(y);
        free(phi);
        return lr_err_set(e, LR_ENOMEM, "transrad: out of memory (transfer solve)");
    }
    /* W0: first interaction of the direct light. */
    for (size_t p = 0; p < n; p++) {
        const lr_tr_surf *sf = &t->surf[t->p[p].surface];
        for (int b = 0; b < 3; b++) {
            size_t i = 3 * p + (size_t)b;
            if (sf->d.kind != LR_TR_TRANSLUCENT) {
                w0[i] += sf->d.albedo[b] * t->Edir[i];
                continue;
            }
            w0[i] += t->Edir[i] - t->Ein[i];
        }
        if (sf->d.kind == LR_TR_TRANSLUCENT)
            for (size_t k = t->S.row[p]; k < t->S.row[p + 1]; k++)
                for (int b = 0; b < 3; b++)
                    w0[3 * (size_t)t->S.col[k] + (size_t)b] +=
                        (double)t->S.val[3 * k + (size_t)b] * t->Ein[3 * p + (size_t)b];
    }
    for (int b = 0; b < 3; b++)
        lu_solve(t, b, w0, y, sl->W);
    /* H, Hind, Wsss from the solution, and the residual of W = W0 + K W as a check. */
    memset(sl->Wsss, 0, 3 * n * sizeof *sl->Wsss);
    for (size_t p = 0; p < n; p++) {
        double h[3] = {0, 0, 0};
        for (size_t k = t->F.row[p]; k < t->F.row[p + 1]; k++)
            for (int b = 0; b < 3; b++)
                h[b] += t->F.val[k] * sl->W[3 * (size_t)t->F.col[k] + (size_t)b];
        const lr_tr_surf *sf = &t->surf[t->p[p].surface];
        for (int b = 0; b < 3; b++) {
            size_t i = 3 * p + (size_t)b;
            sl->Hind[i] = h[b];
            sl->H[i] = t->Edir[i] + h[b];
            if (sf->d.kind == LR_TR_TRANSLUCENT)
                phi[i] = t->Ein[i] + sf->t_hem * h[b];
        }
        if (sf->d.kind == LR_TR_TRANSLUCENT)
            for (size_t k = t->S.row[p]; k < t->S.row[p + 1]; k++)
                for (int b = 0; b < 3; b++)
                    sl->Wsss[3 * (size_t)t->S.col[k] + (size_t)b] +=
                        (double)t->S.val[3 * k + (size_t)b] * phi[3 * p + (size_t)b];
    }
    double dn = 0, nn = 0;
    for (size_t p = 0; p < n; p++) {
        const lr_tr_surf *sf = &t->surf[t->p[p].surface];
        for (int b = 0; b < 3; b++) {
            size_t i = 3 * p + (size_t)b;
            double w = sf->d.kind == LR_TR_TRANSLUCENT
                           ? sl->Wsss[i] + (t->Edir[i] - t->Ein[i]) + (1 - sf->t_hem) * sl->Hind[i]
                           : sf->d.albedo[b] * sl->H[i];
            dn += t->p[p].area * fabs(w - sl->W[i]);
            nn += t->p[p].area * fabs(w);
        }
    }
    free(w0);
    free(y);
    free(phi);
    st->iterations = 0;
    st->residual = st->residual10 = nn > 0 ? dn / nn : 0;
    st->transfer = true;
    return LR_OK;
}
