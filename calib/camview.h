/* lamprig calib — the calibrated camera's view of a scene (issue 5 items 4 and 6): render
 * what the rig's camera sees, with its intrinsics (lr_intrinsics: fx, fy, cx, cy, OpenCV
 * distortion) and its pose in scene coordinates (X_cam = R X_scene + T, mm; OpenCV's device
 * frame: +Z forward, +Y down the image).
 *
 * The renderers (GPU and CPU twin) draw through a scene camera: a symmetric pinhole frustum
 * with a vertical field of view. A calibrated camera has an off-centre principal point and
 * lens distortion, so its view is made in two steps:
 *   1. render an undistorted pinhole image from the same centre and orientation whose
 *      symmetric frustum covers every ray the camera's pixels see (lr_camview_apply sets the
 *      scene camera to it; lr_camview_render_size gives its size, with the focal length of
 *      the render f_r = max(fx, fy), so no detail is lost);
 *   2. resample it into the camera's pixels (lr_camview_remap): each camera pixel (u, v) is
 *      undistorted to normalised (x', y') (lr_intrinsics_undistort) and read bilinearly at
 *      render pixel (f_r x' + W_r/2 - 1/2, f_r y' + H_r/2 - 1/2).
 * Pixels whose undistortion does not converge (far outside the calibrated field) are NaN in
 * the map and black in the output, and labelled LR_LABEL_INVALID.
 *
 * Labels (object / receiver / background) come from ray casting the scene's geometry (the
 * objects' and receivers' BVHs) through each camera pixel's centre with the same model, so
 * masks do not depend on which renderer drew the image.
 */
#ifndef LR_CALIB_CAMVIEW_H
#define LR_CALIB_CAMVIEW_H

#include <stdint.h>

#include "calib/intrinsics.h"
#include "render/base/vec3.h"
#include "render/image/image.h"
#include "render/scene/scene.h"

/* A rigid transform X_dev = R X_scene + T (R row-major, T in mm). */
typedef struct lr_pose {
    double R[9];
    double T[3];
} lr_pose;

enum lr_pixel_label {
    LR_LABEL_BACKGROUND = 0, /* the ray leaves the scene */
    LR_LABEL_OBJECT = 1,     /* first hit: a translucent object */
    LR_LABEL_RECEIVER = 2,   /* first hit: a receiver (table, wall) */
    LR_LABEL_INVALID = 3,    /* outside the calibrated field (undistortion failed) */
};

typedef struct lr_camview lr_camview;

/* Plans the view for camera k at pose; max_side caps the pinhole render's larger side
 * (0 -> 4096; LR_EINVAL when the camera's field needs more, e.g. a fish-eye). */
int lr_camview_create(const lr_intrinsics *k, const lr_pose *pose, int max_side,
                      lr_camview **out, lr_err *e);
void lr_camview_destroy(lr_camview *v);

/* The camera image size (k.width x k.height) and the pinhole render's. */
void lr_camview_size(const lr_camview *v, int *width, int *height);
void lr_camview_render_size(const lr_camview *v, int *width, int *height);

/* Sets the scene's camera to the pinhole render's (type perspective, position, target, up,
 * fov_deg; near and far are kept); ORs the dirty flags into *dirty (may be NULL). */
int lr_camview_apply(const lr_camview *v, lr_scene *s, unsigned *dirty, lr_err *e);

/* Resamples a pinhole render (lr_camview_render_size, rows top to bottom) into the camera's
 * pixels; *out is allocated. */
int lr_camview_remap(const lr_camview *v, const lr_image *pinhole, lr_image *out, lr_err *e);

/* The ray through camera pixel (u, v) (OpenCV pixel centres), in scene coordinates:
 * origin the camera centre -R^T T, unit direction. LR_EINVAL outside the calibrated field. */
int lr_camview_ray(const lr_camview *v, double u, double vv, lr_vec3 *org, lr_vec3 *dir,
                   lr_err *e);

/* Per camera pixel, enum lr_pixel_label (width*height bytes, rows top to bottom). */
int lr_camview_labels(const lr_camview *v, const lr_scene *s, uint8_t *labels, lr_err *e);

/* Pose helpers: compose (X_c = A X_b, X_b = B X_a gives X_c = (A B) X_a) and the camera
 * centre in scene coordinates. */
void lr_pose_compose(const lr_pose *a, const lr_pose *b, lr_pose *out);
lr_vec3 lr_pose_center(const lr_pose *p);
/* Rodrigues: rotation vector (axis * angle, rad) to row-major R, and back. */
void lr_pose_rodrigues(const double rvec[3], double R[9]);
void lr_pose_rvec(const double R[9], double rvec[3]);

#endif
