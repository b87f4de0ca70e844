/* lamprig calib — captures as the material fit's target: photos of the lit object, linear
 * radiance at the fit's resolution.
 *
 * The camera response is the rig's rule (lr_rig_camera_response: camera_response.json, else
 * the gamma curve, calib->gamma or 2.2), the one compare and lamprig-capsim use, so a
 * simulated capture reads back as the radiance it was made from. One photo: each pixel
 * through that response and the colour matrix (lr_rig_camera_to_linear), divided by its
 * exposure time. Several (an exposure stack, times given): the per-channel HDR merge
 * (lr_camresp_merge with the same response), then the colour matrix. Then an
 * area-weighted box filter down to the fit's size (the photo and the fit must have the same
 * aspect ratio to 1 %: the scene's camera is the rig's camera) and the scale to radiance.
 * Fit pixels touching a capture pixel that is clipped in every capture (some channel >= 250,
 * or all channels 0) are NaN: a clipped value says only "at least" (or "at most"), and
 * lr_fit_run leaves NaN pixels out of its mask. The radiance scale:
 *     L = X / (scale)      X: relative exposure per second, scale: the camera's
 *                          exposure units per W/(mm^2 sr) (the capture simulator's `gain`;
 *                          the scene's render.exposure when it was captured like a render).
 */
#ifndef LR_CALIB_FIT_CAPTURES_H
#define LR_CALIB_FIT_CAPTURES_H

#include "calib/rig.h"
#include "render/base/err.h"
#include "render/image/image.h"

/* paths: n 8-bit photos (PNG/JPEG); times: n exposure times in s (NULL: 1 s each; n > 1
 * requires times). */
int lr_fit_load_captures(const char *const *paths, const double *times, int n,
                         const lr_rig_calib *calib, int width, int height, double scale,
                         lr_image *out, lr_err *e);

/* Area-weighted box filter of src down (or up) to w x h. */
int lr_image_resample_box(const lr_image *src, int w, int h, lr_image *out, lr_err *e);

#endif
