/* lamprig — `lamprig fit --diffusion`: a block sample's captures under projector patterns to a
 * heterogeneous volume file (seed 001 Sec. 4; the solver is inverse.h).
 *
 * Captures file (text; '#' comments and blank lines ignored; errors "FILE:LINE: ..."):
 *   lamprig-diffusion-captures 1
 *   block SX SY SZ                  mm: the sample is [0,SX] x [0,SY] x [0,SZ]
 *   eta ETA                         relative index (seed 001 uses 1.3)
 *   h H                             grid spacing of the fit, mm (SX / H etc. at most 64)
 *   pattern X0 Y0 X1 Y1 R G B       a projector pattern: transmitted irradiance R G B on the top
 *                                   face z = SZ inside [X0,X1] x [Y0,Y1] (seed 001 Sec. 4.1's
 *                                   4 x 4 regions are 16 such lines)
 *   B X Y Z R G B                   measured exitance at surface point (X,Y,Z) under the last
 *                                   pattern: an unlit point (multiple scattering only)
 * Every B is matched to the grid's nearest boundary point (within h).
 *
 * The fit: per band, the homogeneous (D, mu) first, then per node with the regulariser
 * (inverse.h); the result is written as a volume file (render/diffusion/README.md) whose cells
 * are the grid's inside nodes, with nodes of nearly equal coefficients merged into one region
 * (at most 62 regions, 0-9a-zA-Z).
 */
#ifndef LR_DFIT_H
#define LR_DFIT_H

#include "render/base/err.h"

typedef struct lr_dfit_desc {
    const char *captures; /* path */
    const char *out;      /* .vol written atomically */
    int max_iter;         /* CG iterations of the per-node fit; 0: 150 */
    double lambda;        /* regulariser; 0: 1e-6 */
} lr_dfit_desc;

typedef struct lr_dfit_result {
    int patterns, observations, unknowns_per_band, regions;
    double misfit_homogeneous[3], misfit[3]; /* relative data term after each fit */
    double homogeneous_D[3], homogeneous_mu[3];
} lr_dfit_result;

int lr_dfit_run(const lr_dfit_desc *d, lr_dfit_result *r, lr_err *e);

#endif
