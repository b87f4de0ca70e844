/* lamprig calib — a 3x3 colour matrix taking the camera's linear RGB to reference linear
 * RGB (linear sRGB primaries), by least squares over colour patches.
 *
 * Patch pairs come from a file (camera and reference values measured any way) or from a
 * photo of an X-Rite ColorChecker Classic detected with OpenCV's mcc module, whose reference
 * values are built in. Seed 000 section 6.2 calibrates colour with a Macbeth ColorChecker;
 * seed 001 section 4.1 white-balances its camera on one. Camera values must be linear:
 * decode them with the camera response first (calib/camresp.h).
 *
 *   reference = M camera,   M = argmin sum_i |M c_i - r_i|^2 = (R^T C)(C^T C)^-1
 * The fit refuses patch sets that do not span three colour directions (all grey, or too few
 * patches), where M would be noise.
 */
#ifndef LR_CALIB_COLORMATRIX_H
#define LR_CALIB_COLORMATRIX_H

#include "calib/camresp.h"
#include "calib/image.h"

#define LR_COLORMATRIX_KIND "color_matrix"

typedef struct lr_colormatrix {
    double m[9];      /* row-major */
    double rms;       /* RMS of |M c - r| over the patches */
    double max_err;   /* largest |M c - r| */
    int patches;
    char source[32];  /* "pairs" or "colorchecker" */
} lr_colormatrix;

/* cam, ref: n RGB triples (linear). */
int lr_colormatrix_fit(const double *cam, const double *ref, int n, lr_colormatrix *out,
                       lr_err *e);
void lr_colormatrix_apply(const lr_colormatrix *m, const double in[3], double out[3]);

/* The 24 ColorChecker Classic patches in reading order (dark skin .. black) as 8-bit sRGB
 * and as linear sRGB (0..1). */
const unsigned char *lr_colorchecker_srgb8(void);
void lr_colorchecker_linear(double out[72]);
/* sRGB transfer function, 0..1 -> linear. */
double lr_srgb_to_linear(double v);

/* Finds the chart in an RGB 8-bit photo (mcc) and returns the 24 patch colours linearised
 * with cam (NULL: the photo is taken as sRGB-encoded). */
int lr_colorchecker_measure(const lr_img *photo, const lr_camresp *cam, double out[72],
                            lr_err *e);

/* Patch pairs from a file: {"version":1, "kind":"color_pairs", "pairs":[{"camera":[r,g,b],
 * "reference":[r,g,b]}, ...]} (linear values). *cam and *ref are malloc'ed n x 3 arrays. */
int lr_colorpairs_load(const char *path, double **cam, double **ref, int *n, lr_err *e);

/* {"version":1, "kind":"color_matrix", "matrix":[[3]x3], "rms", "max_error", "patches",
 *  "source"}; the matrix must be finite, entries within +-100, and invertible. */
int lr_colormatrix_save(const char *path, const lr_colormatrix *m, lr_err *e);
int lr_colormatrix_load(const char *path, lr_colormatrix *out, lr_err *e);

#endif
