/* lamprig calib — the C face of OpenCV (calib/cv_shim.cpp is the project's one C++ file).
 *
 * OpenCV 4 has no C API, so every OpenCV call the rig needs is wrapped here behind plain C
 * types: pixel buffers (lr_img), arrays of doubles, lr_err. No C++ exception crosses this
 * boundary: each function catches cv::Exception (and anything else) and returns LR_EINVAL /
 * LR_EIO / LR_ENOMEM with a message naming the image or operation. Pipelines, validation,
 * file formats and the CLI stay in the C files of calib/; keep this layer thin.
 *
 * Memory: buffers returned through pointer-to-pointer arguments are allocated with malloc()
 * and freed by the caller with free() (or lr_img_free for images).
 */
#ifndef LR_CALIB_CV_SHIM_H
#define LR_CALIB_CV_SHIM_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* The project's C headers have no linkage guards of their own: included from the C++ shim,
 * their declarations must be given C linkage here. */
#ifdef __cplusplus
extern "C" {
#endif

#include "calib/image.h"
#include "render/base/progress.h"
#include "render/base/err.h"

/* ---- images ------------------------------------------------------------------------- */

int lr_cv_imread(const char *path, int mode /* enum lr_img_read_mode */, lr_img *out,
                 lr_err *e);
/* Encodes img in the format named by ext (".png", ".hdr", ".exr", ".jpg") into a malloc'ed
 * buffer. */
int lr_cv_imencode(const char *ext, const lr_img *img, void **buf, size_t *len, lr_err *e);

/* ---- calibration boards ------------------------------------------------------------- */

enum lr_board_pattern {
    LR_BOARD_CHESSBOARD = 0, /* inner corners, refined with cornerSubPix */
    LR_BOARD_CIRCLES,        /* symmetric circle grid, blob centroids */
    LR_BOARD_ACIRCLES,       /* asymmetric circle grid */
};

/* Finds a cols x rows board in an 8-bit grey image; *found = false when it is not there
 * (not an error). xy receives cols*rows points (x, y), row by row as OpenCV orders them.
 * Chessboard corners are refined to subpixel precision (cornerSubPix) with a search window
 * of half-size subpix_half px (OpenCV's calibration sample uses 11); subpix_half <= 0 adapts
 * it to the board: 0.4 x the smallest corner spacing in this image, at most 11. */
int lr_cv_find_board(const lr_img *gray, int pattern, int cols, int rows, int subpix_half,
                     double *xy, bool *found, lr_err *e);

/* Point correspondences of several views of a planar target. */
typedef struct lr_cv_views {
    int nviews;
    const int *npoints;  /* points in each view */
    const double *obj;   /* sum(npoints) x 3: board frame, millimetres */
    const double *img;   /* sum(npoints) x 2: pixels in the first device */
    const double *img2;  /* sum(npoints) x 2: pixels in the second device (stereo), or NULL */
} lr_cv_views;

enum lr_cv_calib_flags {
    LR_CV_FIX_ASPECT = 1,    /* fx / fy fixed at the ratio in K on input (1 when K is zero) */
    LR_CV_USE_GUESS = 2,     /* K on input is the starting point */
    LR_CV_ZERO_TANGENT = 4,  /* p1 = p2 = 0 */
    LR_CV_FIX_K3 = 8,        /* k3 = 0 */
};

/* Zhang's method (cv::calibrateCamera, 5-parameter distortion k1 k2 p1 p2 k3).
 * K: 3x3 row-major (in/out), dist[5] (in/out), *rms: RMS reprojection error over all points
 * (px); view_err[nviews]: RMS per view (may be NULL); extr[6*nviews]: rvec, tvec per view
 * (may be NULL). */
int lr_cv_calibrate(const lr_cv_views *v, int width, int height, int flags, double K[9],
                    double dist[5], double *rms, double *view_err, double *extr, lr_err *e);

/* cv::stereoCalibrate with both intrinsics held fixed: R (3x3 row-major), T (mm) take points
 * from the first device's frame into the second's: X2 = R X1 + T. view_err[2*nviews]: RMS
 * per view for device 1 and 2 (may be NULL). */
int lr_cv_stereo_calibrate(const lr_cv_views *v, int width, int height, const double K1[9],
                           const double d1[5], const double K2[9], const double d2[5],
                           double R[9], double T[3], double *rms, double *view_err, lr_err *e);

/* Homography dst ~ H src from n >= 4 pairs; ransac_px > 0 uses RANSAC with that inlier
 * threshold, 0 a plain least-squares fit. *inliers may be NULL. */
int lr_cv_find_homography(int n, const double *src, const double *dst, double ransac_px,
                          double H[9], int *inliers, lr_err *e);

/* Pinhole + distortion projection (cv::projectPoints): n points X (3 each) through pose
 * (rvec, tvec) into pixels uv (2 each). Used by tests to check calib/intrinsics.c. */
int lr_cv_project_points(int n, const double *X, const double rvec[3], const double tvec[3],
                         const double K[9], const double dist[5], double *uv, lr_err *e);

/* Pose of an object from n >= 4 point correspondences (cv::solvePnP, then Levenberg-
 * Marquardt refinement with cv::solvePnPRefineLM): X_dev = R(rvec) X_obj + tvec. planar: the
 * points lie in the object's z = 0 plane (a board: IPPE start), else any 3-D points, n >= 6
 * (iterative DLT start). *rms: RMS reprojection error (px) of the refined pose. */
int lr_cv_solve_pnp(int n, const double *obj, const double *img, const double K[9],
                    const double dist[5], bool planar, double rvec[3], double tvec[3],
                    double *rms, lr_err *e);

/* ---- Gray-code structured light (cv::structured_light::GrayCodePattern) ------------- */

/* Number of pattern images for a projector of pw x ph pixels (pattern + inverse for each
 * column bit and each row bit; white and black references not counted). */
int lr_cv_graycode_count(int pw, int ph, int *count, lr_err *e);

/* Generates the sequence and hands each 8-bit grey image to sink in order (index 0..count-1);
 * a non-zero return from sink stops and is returned. */
typedef int (*lr_cv_image_sink)(void *ctx, int index, const lr_img *img, lr_err *e);
int lr_cv_graycode_generate(int pw, int ph, lr_cv_image_sink sink, void *ctx, lr_err *e);

/* Decodes captured images (8-bit grey after loading) per camera pixel with
 * GrayCodePattern::getProjPixel (which returns true on *error*). Camera pixels where
 * white - black <= shadow are LR_GC_SHADOW; pixels where some pattern/inverse pair differs by
 * less than contrast are LR_GC_LOW_CONTRAST; codes outside the projector are
 * LR_GC_OUT_OF_RANGE. Outputs (malloc'ed, cam_w * cam_h, row-major): proj_xy (x, y per pixel,
 * -1 where not valid) and status. Progress: one unit per image loaded, then per 64 rows. */
enum lr_gc_status { LR_GC_VALID = 0, LR_GC_SHADOW, LR_GC_LOW_CONTRAST, LR_GC_OUT_OF_RANGE };
int lr_cv_graycode_decode(int pw, int ph, const char *const *patterns, int npatterns,
                          const char *white, const char *black, int contrast, int shadow,
                          const lr_progress *progress, const char *stage, int *cam_w,
                          int *cam_h, int32_t **proj_xy, uint8_t **status, lr_err *e);

/* ---- radiometry ---------------------------------------------------------------------- */

/* Debevec & Malik 1997 (cv::CalibrateDebevec): response[c * 256 + z] is the relative
 * exposure that produces pixel value z in channel c (exp of Debevec's g; OpenCV pins
 * g(128) = 0, so response[c*256+128] = 1). imgs: n RGB 8-bit images of a static scene,
 * times: exposure times (s). samples: pixel locations sampled (70 in OpenCV), lambda:
 * smoothness weight (10 in OpenCV). */
int lr_cv_debevec_response(const lr_img *imgs, const double *times, int n, int samples,
                           double lambda, double *response, lr_err *e);

/* ColorChecker Classic (24 patches) detection with cv::mcc::CCheckerDetector in an RGB
 * 8-bit photo. rgb[24*3]: mean RGB per patch in [0, 1] (the photo's encoding, not
 * linearised), in the chart's reading order (dark skin first, black last). */
int lr_cv_detect_colorchecker(const lr_img *photo, double *rgb, lr_err *e);

/* ---- live capture (cv::VideoCapture over V4L2) -------------------------------------- */

typedef struct lr_cv_camera lr_cv_camera;
/* device: "/dev/videoN". width/height 0 keep the driver's default. A missing device is
 * LR_ENODEV with a message naming it. */
int lr_cv_camera_open(const char *device, int width, int height, lr_cv_camera **out,
                      lr_err *e);
/* Grabs and drops `discard` frames (stale frames in the driver's queue), then returns the
 * next one as RGB 8-bit. */
int lr_cv_camera_grab(lr_cv_camera *cam, int discard, lr_img *out, lr_err *e);
void lr_cv_camera_close(lr_cv_camera *cam);

#ifdef __cplusplus
}
#endif

#endif
