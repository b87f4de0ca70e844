/* lamprig — light-propagation volumes on the CPU (seed 004 Sec. 3.2 and 4.3-4.4, after
 * Kaplanyan & Dachsbacher 2010): a regular grid of n^3 cubic cells of side h over a box of the
 * scene, each holding the intensity distribution I(w) (W/sr, per unit light intensity when
 * the caller injects unit-intensity light) of the light passing through it as two-band SH per
 * colour channel (render/lpv/sh4.h), plus a blocking grid from a voxelisation of the scene's
 * surfaces.
 *
 *   inject     reflected flux Phi = rho E A of a surface sample as the lobe
 *              (Phi / pi) max(0, n . w) one cell off the surface (Eq. 3b-4), or any SH;
 *   propagate  k steps of the 6-neighbour face-flux transfer (Eq. 9-16, stencil.h) with
 *              geometry blocking; the result is the sum of the injected grid and every step's;
 *   gather     the irradiance of a surface from the light the volume delivered to it: the
 *              flux its blocked interfaces absorbed over all steps, per covered area.
 *
 * Energy. Two-band SH of a positive lobe go negative away from it, and the faces behind a
 * lobe get negative flux v_f . c_s. Kaplanyan & Dachsbacher clamp those to zero, which adds
 * energy at every step. Here the clamped face fluxes of a source cell are scaled by
 * min(1, Phi_s / sum_f max(0, v_f . c_s)), Phi_s = c_00 sqrt(4 pi) its flux: the 30 faces tile
 * the sphere, so sum_f v_f . c_s = Phi_s exactly, the scale is <= 1, and a cell sends out at
 * most what it holds. Blocking multiplies a transfer by a transmittance in [0, 1]. So the
 * volume's total flux never increases from one step to the next (exactly conserved in empty
 * space away from the border; flux leaving the box is dropped). The scale makes a step
 * positively homogeneous of degree 1, not additive: twice the light gives exactly twice the
 * volume, which is what the renderer's per-light, unit-intensity stores need (the dimmer
 * multiplies them); light from different lights must not share a volume.
 *
 * Blocking (Sec. 4.4's blocking potential B(w)). Per cell interface and axis: the projected
 * area sum A |n . e_axis| / h^2 of the surface samples nearest to that interface, clamped to
 * 1 when used, the fraction of the interface that surfaces cover for light crossing it. Light
 * from s to its neighbour d crosses their shared interface and is multiplied by 1 - B there.
 * (Kaplanyan & Dachsbacher store B in two-band SH at cell corners; two bands cannot hold a
 * two-sided |n . w|, whose l = 1 part vanishes, so a surface would block every direction
 * alike. Propagation only ever crosses axis-aligned interfaces, so the per-axis projection is
 * exact for what it is used for.) Blocked light is absorbed and recorded per interface, axis,
 * direction of travel and channel: that record is what the surfaces receive (gathering). The
 * bounce of light off surfaces enters the volume only by injection.
 *
 * Why gather the absorbed flux. Two-band lobes are broad (a clamped cosine is 1/4 + cos/2 of
 * its peak), so each step sends most of a lobe's flux sideways and propagation is close to
 * diffusion: the light dwells in a cell for several steps, and a gather from the accumulated
 * intensity (Kaplanyan & Dachsbacher's) overstates irradiance by that dwell time, which grows
 * with distance (about 3x at 5 cells, measured). The absorbed flux is exact bookkeeping
 * instead: a surface receives exactly what propagation delivered to it, so what the receivers
 * absorb plus what left the box plus what is still in flight is what was injected.
 *
 * Grid layout (also the GPU's): cell (i, j, k), i along x, index c = (k n + j) n + i; its
 * coefficients for channel ch at [c * 12 + ch * 4 + 0..3] in sh4.h's order. Blocking:
 * interface (i, j, k) of axis a is the face at index i (resp. j, k) along a between cells
 * i-1 and i, the other two indices those of the cells; stored at
 * [((k (n+1) + j) (n+1) + i) * 4 + a], (n+1)^3 * 4 floats (the 4th unused). Units: mm. */
#ifndef LR_LPV_H
#define LR_LPV_H

#include <stdbool.h>

#include "render/base/err.h"
#include "render/base/vec3.h"
#include "render/lpv/stencil.h"

#define LR_LPV_MIN_N 2
#define LR_LPV_MAX_N 128

typedef struct lr_lpv lr_lpv;

typedef struct lr_lpv_desc {
    lr_vec3 origin; /* the box's minimum corner, mm */
    double cell;    /* h, mm */
    int n;          /* cells per axis */
} lr_lpv_desc;

/* LR_EINVAL naming the field for n outside [2, 128], h not finite or <= 0, a non-finite
 * origin; LR_ENOMEM. */
int lr_lpv_create(const lr_lpv_desc *d, lr_lpv **out, lr_err *e);
void lr_lpv_destroy(lr_lpv *v);
/* A box of n^3 cubic cells around [lo, hi] (each side widened by `margin` mm, the longest
 * side split into n cells, the box centred). LR_EINVAL for an empty or non-finite box. */
