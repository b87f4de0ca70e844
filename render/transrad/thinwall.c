/* lamprig — translucent radiosity: S on a wall much thinner than its patches.
 *
 * subsurface.c evaluates the slab multipole (Donner & Jensen 2005) at the distance from 256
 * entry points spread over the source patch i to the centroid of the exit patch j (seed 000
 * Sec. 4.1), then scales the column to the slab's plane total R + T. That is right when the
 * profile is wide against the spacing of those points (patch_mm / 16, 0.75 mm at 12 mm). On a
 * 0.1 mm paper wall the profiles hold 90 % of their light within 0.1 mm (R) and 0.15 mm (T):
 * the sums see only the profiles' tails, where R(r) and T(r) tend to the same value (the slab's
 * lowest diffusion mode is symmetric across the wall), so the column sends about half of its
 * light out of each face while the slab sends R / (R + T) = 0.77 back out of the lit one. The
 * led_shade's outer face came out 1.8x too bright and its inner face 0.71 (issue 12).
 *
 * The thin-wall column (seed 000 Eq. 8, S_ji = int_{A_i} int_{A_j} Rd(x, y) dy dx / A_i with
 * the slab's two profiles, integrated over both patches by Monte Carlo): per unit power that
 * enters at a point x of patch i, the slab sends R_tot (lr_multipole_total, closed form) out
 * of the lit face, spread about x by the radial density 2 pi r R(r) / R_tot, and T_tot out of
 * the opposite face, spread about the point across the wall below x by 2 pi r T(r) / T_tot.
 * For each of M entry points x_k (lr_tr_patch_point) one exit radius per profile and band is
 * drawn from the tabulated inverse CDF and one direction (Halton), the exit point is placed in
 * x_k's tangent plane (the wall is flat over the spread) and found on the mesh by a ray along
 * -n: the first front face near the tangent plane (lit face) or the first face where that ray
 * leaves the material within 3 d (opposite face). Then
 *
 *     A_j S_ji / A_i = P_tot (hits in j) / M,     P_tot = R_tot (lit face) or T_tot (opposite),
 *
 * so every column leaves exactly R_tot + T_tot, split between the faces as the slab does; the
 * exit is integrated over the exit patch (no centroid), so a paper wall's light lands under the
 * patch where it entered instead of at whichever centroid an entry point happened to fall
 * next to. An exit past the wall's end (a rim: the votive's 7 mm wax, spread over
 * millimetres) leaves through the end face the spread crosses (end_patch: a ray at mid-wall
 * along the spread); left where it entered, the votive's rim, which glows in the
 * reference, rendered at the wall's level: 83 % of its receiver error (render/
 * transrad/README.md). One that finds no face at all (an open one-sided edge; a rim patch's
 * own ray, which runs along the wall instead of across it) falls back to the unshifted point,
 * then to patch i itself: the light stays in the object (energy kept).
 *
 * The rule (lr_tr_wall_thin): thin when the wall is no thicker than a patch, d <= patch_mm.
 * T spreads over about d and the two faces' patches overlap, so the centroid sums, which fix
 * the exit at one centroid per patch, get the split between the faces wrong: at 12 mm
 * patches paper 0.1 mm sent 0.47 of the light out of the far face for T 0.22, porcelain
 * 1.5 mm 0.117 / 0.093 / 0.061 for T 0.100 / 0.076 / 0.045, and the votive's 7 mm wax (once
 * its mesh was refined into 12 mm patches) 0.26 for T 0.19. An earlier rule,
 * r90 <= patch_mm / 4 (the wider profile's 90 % radius), left the wax to the sums on the
 * belief that wide profiles make them accurate; a wall curved over tens of patches is still
 * flat over d (the shades' radii are 70-110 mm, the votive's 33-40 mm). Thicker bodies (the
 * candle's 40-120 mm under its pool) keep the sums, whose in-object distances carry light
 * round rims and into floors.
 * Measured on the fair bench (tools/bench/README.md): led_shade objects / receivers 0.821 /
 * 0.335 -> 0.160 / 0.081, lamp shade 0.162 / 0.101 -> 0.111 / 0.096. */
#include "render/transrad/tr_priv.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define TW_POINTS 256
/* Radius grid of the tabulated CDFs: 0 and log-spaced from 1e-4 L to 30 L, L = d + 2 z_b (the
 * slab with its extrapolated boundaries; its profiles decay at least as e^{-pi r / L}, so 30 L
 * leaves e^{-94}). */
#define TW_R_LO 1e-4
#define TW_R_HI 30.0

