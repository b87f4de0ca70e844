/* lamprig — the CPU light-propagation volume: storage, injection, blocking, gathering
 * (lpv.h; the propagation step is propagate.c). */
#include "render/lpv/lpv.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/lpv/sh4.h"

struct lr_lpv {
    lr_lpv_desc d;
    lr_lpv_stencil st;
    double *cur, *tmp; /* n^3 * 12 */
    double *scale;     /* n^3 * 3: lr_lpv_step's scratch */
    double *abs;       /* (n+1)^3 * 18 */
    float *blk;              /* (n+1)^3 * 4 */
    double dropped[3];
};

static size_t cells(int n) { return (size_t)n * n * n; }
static size_t corners(int n) { return (size_t)(n + 1) * (n + 1) * (n + 1); }

int lr_lpv_create(const lr_lpv_desc *d, lr_lpv **out, lr_err *e)
{
    *out = NULL;
    if (d->n < LR_LPV_MIN_N || d->n > LR_LPV_MAX_N)
        return lr_err_set(e, LR_EINVAL, "lpv: n = %d cells per axis, must be %d to %d", d->n,
                          LR_LPV_MIN_N, LR_LPV_MAX_N);
    if (!isfinite(d->cell) || d->cell <= 0.0)
        return lr_err_set(e, LR_EINVAL, "lpv: cell = %g mm, must be finite and > 0", d->cell);
    if (!lr_v3_isfinite(d->origin))
        return lr_err_set(e, LR_EINVAL, "lpv: origin is not finite");
    lr_lpv *v = calloc(1, sizeof *v);
    if (!v)
        return lr_err_set(e, LR_ENOMEM, "lpv: out of memory");
    v->d = *d;
    size_t m = cells(d->n) * 12;
    v->cur = calloc(m, sizeof *v->cur);
    v->abs = calloc(corners(d->n) * 18, sizeof *v->abs);
    v->tmp = calloc(m, sizeof *v->tmp);
    v->blk = calloc(corners(d->n) * 4, sizeof *v->blk);
    v->scale = calloc(cells(d->n) * 3, sizeof *v->scale);
    if (!v->cur || !v->abs || !v->tmp || !v->blk || !v->scale) {
        lr_lpv_destroy(v);
        return lr_err_set(e, LR_ENOMEM, "lpv: out of memory for %d^3 cells", d->n);
    }
    lr_lpv_stencil_make(&v->st);
    *out = v;
    return LR_OK;
}

void lr_lpv_destroy(lr_lpv *v)
{
    if (!v)
        return;
    free(v->cur);
    free(v->abs);
    free(v->tmp);
    free(v->blk);
    free(v->scale);
    free(v);
}

int lr_lpv_desc_around(lr_vec3 lo, lr_vec3 hi, double margin, int n, lr_lpv_desc *d, lr_err *e)
{
    if (!lr_v3_isfinite(lo) || !lr_v3_isfinite(hi) || !isfinite(margin) || margin < 0.0)
        return lr_err_set(e, LR_EINVAL, "lpv: bounds or margin not finite");
    if (hi.x < lo.x || hi.y < lo.y || hi.z < lo.z)
        return lr_err_set(e, LR_EINVAL, "lpv: empty bounds");
    if (n < LR_LPV_MIN_N || n > LR_LPV_MAX_N)
        return lr_err_set(e, LR_EINVAL, "lpv: n = %d cells per axis, must be %d to %d", n,
                          LR_LPV_MIN_N, LR_LPV_MAX_N);
    lr_vec3 ext = lr_v3_sub(hi, lo);
    double side = fmax(ext.x, fmax(ext.y, ext.z)) + 2.0 * margin;
    if (!(side > 0.0))
        return lr_err_set(e, LR_EINVAL, "lpv: the box has no extent");
    lr_vec3 c = lr_v3_scale(lr_v3_add(lo, hi), 0.5);
    d->n = n;
    d->cell = side / n;
    d->origin = lr_v3_sub(c, lr_v3(side / 2, side / 2, side / 2));
    return LR_OK;
}

