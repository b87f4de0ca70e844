/* lamprig-transrad --split: the irradiance-weighted split of S's output by distance and by the
 * exit patch's facing. The half-space dipole's share within a radius, 2 pi int_0^r r' Rd(r')
 * dr' / Rd_tot (Jensen 2001 Eq. 4-5; trapezoid on a fine grid), is what a flat body would let
 * out there: an S that sends much less near the entry and more far from it spreads the light
 * that the profile keeps close. */
#include "tools/transrad/split.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#define NB 5
static const double edge[NB] = {0, 12, 24, 48, INFINITY}; /* upper edges; bin 0: j == i */
static const char *bname[NB] = {"same patch", "0-12 mm", "12-24 mm", "24-48 mm", "> 48 mm"};
#define NR 5
static const char *rname[NR] = {"up", "down", "inward", "outward upper", "outward lower"};

static void dipole_share(const lr_coeffs *c, double r, double out[3])
{
    double tot[3], acc[3] = {0, 0, 0}, prev[3] = {0, 0, 0};
    lr_dipole_rd_total(c, tot);
    int n = 4000;
    double rm = fmin(r, 1000.0), rp = 0;
    for (int k = 1; k <= n; k++) {
        double x = rm * (double)k * k / ((double)n * n), v[3];
        lr_dipole_rd(c, x, v);
        for (int b = 0; b < 3; b++) {
            double f = 2 * M_PI * x * v[b];
            acc[b] += 0.5 * (f + prev[b]) * (x - rp);
            prev[b] = f;
        }
        rp = x;
    }
    for (int b = 0; b < 3; b++)
        out[b] = tot[b] > 0 ? acc[b] / tot[b] : 0;
}