void lr_tr_spread_build(const lr_coeffs *c, double d, lr_tr_spread *sp)
{
    memset(sp, 0, sizeof *sp);
    double zb = 0;
    for (int b = 0; b < 3; b++)
        zb = fmax(zb, 2 * c->A * c->D[b]);
    double L = d + 2 * zb;
    int pairs = lr_multipole_pairs(c, d);
    lr_multipole_total(c, d, sp->total[0], sp->total[1]);
    double prev[2][3] = {{0}}, acc[2][3] = {{0}};
    for (int m = 0; m < LR_TR_SPREAD_RADII; m++) {
        double r = m == 0 ? 0
                          : L * TW_R_LO * pow(TW_R_HI / TW_R_LO,
                                              (m - 1) / (double)(LR_TR_SPREAD_RADII - 2));
        double P[2][3];
        lr_multipole_profile_n(c, d, pairs, r, P[0], P[1]);
        for (int w = 0; w < 2; w++)
            for (int b = 0; b < 3; b++) {
                double f = 2 * M_PI * r * P[w][b];
                if (m > 0) /* trapezoid in r */
                    acc[w][b] += 0.5 * (f + prev[w][b]) * (r - sp->r[m - 1]);
                prev[w][b] = f;
                sp->cdf[w][b][m] = acc[w][b];
            }
        sp->r[m] = r;
    }
    for (int w = 0; w < 2; w++)
        for (int b = 0; b < 3; b++)
            for (int m = 0; m < LR_TR_SPREAD_RADII; m++)
                sp->cdf[w][b][m] = acc[w][b] > 0 ? sp->cdf[w][b][m] / acc[w][b] : 1.0;
    sp->L = L;
}

double lr_tr_spread_radius(const lr_tr_spread *sp, int which, int band, double u)
{
    const double *F = sp->cdf[which][band];
    if (!(u > 0))
        return 0;
    int lo = 0, hi = LR_TR_SPREAD_RADII - 1;
    if (u >= F[hi])
        return sp->r[hi];
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (F[mid] < u)
            lo = mid;
        else
            hi = mid;
    }
    double w = F[hi] > F[lo] ? (u - F[lo]) / (F[hi] - F[lo]) : 0.5;
    return sp->r[lo] + w * (sp->r[hi] - sp->r[lo]);
}

double lr_tr_spread_r90(const lr_tr_spread *sp)
{
    double r = 0;
    for (int w = 0; w < 2; w++)
        for (int b = 0; b < 3; b++)
            if (sp->total[w][b] > 0)
                r = fmax(r, lr_tr_spread_radius(sp, w, b, 0.9));
    return r;
}

bool lr_tr_wall_thin(const lr_coeffs *c, double d, double patch_mm)
{
    return c && d > 0 && patch_mm > 0 && d <= patch_mm;
}

/* An orthonormal pair spanning the plane normal to n. */
static void tangents(lr_vec3 n, lr_vec3 *a, lr_vec3 *b)
{
    lr_vec3 h = fabs(n.x) < 0.6 ? lr_v3(1, 0, 0) : lr_v3(0, 1, 0);
    *a = lr_v3_normalize(lr_v3_cross(n, h));
    *b = lr_v3_cross(n, *a);
}

/* The patch of surface s that receives the exit: a ray from o along dir (= -n of the entry),
 * o lifted delta above the entry's tangent plane. lit: the first hit must be a front face
 * (the lit face seen from outside) within 2 delta (the tangent plane's sag on a wall curved no
 * more than the offset); opposite: the first face where the ray leaves the material (a back
 * face), within delta + 3 d. SIZE_MAX when none. */
static size_t exit_patch(const lr_tr *t, int s, lr_vec3 o, lr_vec3 dir, double delta, double d,
                         bool lit)
{
    const lr_tr_surf *sf = &t->surf[s];
    double tmin = 0, tmax = lit ? 2 * delta : delta + 3 * d;
    for (int k = 0; k < 4; k++) {
        lr_hit h;
        if (!lr_bvh_intersect(sf->d.bvh, o, dir, tmin, tmax, &h))
            return SIZE_MAX;
        bool back = lr_v3_dot(lr_mesh_triangle_normal(sf->d.mesh, h.triangle), dir) >= 0;
        if (lit)
            return back ? SIZE_MAX : sf->tri_patch[h.triangle];
        if (back)
            return sf->tri_patch[h.triangle];
        tmin = h.t * (1 + 1e-9) + 1e-9; /* the lit face: go on into the material */
    }
    return SIZE_MAX;
}

