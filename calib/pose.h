/* lamprig calib — the mockup's pose: where the rig's camera (and projector) sit in scene
 * coordinates (issue 5 item 2, "the mockup's pose"; seed 000 section 6.2 registers its
 * projector to the mockup the same way, seed 001 section 4.1 calibrates camera and projector
 * with Zhang's method and then locates the object).
 *
 * Two ways in:
 *   board:  a calibration board lies at a known place in the scene (on the table), given as
 *           the scene position of its first point and the scene directions of its +x (along
 *           a row, the way the columns count) and +y (the way the rows count) axes, as
 *           OpenCV orders the detected points (lr_board_object_points). The camera photographs
 *           it; the board's pose in the camera (cv::solvePnP, IPPE + LM refinement) composed
 *           with the board's placement gives the camera's scene pose:
 *               X_cam = R_pnp (B^T (X_scene - o)) + t_pnp,  B = [x_axis y_axis x_axis*y_axis]
 *   points: pixels of known scene points (e.g. marked vertices of the mockup mesh), >= 6
 *           non-coplanar or >= 4 coplanar.
 * The projector's scene pose follows from projector.json's extrinsics
 * (lr_procam_projector_pose). Accuracy: with corner noise sigma (px) and n corners the pose
 * is known to about sigma / sqrt(n) in image terms: at distance Z and focal length f that is
 * Z sigma / (f sqrt(n)) mm across the view and a few times that along it.
 *
 * pose.json: {"version":1, "kind":"pose", "source":"board"|"points",
 *   "camera":{"R":[[3]x3], "T":[3]}, "projector":{"R","T"} (when projector.json was given),
 *   "rms": reprojection px, "points": n,
 *   "board":{...}, "placement":{"origin":[3], "x_axis":[3], "y_axis":[3]} (source board)}
 * R is checked to be a rotation on load; T within +-1e5 mm.
 */
#ifndef LR_CALIB_POSE_H
#define LR_CALIB_POSE_H

#include <stdbool.h>

#include "calib/board.h"
#include "calib/camview.h"
#include "calib/intrinsics.h"
#include "calib/procam.h"

#define LR_POSE_KIND "pose"

typedef struct lr_board_placement {
    double origin[3]; /* scene mm of the board's first point */
    double x_axis[3]; /* scene direction of board +x (need not be unit) */
    double y_axis[3]; /* scene direction of board +y (orthogonalised against x_axis) */
} lr_board_placement;

typedef struct lr_rig_pose {
    lr_pose camera;       /* X_cam = R X_scene + T */
    bool has_projector;
    lr_pose projector;    /* X_proj = R X_scene + T */
    double rms;           /* reprojection error of the fit, px */
    int points;
    char source[16];      /* "board" or "points" */
    bool has_board;
    lr_board board;
    lr_board_placement placement;
} lr_rig_pose;

/* The board-to-scene placement as a pose scene -> board (X_board = R X_scene + T); LR_EINVAL
 * for zero or parallel axes. */
int lr_board_placement_pose(const lr_board_placement *pl, lr_pose *scene_to_board, lr_err *e);

/* From a photo (8-bit grey) of the board: finds it (subpixel corners), solves its pose,
 * composes with the placement. procam may be NULL (no projector pose). */
int lr_rig_pose_from_board(const lr_img *gray, const lr_board *b, const lr_board_placement *pl,
                           const lr_intrinsics *k, const lr_procam *procam, lr_rig_pose *out,
                           lr_err *e);
/* From n scene points (x, y, z each) and their pixels (u, v each). */
int lr_rig_pose_from_points(int n, const double *scene_xyz, const double *uv,
                            const lr_intrinsics *k, const lr_procam *procam, lr_rig_pose *out,
                            lr_err *e);

int lr_rig_pose_save(const char *path, const lr_rig_pose *p, lr_err *e);
int lr_rig_pose_load(const char *path, lr_rig_pose *out, lr_err *e);

#endif