int lr_lpv_n(const lr_lpv *v) { return v->d.n; }
double lr_lpv_h(const lr_lpv *v) { return v->d.cell; }
lr_vec3 lr_lpv_origin(const lr_lpv *v) { return v->d.origin; }
const lr_lpv_stencil *lr_lpv_stencil_of(const lr_lpv *v) { return &v->st; }

void lr_lpv_clear_light(lr_lpv *v)
{
    size_t m = cells(v->d.n) * 12;
    memset(v->cur, 0, m * sizeof *v->cur);
    memset(v->abs, 0, corners(v->d.n) * 18 * sizeof *v->abs);
    v->dropped[0] = v->dropped[1] = v->dropped[2] = 0.0;
}

void lr_lpv_clear_blocking(lr_lpv *v) { memset(v->blk, 0, corners(v->d.n) * 4 * sizeof *v->blk); }

/* p in cell units (0 at the origin corner). */
static lr_vec3 to_grid(const lr_lpv *v, lr_vec3 p)
{
    return lr_v3_scale(lr_v3_sub(p, v->d.origin), 1.0 / v->d.cell);
}

int lr_lpv_cell_of(const lr_lpv *v, lr_vec3 p, int ijk[3])
{
    lr_vec3 u = to_grid(v, p);
    double c[3] = {floor(u.x), floor(u.y), floor(u.z)};
    for (int a = 0; a < 3; a++) {
        if (!(c[a] >= 0.0 && c[a] < v->d.n))
            return -1;
        ijk[a] = (int)c[a];
    }
    return 0;
}

static void add_sh(lr_lpv *v, const int ijk[3], const double c[4], const double s[3])
{
    size_t n = (size_t)v->d.n, base = (((size_t)ijk[2] * n + ijk[1]) * n + ijk[0]) * 12;
    for (int ch = 0; ch < 3; ch++)
        for (int i = 0; i < 4; i++)
            v->cur[base + ch * 4 + i] += s[ch] * c[i];
}

static int check_flux(const double phi[3], lr_err *e)
{
    for (int ch = 0; ch < 3; ch++)
        if (!isfinite(phi[ch]) || phi[ch] < 0.0)
            return lr_err_set(e, LR_EINVAL, "lpv: flux[%d] = %g, must be finite and >= 0", ch,
                              phi[ch]);
    return LR_OK;
}

int lr_lpv_inject_lobe(lr_lpv *v, lr_vec3 p, lr_vec3 n, const double phi[3], lr_err *e)
{
    if (!lr_v3_isfinite(p) || !lr_v3_isfinite(n))
        return lr_err_set(e, LR_EINVAL, "lpv: injected sample's position or normal not finite");
    if (fabs(lr_v3_len(n) - 1.0) > 1e-6)
        return lr_err_set(e, LR_EINVAL, "lpv: injected sample's normal has length %g, not 1",
                          lr_v3_len(n));
    int rc = check_flux(phi, e);
    if (rc)
        return rc;
    int ijk[3];
    /* Eq. 4: one unit (cell) along the normal, so the lobe starts outside the surface's own
     * cell and its blocked interface. */
    if (lr_lpv_cell_of(v, lr_v3_add(p, lr_v3_scale(n, v->d.cell)), ijk)) {
        for (int ch = 0; ch < 3; ch++)
            v->dropped[ch] += phi[ch];
        return LR_OK;
    }
    double c[4], s[3];
    lr_sh4_cosine_lobe(n, c);
    for (int ch = 0; ch < 3; ch++)
        s[ch] = phi[ch] / M_PI;
    add_sh(v, ijk, c, s);
    return LR_OK;
}

int lr_lpv_inject_point(lr_lpv *v, lr_vec3 p, const double phi[3], lr_err *e)
{
    if (!lr_v3_isfinite(p))
        return lr_err_set(e, LR_EINVAL, "lpv: point light's position not finite");
    int rc = check_flux(phi, e);
    if (rc)
        return rc;
    int ijk[3];
    if (lr_lpv_cell_of(v, p, ijk)) {
        for (int ch = 0; ch < 3; ch++)
            v->dropped[ch] += phi[ch];
        return LR_OK;
    }
    /* I = phi / (4 pi): c_00 = integral I k0 dw = phi k0. */
    double c[4] = {LR_SH4_K0, 0, 0, 0};
    add_sh(v, ijk, c, phi);
    return LR_OK;
}

