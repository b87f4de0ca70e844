/* lamprig — translucent radiosity: the solve of B = (I - S F)^-1 S E (seed 000 Eq. 14).
 *
 * Seed 000 Sec. 3 solves Eq. 14 "by iterative methods, such as Jacobi or Gauss-Seidel"; Sec. 5's
 * GPU solver is Jacobi (L = S E, then L <- S E + S F L). Here Gauss-Seidel: patch by patch,
 * the light arriving from the others, H_p = sum_q F_pq W_q (Eq. 13's F W, with the W already
 * updated in this sweep), and the change of what enters p scattered through S's column p
 * at once; about twice Jacobi's rate in a closed cavity (sphere_shell: 0.5 % after 10 sweeps
 * needs it). Sweeps stop when the change is below the tolerance. It converges because every column of S sums below 1 (in power) and
 * every row of F to at most 1 (Sec. 3: rho(S F) <= rho(S) rho(F) < 1); each sweep's change is
 * the residual of the fixed point W = S E + S F W. Diffuse patches have S = their albedo (the
 * classical radiosity of Eq. 2). A translucent patch lets in F_t of its direct light and
 * T_hem of the diffuse light reaching it, and reflects the rest (W_refl). The sweep starts
 * from the slot's last solution (a light move: the previous position's answer). */
#include "render/transrad/tr_priv.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

static int slot_alloc(lr_tr *t, int slot, lr_err *e)
{
    lr_tr_slot *s = &t->slot[slot];
    if (s->W)
        return LR_OK;
    size_t n3 = 3 * (t->n ? t->n : 1);
    s->W = calloc(n3, sizeof *s->W);
    s->Wsss = calloc(n3, sizeof *s->Wsss);
    s->H = calloc(n3, sizeof *s->H);
    s->Hind = calloc(n3, sizeof *s->Hind);
    if (!s->W || !s->Wsss || !s->H || !s->Hind)
        return lr_err_set(e, LR_ENOMEM, "transrad: out of memory (slot %d)", slot);
    return LR_OK;
}

