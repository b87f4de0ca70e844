/* lamprig calib — the sensor model of the capture simulator: what the rig's camera records
 * for a linear RGB radiance image (issue 5 item 6: ground truth for comparison runs, fits
 * and tests). The camera's *view* (pose, intrinsics, distortion) is calib/camview.h; this
 * file turns radiance at each camera pixel into digital values.
 *
 * Per pixel and channel, in this order (the inverse of what the rig's calibration undoes:
 * lr_rig_camera_to_linear applies the response, then the colour matrix):
 *
 *   raw   = M^-1 L                       the inverse colour matrix (identity without one):
 *                                        the camera's own primaries from reference linear RGB
 *   X     = gain * t * V(x, y) * raw     relative exposure in the response's units
 *                                        (lr_camresp: X = curve(z); 1 gives value 128)
 *   e     = X / X_sat * full_well        photo-electrons (X_sat: exposure at value 255)
 *   e'    = Poisson(e) + N(0, read^2)    shot noise (exact Poisson below 64 e-, its normal
 *                                        approximation above) and Gaussian read noise
 *   z     = curve^-1(e' / full_well * X_sat), clipped to [0, 255], rounded to 8 bits (or
 *           scaled by 65535/255 and rounded to 16 bits)
 *
 * L is the renderer's HDR output, W/(mm^2 sr) (render/cpu/frame.h, lr_renderer_read_hdr);
 * `gain` carries radiance into the camera's exposure units (use the scene's
 * render.exposure to get an image as bright as the renderer's). The vignetting V is
 *   LR_VIGNETTE_COS4:  cos^4(theta), tan(theta) = r / focal_px (natural fall-off of a
 *                      thin lens), r the distance from (cx, cy) in pixels;
 *   LR_VIGNETTE_POLY:  1 + v1 rho^2 + v2 rho^4 + v3 rho^6, rho = r / half-diagonal
 *                      (the radial polynomial vignetting calibrations fit), clipped at 0.
 * The response is the inverse of an lr_camresp curve (piecewise linear, as
 * lr_camresp_linear reads it) when given, else the gamma curve lr_camresp_gamma describes,
 * evaluated analytically: z = 255 (X (128/255)^gamma)^(1/gamma).
 *
 * Noise is a pure function of (seed, pixel, channel): a counter-based generator
 * (render/base/rng.h), so a capture is reproducible and independent of evaluation order.
 * With full_well_e = 0 there is no shot noise; with read_noise_e = 0 no read noise.
 */
#ifndef LR_CALIB_CAPTURE_SIM_H
#define LR_CALIB_CAPTURE_SIM_H

#include <stdint.h>

#include "calib/camresp.h"
#include "calib/colormatrix.h"
#include "calib/image.h"
#include "render/image/image.h"

enum lr_vignette_model { LR_VIGNETTE_NONE = 0, LR_VIGNETTE_COS4, LR_VIGNETTE_POLY };

typedef struct lr_sensor {
    double exposure_s;             /* exposure time t, s; 0 -> 1 */
    double gain;                   /* radiance -> exposure units; 0 -> 1 */
    enum lr_vignette_model vignette;
    double vignette_poly[3];       /* v1 v2 v3 (POLY) */
    double focal_px;               /* COS4: focal length in pixels (> 0 required) */
    double cx, cy;                 /* optical centre (pixels); both 0 -> the image centre */
    const lr_camresp *response;    /* NULL -> gamma (lamprig-capsim passes the rig's rule,
                                    * lr_rig_camera_response, as a table) */
    double gamma;                  /* 0 -> LR_CAMRESP_DEFAULT_GAMMA (2.2) */
    const lr_colormatrix *color;   /* NULL -> identity; must be invertible */
    double full_well_e;            /* electrons at X_sat; 0 -> no shot noise */
    double read_noise_e;           /* read noise sigma, electrons (needs full_well_e > 0) */
    uint64_t seed;                 /* noise stream */
    int bits;                      /* 8 or 16; 0 -> 8 */
} lr_sensor;

/* Checks the parameters (finite, in range, invertible colour matrix, COS4 with a focal
 * length); the message names the field ("sensor.gain: ..."). */
int lr_sensor_check(const lr_sensor *s, lr_err *e);

/* The relative exposure that saturates channel c (value 255): curve[c][255], or
 * (255/128)^gamma for the gamma curve. */
double lr_sensor_saturation(const lr_sensor *s, int c);

/* Vignetting factor V at pixel centre (x, y) of a w x h image. */
double lr_sensor_vignette(const lr_sensor *s, int w, int h, double x, double y);

/* Noise-free exposure X per pixel and channel (before noise, response and quantisation):
 * out is w*h*3 doubles, rows top to bottom. For tests and for deriving error bounds. */
int lr_sensor_exposure(const lr_sensor *s, const lr_image *radiance, double *out, lr_err *e);

/* The digital value (0..255, fractional, unclipped) the response gives exposure X in
 * channel c: the inverse response. */
double lr_sensor_encode(const lr_sensor *s, int c, double X);

/* Parses a vignetting model as the command lines give it: "none", "cos4" or
 * "poly:V1,V2,V3" into s->vignette / s->vignette_poly (cos4 still needs focal_px, cx, cy).
 * LR_EINVAL with a message quoting the text. */
int lr_sensor_parse_vignette(const char *text, lr_sensor *s, lr_err *e);

/* The whole chain: radiance (lr_image, rows top to bottom) -> an RGB image of 8 or 16 bits
 * (allocated into *out; free with lr_img_free). */
int lr_sensor_capture(const lr_sensor *s, const lr_image *radiance, lr_img *out, lr_err *e);

#endif
