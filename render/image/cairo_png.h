/* lamprig — finishing a cairo drawing as a PNG file, written atomically.
 * Shared by the plots (lamprig optics --plot, the bench's Pareto plot, compare's heatmap). */
#ifndef LR_IMAGE_CAIRO_PNG_H
#define LR_IMAGE_CAIRO_PNG_H

#include <cairo.h>

#include "render/base/err.h"

/* Checks cr's status, destroys cr, writes s to path (temp file + rename) and destroys s, on
 * success and on failure alike. Errors name the path: "drawing failed" or "PNG encoding
 * failed" with cairo's reason, or the atomic file's own error. */
int lr_cairo_finish_png(cairo_t *cr, cairo_surface_t *s, const char *path, lr_err *e);

#endif
