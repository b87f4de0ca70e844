/* lamprig calib — the camera's response: which (relative) exposure produced a pixel value,
 * and HDR images merged from exposure stacks.
 *
 * Seed 001 section 4.1 calibrates its camera radiometrically with Debevec & Malik 1997 and
 * builds each measurement from an exposure stack; so does the rig. The response is fitted
 * with OpenCV's CalibrateDebevec (smoothness-regularised least squares on log exposure),
 * then forced non-decreasing (isotonic fit: a response cannot fall; Debevec's curve can at
 * the ends, where few samples land). curve[c][z] is the relative linear exposure producing
 * value z in channel c, normalised so that curve[c][128] = 1 (OpenCV pins g(128) = 0).
 * Channels are therefore not white-balanced against each other: the colour matrix does
 * that (calib/colormatrix.h).
 */
#ifndef LR_CALIB_CAMRESP_H
#define LR_CALIB_CAMRESP_H

#include "calib/image.h"
#include "render/base/json_write.h"

#define LR_CAMRESP_KIND "camera_response"
#define LR_CAMRESP_MAX_STACK 64

typedef struct lr_camresp {
    double curve[3][256];
    /* Provenance (0 when not fitted from a stack). */
    int images;
    int samples;
    double lambda;
} lr_camresp;

typedef struct lr_camresp_desc {
    const lr_img *images; /* n RGB 8-bit frames of a static scene, same size */
    const double *times;  /* exposure times, seconds (only ratios matter) */
    int n;                /* >= 2 */
    int samples;          /* pixel locations sampled; 0 -> 70 (OpenCV's default) */
    double lambda;        /* smoothness; 0 -> 10 (OpenCV's default) */
} lr_camresp_desc;

int lr_camresp_fit(const lr_camresp_desc *d, lr_camresp *out, lr_err *e);

/* The response assumed for 8-bit captures when a rig has no measured one (calib/rig.h,
 * lr_rig_camera_response): a camera delivering roughly sRGB-encoded frames, as nearly all
 * cameras do by default (sRGB's curve is within 1.5 % of gamma 2.2 above value 40). */
#define LR_CAMRESP_DEFAULT_GAMMA 2.2

/* A camera whose pixel values are (value / 255)^gamma times exposure (gamma = 1: linear raw
 * data; 2.2: a camera delivering roughly sRGB-encoded frames), normalised like a fitted
 * curve: curve[c][z] = lr_camresp_gamma_at(gamma, z), 1 at z = 128. */
void lr_camresp_gamma(lr_camresp *r, double gamma);
/* One entry of that table: ((z > 0 ? z : 0.25) / 255)^gamma / (128 / 255)^gamma. */
double lr_camresp_gamma_at(double gamma, int z);

/* Relative exposure for a (possibly fractional) value z in [0, 255], linear between
 * entries. */
double lr_camresp_linear(const lr_camresp *r, int c, double z);

/* HDR radiance (relative, float RGB) from an exposure stack with this response: per pixel
 * and channel, the hat-weighted mean of ln(curve(z) / t) over the exposures (Debevec &
 * Malik 1997, Eq. 6; w(z) = min(z, 255 - z), so clipped and black values carry no weight).
 * Not cv::MergeDebevec: it averages the weights over the three channels, so one clipped
 * channel drags the other two (measured: 12 % of samples off by > 8 % on a stack whose
 * channels clip at different exposures). A value clipped in every exposure gets the bound
 * the stack allows: curve(255) / shortest time, or curve(0) / longest time. */
int lr_camresp_merge(const lr_camresp *r, const lr_img *images, const double *times, int n,
                     lr_img *out, lr_err *e);

/* {"version":1, "kind":"camera_response", "curve":[[256],[256],[256]], "images", "samples",
 *  "lambda"}; every entry finite, > 0, non-decreasing in z. */
int lr_camresp_save(const char *path, const lr_camresp *r, lr_err *e);
int lr_camresp_load(const char *path, lr_camresp *out, lr_err *e);

#endif