double lr_lpv_dropped(const lr_lpv *v, int ch) { return v->dropped[ch]; }

int lr_lpv_add_blocker(lr_lpv *v, lr_vec3 p, lr_vec3 n, double area, lr_err *e)
{
    if (!lr_v3_isfinite(p) || !lr_v3_isfinite(n) || !isfinite(area) || area < 0.0)
        return lr_err_set(e, LR_EINVAL, "lpv: blocker sample not finite or negative area");
    lr_vec3 u = to_grid(v, p);
    double uu[3] = {u.x, u.y, u.z}, nn[3] = {n.x, n.y, n.z};
    int n1 = v->d.n + 1;
    double h2 = v->d.cell * v->d.cell;
    for (int a = 0; a < 3; a++) {
        /* The interface nearest p along a; the cells' indices across. */
        double idx[3];
        for (int b = 0; b < 3; b++)
            idx[b] = b == a ? floor(uu[b] + 0.5) : floor(uu[b]);
        int ok = 1;
        for (int b = 0; b < 3; b++)
            ok &= idx[b] >= 0.0 && idx[b] <= (b == a ? v->d.n : v->d.n - 1);
        if (!ok)
            continue;
        size_t at = (((size_t)idx[2] * n1 + (size_t)idx[1]) * n1 + (size_t)idx[0]) * 4 + a;
        v->blk[at] += (float)(area * fabs(nn[a]) / h2);
    }
    return LR_OK;
}

int lr_lpv_propagate(lr_lpv *v, int steps, lr_err *e)
{
    if (steps < 0 || steps > 4 * v->d.n)
        return lr_err_set(e, LR_EINVAL, "lpv: steps = %d, must be 0 to %d (4 n)", steps,
                          4 * v->d.n);
    for (int s = 0; s < steps; s++) {
        lr_lpv_step(&v->st, v->d.n, v->blk, v->cur, v->tmp, v->abs, v->scale);
        double *t = v->cur;
        v->cur = v->tmp;
        v->tmp = t;
    }
    return LR_OK;
}

double lr_lpv_total_flux(const lr_lpv *v, int ch)
{
    double s = 0.0;
    for (size_t c = 0; c < cells(v->d.n); c++)
        s += lr_sh4_flux(&v->cur[c * 12 + ch * 4]);
    return s;
}

double lr_lpv_absorbed_flux(const lr_lpv *v, int ch)
{
    double s = 0.0;
    for (size_t i = 0; i < corners(v->d.n) * 6; i++)
        s += v->abs[i * 3 + ch];
    return s;
}

/* The light arriving through side s of interface idx along a, per unit area: what the
 * blocked part absorbed over the open part's area (lr_lpv_face_fn). */
static bool volume_face(const void *ctx, const int idx[3], int a, int s, double out[3])
{
    const lr_lpv *v = ctx;
    int n1 = v->d.n + 1;
    double h2 = v->d.cell * v->d.cell;
    size_t iface = ((size_t)idx[2] * n1 + idx[1]) * n1 + idx[0];
    double B = fmin(1.0, v->blk[iface * 4 + a]);
    if (!(B > 0.0))
        return false;
    for (int ch = 0; ch < 3; ch++)
        out[ch] = v->abs[(iface * 6 + 2 * a + s) * 3 + ch] / (B * h2);
    return true;
}

void lr_lpv_irradiance(const lr_lpv *v, lr_vec3 x, lr_vec3 n, double E[3])
{
    lr_vec3 u = to_grid(v, x);
    double uu[3] = {u.x, u.y, u.z};
    lr_lpv_face_gather(v->d.n, uu, n, volume_face, v, E);
}

const double *lr_lpv_grid(const lr_lpv *v) { return v->cur; }

void lr_lpv_set_state(lr_lpv *v, const double *grid, const double *absorbed)
{
    if (grid)
        memcpy(v->cur, grid, cells(v->d.n) * 12 * sizeof *grid);
    if (absorbed)
        memcpy(v->abs, absorbed, corners(v->d.n) * 18 * sizeof *absorbed);
}

const float *lr_lpv_blocking(const lr_lpv *v) { return v->blk; }
const double *lr_lpv_absorbed(const lr_lpv *v) { return v->abs; }
