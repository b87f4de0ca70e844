/* lamprig-transrad --split: where S sends the light that entered an object (diagnosis of
 * issue 12/14's solid bodies). */
#ifndef LAMPRIG_TOOLS_TRANSRAD_SPLIT_H
#define LAMPRIG_TOOLS_TRANSRAD_SPLIT_H

#include "render/optics/optics.h"
#include "render/transrad/transrad.h"

/* For object surface s in slot's solution: the power that S lets out, weighted by the
 * irradiance each entry patch receives (A_i H_i), binned by the straight distance from the
 * entry patch's centroid to the exit patch's (same patch, 0-12, 12-24, 24-48, > 48 mm) and by
 * the exit patch's facing (up, down, sideways toward / away from the object's vertical axis
 * through its bounding box centre, the latter above and below mid-height), next to the
 * half-space dipole's shares of the same radii (c: the object's coefficients). */
void lr_trtool_print_split(const lr_tr *t, int s, int slot, const lr_coeffs *c);

#endif