void lr_trtool_print_split(const lr_tr *t, int s, int slot, const lr_coeffs *c)
{
    size_t f, n;
    lr_tr_surface_patches(t, s, &f, &n);
    if (!n)
        return;
    lr_vec3 lo = {INFINITY, INFINITY, INFINITY}, hi = {-INFINITY, -INFINITY, -INFINITY};
    lr_vec3 *pc = malloc(n * sizeof *pc), *pn = malloc(n * sizeof *pn);
    double *pa = malloc(n * sizeof *pa);
    if (!pc || !pn || !pa) {
        free(pc);
        free(pn);
        free(pa);
        return;
    }
    for (size_t i = 0; i < n; i++) {
        lr_tr_patch_geometry(t, f + i, &pc[i], &pn[i], &pa[i]);
        lo = (lr_vec3){fmin(lo.x, pc[i].x), fmin(lo.y, pc[i].y), fmin(lo.z, pc[i].z)};
        hi = (lr_vec3){fmax(hi.x, pc[i].x), fmax(hi.y, pc[i].y), fmax(hi.z, pc[i].z)};
    }
    double cx = 0.5 * (lo.x + hi.x), cy = 0.5 * (lo.y + hi.y), zm = 0.5 * (lo.z + hi.z);
    double bin[NB][3] = {{0}}, reg[NR][3] = {{0}}, in[NR][3] = {{0}}, all[3] = {0, 0, 0};
    double selfsh[3] = {0, 0, 0}, selfdip[3] = {0, 0, 0}, win[3] = {0, 0, 0};
    int *rg = malloc(n * sizeof *rg);
    if (!rg) {
        free(pc);
        free(pn);
        free(pa);
        return;
    }
    for (size_t j = 0; j < n; j++) {
        double rx = pc[j].x - cx, ry = pc[j].y - cy, rl = hypot(rx, ry);
        double radial = rl > 0 ? (pn[j].x * rx + pn[j].y * ry) / rl : 0;
        rg[j] = pn[j].z > 0.7 ? 0 : pn[j].z < -0.7 ? 1 : radial < 0 ? 2 : pc[j].z > zm ? 3 : 4;
    }
    for (size_t i = 0; i < n; i++) {
        double H[3];
        lr_tr_irradiance(t, slot, f + i, H);
        double w[3] = {pa[i] * H[0], pa[i] * H[1], pa[i] * H[2]};
        if (!(w[1] > 0))
            continue;
        double colsum[3] = {0, 0, 0}, sii[3];
        for (size_t j = 0; j < n; j++) {
            double S[3];
            lr_tr_subsurface(t, f + j, f + i, S);
            double dist = j == i ? -1 : lr_v3_len(lr_v3_sub(pc[j], pc[i]));
            int k = 0;
            while (k < NB - 1 && dist >= edge[k])
                k++;
            for (int b = 0; b < 3; b++) {
                double p = w[b] * pa[j] * S[b] / pa[i]; /* power out of j from i's entry */
                bin[k][b] += p;
                reg[rg[j]][b] += p;
                all[b] += p;
                colsum[b] += pa[j] * S[b] / pa[i];
            }
        }
        /* The entry patch's own share of its column, against the dipole's share within the
         * equal-area disk (radius sqrt(A / pi)). */
        lr_tr_subsurface(t, f + i, f + i, sii);
        double dsh[3];
        dipole_share(c, sqrt(pa[i] / M_PI), dsh);
        for (int b = 0; b < 3; b++) {
            in[rg[i]][b] += w[b];
            if (colsum[b] > 0) {
                selfsh[b] += w[b] * sii[b] / colsum[b];
                selfdip[b] += w[b] * dsh[b];
                win[b] += w[b];
            }
        }
    }
    printf("surface %d (light %d): power S lets out %.4g %.4g %.4g (R G B), shares by distance "
           "entry -> exit centroid (half-space dipole within the radius in brackets, G):\n", s,
           slot, all[0], all[1], all[2]);
    for (int k = 0; k < NB; k++) {
        double d[3] = {0, 0, 0};
        if (k > 0 && isfinite(edge[k]))
            dipole_share(c, edge[k], d);
        printf("  %-10s %.3f %.3f %.3f", bname[k], bin[k][0] / all[0], bin[k][1] / all[1],
               bin[k][2] / all[2]);
        if (k > 0 && isfinite(edge[k]))
            printf("   [dipole within %g mm: %.3f]", edge[k], d[1]);
        printf("\n");
    }
    printf("  entry patch's own share of its column %.3f %.3f %.3f; the dipole within the "
           "patch's equal-area disk %.3f %.3f %.3f\n", selfsh[0] / win[0], selfsh[1] / win[1],
           selfsh[2] / win[2], selfdip[0] / win[0], selfdip[1] / win[1], selfdip[2] / win[2]);
    double tin[3] = {0, 0, 0};
    for (int r = 0; r < NR; r++)
        for (int b = 0; b < 3; b++)
            tin[b] += in[r][b];
    printf("  by facing (exit G share / entry G share):");
    for (int r = 0; r < NR; r++)
        printf(" %s %.3f / %.3f;", rname[r], reg[r][1] / all[1], in[r][1] / tin[1]);
    printf("\n");
    /* The solution per facing: irradiance arriving (all, of it the bounce) and radiosity
     * leaving, as power (G band), and the mean radiosity per mm^2. */
    double Hp[NR] = {0}, Ip[NR] = {0}, Wp[NR] = {0}, Ar[NR] = {0};
    for (size_t j = 0; j < n; j++) {
        double H[3], I[3], W[3];
        lr_tr_irradiance(t, slot, f + j, H);
        lr_tr_indirect(t, slot, f + j, I);
        lr_tr_radiosity(t, slot, f + j, W);
        Hp[rg[j]] += pa[j] * H[1];
        Ip[rg[j]] += pa[j] * I[1];
        Wp[rg[j]] += pa[j] * W[1];
        Ar[rg[j]] += pa[j];
    }
    printf("  solution by facing (G: area mm^2, irradiance power, of it bounce, radiosity power, "
           "mean radiosity):\n");
    for (int r = 0; r < NR; r++)
        printf("    %-14s %8.0f %10.4g %10.4g %10.4g %10.4g\n", rname[r], Ar[r], Hp[r], Ip[r],
               Wp[r], Ar[r] > 0 ? Wp[r] / Ar[r] : 0);
    free(rg);
    free(pc);
    free(pn);
    free(pa);
}
