/* lamprig calib — whether a material fit's data determined its parameters (calib/fit.h).
 *
 * A fit always returns its best point; these checks say when that point means little, so
 * that `lamprig fit` refuses it (exit 3) instead of writing a material several times off
 * (issue 33: 38 of a candle's 62 object pixels clipped, the fit from the other 24 put sigma_s'
 * 6x low at a residual of 0.545, without a word). Each failed check sets its bit and adds a
 * sentence naming its figures:
 *
 *   PIXELS    fewer usable (unclipped) object pixels than lr_fit_min_pixels. Why that many:
 *             the fit's standard errors are s sqrt((J^T J)^-1), s^2 the residual's variance
 *             from m pixels and p parameters, estimated with relative error sqrt(2/(m - p));
 *             s itself to 10 % needs m - p >= 50. Below that even the fit's error bars
 *             are guesses. p = 2 per band (SIGMA: each band is its own 2-parameter fit on
 *             the same m pixels), 2 shared by 3 bands (SCALE: 3 m values).
 *   CLIPPED   more than half the object's pixels clipped in every capture: what is left is
 *             the dim part (edges, the side away from the light), and the clipped bright
 *             part is where the halo's level and width -- sigma_s' and sigma_a -- show.
 *   FLAT      the residual is nearly flat around the optimum: a Gauss-Newton standard error
 *             of a log parameter above LR_FIT_MAX_STDERR_LOG, or J^T J's condition number
 *             above LR_FIT_MAX_COND (one combination of the parameters barely changes the
 *             image, so the data fix only the other).
 *   BOUND     a coefficient within a factor 10 of the model's domain (1e-6..1e3 mm^-1): the
 *             optimiser ran into a wall, the optimum is not inside.
 *   RESIDUAL  the relative RMSE above LR_FIT_MAX_RESIDUAL_RATIO x the noise floor
 *             sqrt(noise_rel^2 + LR_FIT_CAPTURE_NOISE^2): the model does not explain the
 *             captures (wrong scene, light, response, exposure scale or material model).
 */
#ifndef LR_CALIB_FIT_CHECKS_H
#define LR_CALIB_FIT_CHECKS_H

#include <stddef.h>

#include "calib/fit.h"

enum {
    LR_FIT_WEAK_PIXELS = 1 << 0,
    LR_FIT_WEAK_CLIPPED = 1 << 1,
    LR_FIT_WEAK_FLAT = 1 << 2,
    LR_FIT_WEAK_BOUND = 1 << 3,
    LR_FIT_WEAK_RESIDUAL = 1 << 4,
};

/* log-parameter standard error (0.35: a factor 1.4 at one sigma; the Gauss-Newton figure
 * ignores that the model's noise changes with sigma and runs 3-10x below the spread seen
 * between seeds, so the true one is then a factor 3 or more) */
#define LR_FIT_MAX_STDERR_LOG 0.35
#define LR_FIT_MAX_COND 1e4
#define LR_FIT_MAX_RESIDUAL_RATIO 2.0
/* relative noise of an 8-bit capture's linearised pixel after the box filter, allowed on top
 * of the model's (quantisation, shot noise, sub-pixel registration) */
#define LR_FIT_CAPTURE_NOISE 0.05

/* Usable pixels a fit of this mode needs (PIXELS above). */
long lr_fit_min_pixels(lr_fit_mode mode);

/* The checks that need no fit (PIXELS, CLIPPED), from the object's pixels in the view and
 * how many of them are usable. Returns the failed bits; msg (may be NULL) gets one sentence
 * per failed check, "" when none. */
unsigned lr_fit_check_data(lr_fit_mode mode, long object_pixels, long used_pixels, char *msg,
                           size_t cap);

/* Every check on a finished fit. */
unsigned lr_fit_check_result(lr_fit_mode mode, const lr_fit_result *r, char *msg, size_t cap);

/* The failed bits as words ("pixels, flat"), for one-line summaries. */
void lr_fit_check_names(unsigned bits, char *out, size_t cap);

#endif