/* The end face the spread crosses: light spread past a wall's end (a rim) leaves through the
 * end, not back where it entered. A ray at mid-wall from the entry x (normal n) along the
 * spread's direction w, as far as the exit radius r: the first face it leaves the material by
 * (a back face), within r. SIZE_MAX when the spread ends inside the wall or the mesh has no
 * end face there (a one-sided shade). */
static size_t end_patch(const lr_tr *t, int s, lr_vec3 x, lr_vec3 n, lr_vec3 w, double r,
                        double d)
{
    const lr_tr_surf *sf = &t->surf[s];
    lr_vec3 o = lr_v3_sub(x, lr_v3_scale(n, 0.5 * d));
    lr_hit h;
    if (!lr_bvh_intersect(sf->d.bvh, o, w, 0, r, &h) ||
        lr_v3_dot(lr_mesh_triangle_normal(sf->d.mesh, h.triangle), w) < 0)
        return SIZE_MAX;
    return sf->tri_patch[h.triangle];
}

void lr_tr_thin_column(const lr_tr *t, int s, size_t i, double d, const lr_tr_spread *sp,
                       double *out)
{
    const lr_tr_surf *sf = &t->surf[s];
    size_t ns = sf->count, pi = sf->first + i;
    memset(out, 0, ns * 3 * sizeof *out);
    /* Ray offsets at the wall's scale, not the scene's (lr_tr_eps is 0.03 mm beside a 1.4 m
     * wall: a third of a paper sheet). */
    double eps = fmax(1e-4, fmin(lr_tr_eps(t), 0.05 * d));
    for (unsigned k = 0; k < TW_POINTS; k++) {
        lr_vec3 x, n, ta, tb;
        lr_tr_patch_point(t, pi, k, TW_POINTS, 0.5, 0.5, &x, &n);
        tangents(n, &ta, &tb);
        double u = lr_halton(k + 1, 5), phi = 2 * M_PI * lr_halton(k + 1, 7);
        lr_vec3 w = lr_v3_add(lr_v3_scale(ta, cos(phi)), lr_v3_scale(tb, sin(phi)));
        lr_vec3 dir = lr_v3_scale(n, -1);
        for (int which = 0; which < 2; which++) {
            size_t last = SIZE_MAX;
            double last_r = -1;
            for (int b = 0; b < 3; b++) {
                double r = lr_tr_spread_radius(sp, which, b, u);
                size_t j = last;
                /* Bands whose radii agree to a micrometre share the lookup. */
                if (!(fabs(r - last_r) <= 1e-3)) {
                    double delta = eps + 0.5 * r;
                    lr_vec3 o = lr_v3_add(x, lr_v3_add(lr_v3_scale(w, r), lr_v3_scale(n, delta)));
                    j = exit_patch(t, s, o, dir, delta, d, which == 0);
                    if (j == SIZE_MAX) /* past an edge: out of its end face */
                        j = end_patch(t, s, x, n, w, r, d);
                    if (j == SIZE_MAX) /* no end face: the unshifted exit */
                        j = exit_patch(t, s, lr_v3_add(x, lr_v3_scale(n, eps)), dir, eps, d,
                                       which == 0);
                    if (j == SIZE_MAX) /* a rim or an open edge: it stays where it entered */
                        j = pi;
                    last = j;
                    last_r = r;
                }
                out[3 * (j - sf->first) + (size_t)b] += sp->total[which][b] / TW_POINTS;
            }
        }
    }
    /* out holds A_j S_ji / A_i: the power fraction leaving j. */
    for (size_t j = 0; j < ns; j++)
        for (int b = 0; b < 3; b++)
            out[3 * j + b] *= t->p[pi].area / t->p[sf->first + j].area;
}

void lr_tr_subsurface_split(const lr_tr *t, int s, double lit[3], double opposite[3])
{
    for (int b = 0; b < 3; b++)
        lit[b] = opposite[b] = 0;
    if (!t || s < 0 || s >= t->nsurf || t->surf[s].d.kind != LR_TR_TRANSLUCENT)
        return;
    const lr_tr_surf *sf = &t->surf[s];
    double area = 0;
    for (size_t p = sf->first; p < sf->first + sf->count; p++) {
        area += t->p[p].area;
        for (size_t k = t->S.row[p]; k < t->S.row[p + 1]; k++) {
            size_t q = t->S.col[k];
            double *acc = lr_v3_dot(t->p[p].n, t->p[q].n) < 0 ? opposite : lit;
            for (int b = 0; b < 3; b++)
                acc[b] += t->p[q].area * t->S.val[3 * k + (size_t)b];
        }
    }
    for (int b = 0; b < 3; b++) {
        lit[b] = area > 0 ? lit[b] / area : 0;
        opposite[b] = area > 0 ? opposite[b] / area : 0;
    }
}
