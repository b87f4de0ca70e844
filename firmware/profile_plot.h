/* lamprig — a log-log chart of a radial profile per colour band (R_d(r) of `lamprig optics
 * profile --plot`), drawn with cairo and written as PNG atomically (temp file + rename). */
#ifndef LR_PROFILE_PLOT_H
#define LR_PROFILE_PLOT_H

#include "render/base/err.h"

#define LR_PROFILE_PLOT_WIDTH 800
#define LR_PROFILE_PLOT_HEIGHT 560

/* Curve colours (sRGB 0..1), one per band: red, green, blue. Tests look for these. */
extern const double lr_profile_plot_colour[3][3];

/* Draws y[i][band] against x[i] on log-log axes with decade ticks and labels, one curve per
 * band, `title` on top. Points with x or y not finite and > 0 are skipped (a curve is broken
 * there). Needs at least two points with x > 0 and some y > 0; the y range is clipped to
 * twelve decades below the largest value so that an underflowing tail does not squash the
 * chart. */
int lr_profile_plot_png(const char *path, const char *title, const char *x_label,
                        const char *y_label, const double *x, const double (*y)[3], int n,
                        lr_err *e);

#endif
