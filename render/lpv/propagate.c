/* lamprig — one LPV propagation step (seed 004 Sec. 4.4, Eq. 9-16; lpv.h for the energy
 * scale and the blocking). Written as a gather over each destination cell's six neighbours,
 * the same order as the compute shader (render/shaders/lpv_propagate.comp), so the two agree
 * to float rounding. */
#include <math.h>
#include <string.h>

#include "render/lpv/lpv.h"
#include "render/lpv/sh4.h"

/* The scale that keeps the clamped face fluxes of source coefficients c within its flux. */
static double source_scale(const lr_lpv_stencil *st, const double *c)
{
    double phi = lr_sh4_flux(c), out = 0.0;
    if (!(phi > 0.0))
        return 0.0;
    for (int m = 0; m < 6; m++)
        for (int f = 0; f < 5; f++) {
            const double *v = st->v[m][f];
            out += fmax(0.0, v[0] * c[0] + v[1] * c[1] + v[2] * c[2] + v[3] * c[3]);
        }
    return out > phi ? phi / out : 1.0;
}

void lr_lpv_step(const lr_lpv_stencil *st, int n, const float *blocking, const double *src,
                 double *dst, double *absorbed, double *scale)
{
    size_t n1 = (size_t)n + 1;
    /* Each source cell's scale per channel, once a step: its six destinations read the same
     * value (the shader recomputes it per destination, in parallel; here that was six times
     * the 30 face products a source needs, most of a step's arithmetic). The same function
     * of the same coefficients, so the same numbers. */
    for (size_t c = 0; c < (size_t)n * n * n; c++)
        for (int ch = 0; ch < 3; ch++)
            scale[c * 3 + ch] = source_scale(st, &src[c * 12 + ch * 4]);
    for (int k = 0; k < n; k++)
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++) {
                int d[3] = {i, j, k};
                double *out = &dst[(((size_t)k * n + j) * n + i) * 12];
                memset(out, 0, 12 * sizeof *out);
                for (int m = 0; m < 6; m++) {
                    /* The source s = d - dir[m]. */
                    int s[3], a = m / 2, inside = 1;
                    for (int b = 0; b < 3; b++) {
                        s[b] = d[b] - st->dir[m][b];
                        inside &= s[b] >= 0 && s[b] < n;
                    }
                    if (!inside)
                        continue;
                    /* Their shared interface along a: index max(s_a, d_a), d's across. */
                    int f[3] = {d[0], d[1], d[2]};
                    f[a] = s[a] > d[a] ? s[a] : d[a];
                    size_t iface = ((size_t)f[2] * n1 + f[1]) * n1 + f[0];
                    double tr = 1.0 - fmin(1.0, (double)blocking[iface * 4 + a]);
                    /* The travel sign: 1 toward -axis. Only this destination's pass touches
                     * this interface in this direction, so the record needs no atomics. */
                    double *ab = &absorbed[(iface * 6 + 2 * a + (m % 2)) * 3];
                    size_t sidx = ((size_t)s[2] * n + s[1]) * n + s[0];
                    const double *cs = &src[sidx * 12];
                    for (int ch = 0; ch < 3; ch++) {
                        const double *c = &cs[ch * 4];
                        double sc = scale[sidx * 3 + ch];
                        if (sc <= 0.0)
                            continue;
                        double sent = 0.0;
                        for (int face = 0; face < 5; face++) {
                            const double *v = st->v[m][face];
                            double phi = v[0] * c[0] + v[1] * c[1] + v[2] * c[2] + v[3] * c[3];
                            if (phi <= 0.0)
                                continue;
                            sent += sc * phi;
                            /* Eq. 16: the face's flux as the lobe (phi / pi) max(0, n_f . w),
                             * times the interface's transmittance. */
                            for (int q = 0; q < 4; q++)
                                out[ch * 4 + q] += tr * sc * phi * st->lobe[m][face][q];
                        }
                        ab[ch] += (1.0 - tr) * sent;
                    }
                }
            }
}
