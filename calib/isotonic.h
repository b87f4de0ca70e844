/* lamprig calib — monotone (non-decreasing) least-squares fit, for response curves.
 *
 * A device response cannot decrease with its input; measured ones do where noise or too
 * little data bites (the dark end of a Debevec curve, a projector level that flickered).
 * The pool-adjacent-violators algorithm gives the non-decreasing sequence closest to the
 * data in weighted least squares: violating neighbours are replaced by their weighted mean,
 * everything else is untouched.
 */
#ifndef LR_CALIB_ISOTONIC_H
#define LR_CALIB_ISOTONIC_H

#include "render/base/err.h"

/* In place; w may be NULL (equal weights) and must be > 0 otherwise. n <= 65536. */
int lr_isotonic(double *y, const double *w, int n, lr_err *e);

#endif
