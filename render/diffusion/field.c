/* lamprig — the surface radiosity field the renderer interpolates (dgrid.h).
 *
 * B = (phi - 2 q) / (2 A) is a surface quantity (dgrid.h, seed 001 Eq. 3). The renderer needs it
 * at map texels anywhere on the surface, so each node within the band gets B at its closest
 * surface point (the value extended along the normal); a texel's B is the trilinear blend of
 * its cell's corners, renormalised over the corners that have a value. The GPU pass
 * (render/shaders/lib/dgrid.glsl) and the CPU twin (lr_dfield_eval) do the same arithmetic.
 */
#include <math.h>
#include <string.h>

#include "render/diffusion/dgrid.h"
#include "render/diffusion/dgrid_internal.h"

int lr_dsolver_field(const lr_dsolver *s, int slot, lr_dirradiance_fn q, const void *qctx,
                     float *out, lr_err *e)
{
    lr_dgrey g = {q, qctx};
    return lr_dsolver_field_rgb(s, slot, lr_dgrey_q, &g, out, e);
}

int lr_dsolver_field_rgb(const lr_dsolver *s, int slot, lr_dirradiance_rgb_fn q,
                         const void *qctx, float *out, lr_err *e)
{
    if (slot < 0 || slot >= LR_DSOLVER_SLOTS)
        return lr_err_set(e, LR_EINVAL, "diffusion field: slot %d out of range", slot);
    const lr_dgrid *g = lr_dsolver_grid(s);
    memset(out, 0, 4 * g->count * sizeof *out);
    double twoA = 2.0 * lr_dsystem_A(lr_dsolver_system(s, 0));
    for (size_t k = 0; k < g->n_band; k++) {
        lr_vec3 b = g->band_b[k];
        double qb[3];
        q(qctx, b, g->band_n[k], qb);
        float *o = out + 4 * g->band_node[k];
        for (int c = 0; c < 3; c++) {
            double qc = isfinite(qb[c]) && qb[c] >= 0.0 ? qb[c] : 0.0;
            double phi = lr_dgrid_sample(g, lr_dsolver_phi(s, slot, c), b);
            /* Clamped at 0: interpolation can undershoot where q jumps (a shadow edge). */
            o[c] = (float)fmax(0.0, (phi - 2.0 * qc) / twoA);
        }
        o[3] = 1.0f;
    }
    return LR_OK;
}

void lr_dfield_eval(const float *field, const int n[3], lr_vec3 origin, double h, lr_vec3 p,
                    double out[3])
{
    out[0] = out[1] = out[2] = 0.0;
    double f[3] = {(p.x - origin.x) / h, (p.y - origin.y) / h, (p.z - origin.z) / h};
    int c0[3];
    double t[3];
    for (int a = 0; a < 3; a++) {
        if (!isfinite(f[a]))
            return;
        if (n[a] == 1) {
            c0[a] = 0;
            t[a] = 0.0;
            continue;
        }
        double fl = floor(f[a]);
        c0[a] = (int)fmax(0.0, fmin((double)(n[a] - 2), fl));
        t[a] = fmin(1.0, fmax(0.0, f[a] - c0[a]));
    }
    double acc[3] = {0.0, 0.0, 0.0}, wsum = 0.0;
    for (int k = 0; k < 2; k++)
        for (int j = 0; j < 2; j++)
            for (int i = 0; i < 2; i++) {
                int ii = n[0] == 1 ? 0 : c0[0] + i, jj = n[1] == 1 ? 0 : c0[1] + j,
                    kk = n[2] == 1 ? 0 : c0[2] + k;
                double w = (i ? t[0] : 1.0 - t[0]) * (j ? t[1] : 1.0 - t[1]) *
                           (k ? t[2] : 1.0 - t[2]);
                const float *v = field + 4 * (((size_t)kk * (size_t)n[1] + (size_t)jj) *
                                                  (size_t)n[0] + (size_t)ii);
                w *= v[3];
                wsum += w;
                for (int c = 0; c < 3; c++)
                    acc[c] += w * v[c];
            }
    if (wsum > 1e-6)
        for (int c = 0; c < 3; c++)
            out[c] = acc[c] / wsum;
}