static int solve(lr_tr *t, int slot, lr_tr_stats *st, lr_err *e)
{
    double t0 = now_ms();
    int rc = slot_alloc(t, slot, e);
    if (rc)
        return rc;
    lr_tr_slot *sl = &t->slot[slot];
    if (t->X.built) {
        lr_tr_stats s = {0};
        rc = lr_tr_transfer_solve(t, sl, &s, e);
        if (rc)
            return rc;
        sl->valid = true;
        s.ms_solve = now_ms() - t0;
        if (st) {
            s.ms_direct = st->ms_direct;
            *st = s;
        }
        return LR_OK;
    }
    size_t n = t->n;
    double *Wn = malloc(3 * (n ? n : 1) * sizeof *Wn);
    double *phi = malloc(3 * (n ? n : 1) * sizeof *phi);
    if (!Wn || !phi) {
        free(Wn);
        free(phi);
        return lr_err_set(e, LR_ENOMEM, "transrad: out of memory (solve)");
    }
    double *refl = calloc(3 * (n ? n : 1), sizeof *refl);
    if (!refl) {
        free(Wn);
        free(phi);
        return lr_err_set(e, LR_ENOMEM, "transrad: out of memory (solve)");
    }
    /* The state the sweeps update in place: phi (what entered each translucent patch), refl
     * (what its interface reflected), Wsss = S phi and W. A warm start rebuilds phi and refl
     * from the slot's W against the new E, so W stays consistent with them. */
    if (!sl->valid)
        memset(sl->W, 0, 3 * n * sizeof *sl->W);
    memset(phi, 0, 3 * n * sizeof *phi);
    memset(sl->Wsss, 0, 3 * n * sizeof *sl->Wsss);
    lr_tr_stats s = {0};
    for (int it = 0; it < t->set.max_iterations; it++) {
        if (lr_cancel_requested(t->set.cancel)) {
            /* W is a partial sweep's: not a solution (H, Hind are the last solve's), but a fine
             * warm start (a warm start rebuilds phi and refl from W against the new E); the
             * slot is read only after a whole solve. */
            free(refl);
            free(Wn);
            free(phi);
            return lr_cancel_check(t->set.cancel, "transrad: solve", e);
        }
        memcpy(Wn, sl->W, 3 * n * sizeof *Wn);
        /* Gauss-Seidel: patch p gathers H_p = F_p. W from the latest W (patches before it in
         * this sweep included) and scatters the change of what enters it through column p
         * of S at once. */
        for (size_t p = 0; p < n; p++) {
            double h[3] = {0, 0, 0};
            for (size_t k = t->F.row[p]; k < t->F.row[p + 1]; k++) {
                const double *w = sl->W + 3 * (size_t)t->F.col[k];
                for (int b = 0; b < 3; b++)
                    h[b] += t->F.val[k] * w[b];
            }
            const lr_tr_surf *sf = &t->surf[t->p[p].surface];
            double *Wp = sl->W + 3 * p;
            if (sf->d.kind != LR_TR_TRANSLUCENT) {
                for (int b = 0; b < 3; b++)
                    Wp[b] = sf->d.albedo[b] * (t->Edir[3 * p + (size_t)b] + h[b]);
                continue;
            }
            double dphi[3];
            for (int b = 0; b < 3; b++) {
                size_t i = 3 * p + (size_t)b;
                double np = t->Ein[i] + sf->t_hem * h[b];
                double nr = (t->Edir[i] - t->Ein[i]) + (1 - sf->t_hem) * h[b];
                dphi[b] = np - phi[i];
                phi[i] = np;
                if (it > 0)
                    Wp[b] += nr - refl[i];
                refl[i] = nr;
            }
            if (dphi[0] == 0 && dphi[1] == 0 && dphi[2] == 0)
                continue;
            for (size_t k = t->S.row[p]; k < t->S.row[p + 1]; k++) {
                size_t j = (size_t)t->S.col[k];
                const float *v = t->S.val + 3 * k;
                for (int b = 0; b < 3; b++) {
                    double d = v[b] * dphi[b];
                    sl->Wsss[3 * j + (size_t)b] += d;
                    if (it > 0)
                        sl->W[3 * j + (size_t)b] += d;
                }
            }
        }
        if (it == 0) {
            /* The first sweep built phi, refl and Wsss from scratch while the translucent
             * patches' W still held the warm start (or 0) for the gathers; from here W is
             * Wsss + refl, updated in place. */
            for (size_t p = 0; p < n; p++)
                if (t->surf[t->p[p].surface].d.kind == LR_TR_TRANSLUCENT)
                    for (int b = 0; b < 3; b++)
                        sl->W[3 * p + (size_t)b] = sl->Wsss[3 * p + (size_t)b] + refl[3 * p + (size_t)b];
        }
        double dn = 0, nn = 0;
        for (size_t p = 0; p < n; p++)
            for (int b = 0; b < 3; b++) {
                size_t i = 3 * p + (size_t)b;
                dn += t->p[p].area * fabs(sl->W[i] - Wn[i]);
                nn += t->p[p].area * fabs(sl->W[i]);
            }
        s.iterations = it + 1;
        s.residual = nn > 0 ? dn / nn : 0;
        if (it < 10)
            s.residual10 = s.residual;
        if (s.residual < t->set.tolerance)
            break;
    }
    free(refl);
    /* H, Hind consistent with the final W. */
    for (size_t p = 0; p < n; p++) {
        double h[3] = {0, 0, 0};
        for (size_t k = t->F.row[p]; k < t->F.row[p + 1]; k++)
            for (int b = 0; b < 3; b++)
                h[b] += t->F.val[k] * sl->W[3 * (size_t)t->F.col[k] + (size_t)b];
        for (int b = 0; b < 3; b++) {
            sl->Hind[3 * p + (size_t)b] = h[b];
            sl->H[3 * p + (size_t)b] = t->Edir[3 * p + (size_t)b] + h[b];
        }
    }
    sl->valid = true;
    free(Wn);
    free(phi);
    s.ms_solve = now_ms() - t0;
    if (st) {
        double md = st->ms_direct;
        *st = s;
        st->ms_direct = md;
    }
    return LR_OK;
}

