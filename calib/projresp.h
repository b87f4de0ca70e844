/* lamprig calib — the projector's response per channel: how much light an input level
 * gives, as a monotone lookup table with its inverse (for projector compensation: which
 * level to send for a wanted amount of light).
 *
 * Measured from flat frames: each channel alone at a series of levels (0, 16, ..., 240, 255
 * by default), captured by the camera, linearised with the camera response, averaged over
 * the lit area. The level-0 capture (ambient light + the projector's black) is subtracted
 * and the result normalised by the full level:
 *     y_c(v) = (L_c(v) - L_c(0)) / (L_c(1) - L_c(0)),   v = level / 255
 * then forced non-decreasing (isotonic fit) and interpolated to 256 entries piecewise as a
 * power law between measured levels (exact for a pure gamma curve; linear where a segment
 * is flat). Seed 000 section 6.2 calibrates its projector's brightness and colour this way
 * (with a ColorChecker); seed 001 section 4.1 measures the projector's black level.
 *
 * Flat frames are named r_LLL.png, g_LLL.png, b_LLL.png (LLL = level, 3 digits); level 0
 * is shown once per channel so each sweep is complete on its own.
 */
#ifndef LR_CALIB_PROJRESP_H
#define LR_CALIB_PROJRESP_H

#include "calib/camresp.h"
#include "calib/graycode.h"
#include "calib/image.h"

#define LR_PROJRESP_KIND "projector_response"
#define LR_PROJRESP_MAX_LEVELS 256

typedef struct lr_projresp {
    double lut[3][256];  /* y for input level i (0..255): lut[c][0] = 0, lut[c][255] = 1 */
    double black[3];     /* L(0) / L(1): black + ambient relative to full white */
    double gamma[3];     /* least-squares power-law exponent (informative) */
    int nlevels;         /* measured levels */
    double levels[LR_PROJRESP_MAX_LEVELS];        /* v in [0, 1], increasing, 0 and 1 included */
    double measured[3][LR_PROJRESP_MAX_LEVELS];   /* y before the isotonic fit */
} lr_projresp;

/* From measured light per channel at n levels (levels[] in [0, 1], increasing, starting at 0
 * and ending at 1; light[k * 3 + c]: camera-linear light of channel c's sweep at level k). */
int lr_projresp_fit(const double *levels, const double *light, int n, lr_projresp *out,
                    lr_err *e);

/* y for an input v in [0, 1] (linear between LUT entries). */
double lr_projresp_eval(const lr_projresp *r, int c, double v);
/* The input v in [0, 1] giving light y in [0, 1] (y outside is clamped): the smallest v
 * where the LUT reaches y, linear between entries. */
double lr_projresp_inverse(const lr_projresp *r, int c, double y);

/* The flat frames for steps levels (0 -> 17: 0, 16, ..., 240, 255). */
int lr_projresp_levels(int steps, int *levels, int *n, lr_err *e);
/* Shows the flat frames (show as lr_gc_show_fn); the default 17 levels. */
int lr_projresp_run_sequence(int pw, int ph, lr_gc_show_fn show, void *ctx, lr_err *e);
int lr_projresp_run_sequence_steps(int pw, int ph, int steps, lr_gc_show_fn show, void *ctx,
                                   lr_err *e);
int lr_projresp_write_patterns(const char *dir, int pw, int ph, int steps, lr_err *e);

/* Measures a folder of flat captures (any levels present, r_/g_/b_ each with 000 and 255),
 * linearised with cam (NULL: the camera is taken as linear) and averaged over the pixels the
 * projector lights (full level - level 0 above 8 digital values in every channel's sweep),
 * then fits. */
int lr_projresp_measure(const char *dir, const lr_camresp *cam, lr_projresp *out, lr_err *e);

/* {"version":1, "kind":"projector_response", "lut":[[256]x3], "black":[3], "gamma":[3],
 *  "levels":[n], "measured":[[n]x3]}. LUT entries in [0, 1], non-decreasing, 0 at 0 and 1 at
 * 255. */
int lr_projresp_save(const char *path, const lr_projresp *r, lr_err *e);
int lr_projresp_load(const char *path, lr_projresp *out, lr_err *e);

#endif
