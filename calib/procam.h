/* lamprig calib — projector intrinsics and projector-camera extrinsics from Gray-code
 * captures of a board in several poses (Zhang's method applied to the projector as in seed
 * 001 section 4.1; correspondences by local homographies, Moreno & Taubin 2012).
 *
 * Input: a folder with one sub-folder per board pose, each holding the captured Gray-code
 * sequence (white.png, black.png, pattern_NN.png, sequence.json; see calib/graycode.h).
 * Per pose: the board corners are found in white.png (the board lit by the projector), the
 * sequence is decoded, and each corner is carried into the projector through a local
 * homography. Then
 *   camera intrinsics      from a camera calibration file, or calibrated from the poses;
 *   projector intrinsics   calibrateCamera on (board points, projector corners);
 *   extrinsics             stereoCalibrate with both intrinsics fixed:
 *                          X_projector = R X_camera + T   (millimetres, board units).
 * Poses where the board is not found, or too few corners map, are listed and skipped.
 */
#ifndef LR_CALIB_PROCAM_H
#define LR_CALIB_PROCAM_H

#include <stdbool.h>

#include "calib/board.h"
#include "calib/graycode.h"
#include "calib/intrinsics.h"
#include "render/base/progress.h"

#define LR_PROCAM_KIND "projector_camera"

typedef struct lr_procam_pose {
    char *name;         /* pose folder */
    int corners;        /* corners carried into the projector and used */
    long valid_pixels;  /* camera pixels that decoded */
    double cam_error;   /* RMS reprojection error in the stereo fit, camera (px) */
    double proj_error;  /* the same, projector (px) */
} lr_procam_pose;

typedef struct lr_procam_reject {
    char *name;
    char *reason;
} lr_procam_reject;

typedef struct lr_procam {
    lr_intrinsics cam, proj;
    double R[9], T[3];  /* X_proj = R X_cam + T; R row-major; T in mm */
    double rms;         /* stereo RMS reprojection error over both devices (px) */
    double cam_rms;     /* camera calibration RMS (px): from the file when given */
    double proj_rms;    /* projector calibration RMS (px) */
    bool camera_from_file;
    lr_board board;
    lr_gc_params decode;
    lr_gc_local_params local;
    int nposes;
    lr_procam_pose *poses;
    int nrejected;
    lr_procam_reject *rejected;
} lr_procam;

typedef struct lr_procam_desc {
    const char *captures;        /* folder of pose folders */
    int proj_w, proj_h;          /* 0 -> from each pose's sequence.json */
    lr_board board;
    int subpix_window;           /* as lr_camcal_desc: 0 -> 11, LR_SUBPIX_AUTO */
    const lr_intrinsics *camera; /* NULL -> calibrate the camera from the poses too */
    double camera_rms;           /* RMS recorded with the given camera intrinsics */
    bool proj_fix_aspect;        /* square projector pixels: fx = fy */
    lr_gc_params decode;
    lr_gc_local_params local;
    int min_poses;               /* 0 -> 3 */
    int min_corners;             /* per pose; 0 -> half the board's points */
    const lr_progress *progress;
} lr_procam_desc;

int lr_procam_run(const lr_procam_desc *d, lr_procam *out, lr_err *e);
void lr_procam_free(lr_procam *p);

/* Projector pose in a world frame from the camera's: X_cam = Rc X_world + Tc gives
 * X_proj = Rp X_world + Tp. (For spatial AR once the mockup's pose is known.) */
void lr_procam_projector_pose(const lr_procam *p, const double Rc[9], const double Tc[3],
                              double Rp[9], double Tp[3]);

/* {"version":1, "kind":"projector_camera", "camera":{intrinsics}, "projector":{intrinsics},
 *  "R":[[3]x3], "T":[3], "rms", "camera_rms", "projector_rms", "camera_from_file",
 *  "board":{...}, "decode":{"contrast","shadow","half_window","min_points","ransac_px"},
 *  "poses":[{"name","corners","valid_pixels","camera_error","projector_error"}],
 *  "rejected":[{"name","reason"}]}
 * R is checked to be a rotation (orthonormal to 1e-6, determinant +1) on load. */
int lr_procam_save(const char *path, const lr_procam *p, lr_err *e);
int lr_procam_load(const char *path, lr_procam *out, lr_err *e);

#endif