int lr_tr_solve_light(lr_tr *t, const lr_light *light, int slot, lr_tr_stats *st, lr_err *e)
{
    if (!t || !light || slot < 0 || slot >= LR_TR_MAX_SLOTS)
        return lr_err_set(e, LR_EINVAL, "transrad: field 'slot': %d outside [0, %d)", slot,
                          LR_TR_MAX_SLOTS);
    double t0 = now_ms();
    int rc = lr_tr_direct(t, light, e);
    if (rc)
        return rc;
    if (st)
        st->ms_direct = now_ms() - t0;
    return solve(t, slot, st, e);
}

int lr_tr_solve_irradiance(lr_tr *t, const double *E, int slot, lr_tr_stats *st, lr_err *e)
{
    if (!t || !E || slot < 0 || slot >= LR_TR_MAX_SLOTS)
        return lr_err_set(e, LR_EINVAL, "transrad: field 'slot': %d outside [0, %d)", slot,
                          LR_TR_MAX_SLOTS);
    for (size_t p = 0; p < t->n; p++) {
        const lr_tr_surf *sf = &t->surf[t->p[p].surface];
        for (int b = 0; b < 3; b++) {
            size_t i = 3 * p + (size_t)b;
            if (!isfinite(E[i]) || E[i] < 0)
                return lr_err_set(e, LR_EINVAL, "transrad: field 'E': patch %zu band %d: %g", p,
                                  b, E[i]);
            t->Edir[i] = E[i];
            t->Ein[i] = sf->d.kind == LR_TR_TRANSLUCENT ? sf->t_hem * E[i] : E[i];
        }
    }
    if (st)
        st->ms_direct = 0;
    return solve(t, slot, st, e);
}

static const double *slot_arr(const lr_tr *t, int slot, int which)
{
    if (!t || slot < 0 || slot >= LR_TR_MAX_SLOTS || !t->slot[slot].valid)
        return NULL;
    const lr_tr_slot *s = &t->slot[slot];
    return which == 0 ? s->W : which == 1 ? s->H : which == 2 ? s->Hind : s->Wsss;
}

static void get3(const lr_tr *t, int slot, int which, size_t p, double out[3])
{
    const double *a = slot_arr(t, slot, which);
    for (int b = 0; b < 3; b++)
        out[b] = a && p < t->n ? a[3 * p + (size_t)b] : 0;
}

void lr_tr_radiosity(const lr_tr *t, int slot, size_t p, double out[3]) { get3(t, slot, 0, p, out); }
void lr_tr_irradiance(const lr_tr *t, int slot, size_t p, double out[3]) { get3(t, slot, 1, p, out); }
void lr_tr_indirect(const lr_tr *t, int slot, size_t p, double out[3]) { get3(t, slot, 2, p, out); }

void lr_tr_map_radiosity(const lr_tr *t, int slot, size_t p, double out[3])
{
    get3(t, slot, 3, p, out);
    if (p < t->n) {
        const lr_tr_surf *sf = &t->surf[t->p[p].surface];
        for (int b = 0; b < 3; b++)
            out[b] = sf->d.kind == LR_TR_TRANSLUCENT && sf->t_hem > 0 ? out[b] / sf->t_hem : 0;
    }
}

void lr_tr_escaped_power(const lr_tr *t, int slot, double out[3])
{
    out[0] = out[1] = out[2] = 0;
    const double *W = slot_arr(t, slot, 0);
    if (!W)
        return;
    for (size_t p = 0; p < t->n; p++)
        for (int b = 0; b < 3; b++)
            out[b] += t->p[p].area * W[3 * p + (size_t)b] * t->escape[p];
}
