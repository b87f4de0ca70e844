/* lamprig — translucent planar lights (TPLs, seed 004 Sec. 3.3, Eq. 5-6b): the light a
 * translucent object sends out, as a sparse set of small Lambertian planar emitters, and the
 * irradiance a diffuse receiver sample gathers from them.
 *
 * The seed downsamples its TPDS to one TPL per voxel of an 8^3 volume (the sample nearest the
 * voxel's centre, area = the object's area over the TPL count, intensity from the ESLPV,
 * Eq. 5). Here each TPL is the merge of the TPDS of one voxel of a coarse grid whose emission
 * faces the same dominant axis direction: flux-weighted position and normal (the position
 * lifted along the normal onto the plane touching the outermost member), summed area and
 * flux. Merging keeps the emitted flux exactly (sum of the TPLs' phi = sum of the samples'),
 * which the seed's nearest-sample pick does not. The cell is 2h of the volume (scene_lpv.c).
 *
 * Gathering, Eq. 6a-6b without rho/pi (the caller multiplies by its albedo): a TPL of flux phi
 * and area A emitting (phi / pi) cos_t into its hemisphere gives a point x of normal n_x
 *   E = sum_k phi_k / pi * cos_k cos_x / max(|x - x_k|^2, A_k)
 * (the bound of PIPELINE.md's VPL geometry term), 0 where an object is in the way. */
#ifndef LR_LPV_TPL_H
#define LR_LPV_TPL_H

#include "render/base/err.h"
#include "render/base/vec3.h"
#include "render/scene/scene.h"

typedef struct lr_lpv_tpl {
    lr_vec3 p, n;   /* position, unit emission normal */
    double area;    /* mm^2 */
    double phi[3];  /* emitted flux per channel, W per unit light radiance or intensity */
    int object;     /* the scene object it stands on, -1 none (merging keeps them apart) */
} lr_lpv_tpl;

/* Merges in[0..n) (phi >= 0) into *out (malloc'd, caller frees; *nout of them) per cell of
 * side `cell` mm from `origin` and per dominant axis direction of the normal; samples with
 * no flux are dropped. LR_EINVAL for cell <= 0, LR_ENOMEM. */
int lr_lpv_tpl_merge(const lr_lpv_tpl *in, int n, lr_vec3 origin, double cell, lr_lpv_tpl **out,
                     int *nout, lr_err *e);

/* Irradiance E[3] (W/mm^2, added) at x (unit normal nx) from the TPLs, shadowed by the scene's
 * other objects (the last `clip` mm before a TPL are not tested). A TPL's own object is not
 * tested: on a convex object, what faces a TPL's front (cos_t > 0) sees it, and a merged
 * TPL, whose plane does not support the whole object, would be shadowed by the object's
 * bulge (measured: a 20 mm globe's TPLs lost a third of their light to the table); the
 * self-shadowing of concave objects is left out. */
void lr_lpv_tpl_irradiance(const lr_scene *s, const lr_lpv_tpl *t, int n, double clip, lr_vec3 x,
                           lr_vec3 nx, double E[3]);

#endif