int lr_lpv_desc_around(lr_vec3 lo, lr_vec3 hi, double margin, int n, lr_lpv_desc *d,
                       lr_err *e);

int lr_lpv_n(const lr_lpv *v);
double lr_lpv_h(const lr_lpv *v);
lr_vec3 lr_lpv_origin(const lr_lpv *v);
const lr_lpv_stencil *lr_lpv_stencil_of(const lr_lpv *v);

/* Zeroes the light (injected, propagated and accumulated); keeps the blocking. */
void lr_lpv_clear_light(lr_lpv *v);
void lr_lpv_clear_blocking(lr_lpv *v);

/* The cell holding p (0 inside, -1 outside). */
int lr_lpv_cell_of(const lr_lpv *v, lr_vec3 p, int ijk[3]);

/* Eq. 3b-4: the reflected flux phi[3] (W, per channel) of a diffuse surface sample at p with
 * unit normal n, as the lobe (phi / pi) max(0, n . w) in the cell one cell off the surface
 * (p + h n). A lobe outside the box is dropped and counted (lr_lpv_dropped). LR_EINVAL for
 * non-finite input, |n| not 1 within 1e-6 or negative flux. */
int lr_lpv_inject_lobe(lr_lpv *v, lr_vec3 p, lr_vec3 n, const double phi[3], lr_err *e);
/* An isotropic point light of flux phi[3] at p (its cell), I = phi / (4 pi). */
int lr_lpv_inject_point(lr_lpv *v, lr_vec3 p, const double phi[3], lr_err *e);
/* Flux of injected light that fell outside the box, per channel. */
double lr_lpv_dropped(const lr_lpv *v, int ch);

/* A surface sample of area `area` (mm^2) and unit normal n at p blocks its interfaces (see
 * above). Samples outside the box are ignored. LR_EINVAL for non-finite or negative input. */
int lr_lpv_add_blocker(lr_lpv *v, lr_vec3 p, lr_vec3 n, double area, lr_err *e);

/* `steps` propagation steps (0 to 4 n); each adds the flux blocked in it to the absorbed
 * record. LR_EINVAL for steps out of range. */
int lr_lpv_propagate(lr_lpv *v, int steps, lr_err *e);

/* Sum over cells of the flux c_00 sqrt(4 pi) of channel ch in the light still in flight. */
double lr_lpv_total_flux(const lr_lpv *v, int ch);
/* Sum of the absorbed record of channel ch. */
double lr_lpv_absorbed_flux(const lr_lpv *v, int ch);

/* The irradiance E[3] (W/mm^2) on a surface of unit normal n at x, from the absorbed record:
 * per axis a with n_a != 0, the flux absorbed at the interfaces nearest x along a travelling
 * against n_a, per covered area min(1, B_a) h^2, bilinear across the interface plane over
 * the covered interfaces, weighted by |n_a| (exact for axis-aligned surfaces, the table and
 * walls). 0 where nothing covers the interfaces. */
void lr_lpv_irradiance(const lr_lpv *v, lr_vec3 x, lr_vec3 n, double E[3]);

/* The gather behind lr_lpv_irradiance, over any store of per-interface values (gather.c; the
 * objects' field, objfield.h, reads its texels with it): for each axis a with n_a != 0, the
 * interface plane nearest the point along a (uu: grid coordinates, cells of 1, N cells a
 * side), bilinear across between the cells' centres over the interfaces for which face()
 * answers true, with out the light arriving through side s (1: toward -a) of interface idx,
 * per band; each axis weighted by |n_a|. Points beside the box get nothing from that axis. */
typedef bool (*lr_lpv_face_fn)(const void *ctx, const int idx[3], int a, int s, double out[3]);
void lr_lpv_face_gather(int N, const double uu[3], lr_vec3 n, lr_lpv_face_fn face,
                        const void *ctx, double E[3]);

/* The light in flight (n^3 * 12, layout above), e.g. for upload. */
const double *lr_lpv_grid(const lr_lpv *v);
/* Replaces it and the absorbed record (NULL keeps one), e.g. with a GPU readback. */
void lr_lpv_set_state(lr_lpv *v, const double *grid, const double *absorbed);
const float *lr_lpv_blocking(const lr_lpv *v);
/* The absorbed record: (n+1)^3 interfaces x 6 (axis a, travel sign s: 2 a + s, s = 1 for
 * travel toward -axis) x 3 channels, at [((iface * 6) + 2 a + s) * 3 + ch], iface indexed as
 * the blocking. */
const double *lr_lpv_absorbed(const lr_lpv *v);

/* One propagation step on raw arrays (the CPU reference of the compute shader): dst = the
 * transfer of src (n^3 * 12 each), adding the blocked flux to absorbed; scale is n^3 * 3
 * scratch (each source cell's clamp scale per channel). */
void lr_lpv_step(const lr_lpv_stencil *st, int n, const float *blocking, const double *src,
                 double *dst, double *absorbed, double *scale);

#endif
