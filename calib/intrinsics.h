/* lamprig calib — pinhole intrinsics with OpenCV's 5-parameter distortion, for the camera
 * and for the projector (a projector is a camera with the light going the other way).
 *
 * Pixel convention is OpenCV's: the centre of pixel (i, j) is at (u, v) = (i, j), row 0 is the
 * top of the image, the device looks down +Z with +Y pointing down in the image.
 * Distortion (k1 k2 p1 p2 k3), as in cv::projectPoints:
 *   x' = X/Z, y' = Y/Z, r^2 = x'^2 + y'^2, radial = 1 + k1 r^2 + k2 r^4 + k3 r^6
 *   x'' = x' radial + 2 p1 x'y' + p2 (r^2 + 2x'^2),  y'' = y' radial + p1 (r^2 + 2y'^2) + 2 p2 x'y'
 *   u = fx x'' + cx,  v = fy y'' + cy
 *
 * The GL helpers let the renderer draw from a calibrated projector (issue 5 item 7): the
 * projection matrix maps the device's image to NDC with NDC +y at image row 0, so a frame
 * rendered with it and shown on the projector lands where the calibration measured.
 */
#ifndef LR_CALIB_INTRINSICS_H
#define LR_CALIB_INTRINSICS_H

#include "render/base/json_write.h"
#include "render/base/json.h"

typedef struct lr_intrinsics {
    int width, height;      /* image size the intrinsics belong to (pixels) */
    double fx, fy, cx, cy;  /* pixels */
    double dist[5];         /* k1 k2 p1 p2 k3 */
} lr_intrinsics;

/* Range checks (finite, focal lengths > 0, principal point within one image size of the
 * image, as projector lens shift can put it at or past the edge); `what` names the device. */
int lr_intrinsics_check(const lr_intrinsics *k, const char *what, lr_err *e);

/* Device-frame point X (Z > 0) to pixel uv, with distortion. */
void lr_intrinsics_project(const lr_intrinsics *k, const double X[3], double uv[2]);
/* Pixel to normalised undistorted coordinates (x', y') by fixed-point iteration; returns
 * LR_EINVAL when it does not converge (points far outside the calibrated field). */
int lr_intrinsics_undistort(const lr_intrinsics *k, const double uv[2], double xy[2],
                            lr_err *e);

/* Column-major 4x4 GL projection for this device, near/far in the scene's units (mm):
 * eye space is GL's (looking down -z, +y up), obtained from the device frame by
 * lr_extrinsics_gl_view. Distortion is not representable here; render undistorted and warp,
 * or accept the residual (report it). */
void lr_intrinsics_gl_projection(const lr_intrinsics *k, double znear, double zfar,
                                 float m[16]);
/* Column-major 4x4 GL view matrix from a rigid transform X_dev = R X_world + T (R row-major
 * 3x3): the device frame with Y and Z flipped into GL's eye space. */
void lr_extrinsics_gl_view(const double R[9], const double T[3], float m[16]);

/* JSON members "image_size": [w, h], "fx", "fy", "cx", "cy", "dist": [5] inside the current
 * object / the object obj. prefix names obj in messages (NULL at top level). */
void lr_intrinsics_write(lr_jw *w, const lr_intrinsics *k);
int lr_intrinsics_read(const lr_json *j, lr_jnode obj, const char *prefix, lr_intrinsics *k,
                       lr_err *e);

/* 3x3 row-major camera matrix. */
void lr_intrinsics_matrix(const lr_intrinsics *k, double K[9]);

#endif
