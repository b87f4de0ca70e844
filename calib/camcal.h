/* lamprig calib — camera intrinsics from photographs of a planar board (Zhang 1999, as
 * seed 001 section 4.1 calibrates its camera; OpenCV's calibrateCamera).
 *
 * Every photograph is searched for the board; those where it is not found, that cannot be
 * read, or whose size differs from the FIRST GOOD VIEW (the first image, in the order given,
 * where the board is found) are listed with the reason and skipped; the calibration uses all
 * the others (fatal only when fewer than min_views remain). Which image comes first therefore
 * does not matter: a stray photo of another size sorting first is one skipped line, not the
 * size every other view is refused against. Corners are refined
 * to subpixel precision. After the fit, each view's RMS reprojection error is compared with
 * the median over the views:
 *
 *   a view is an OUTLIER when error > outlier_factor x median  AND  error > outlier_floor_px
 *
 * (defaults 3 and 0.5 px). The factor catches a view that fits far worse than its peers (a
 * misdetected corner, motion blur, a bent board); the floor keeps sub-half-pixel views from
 * being flagged when every view is excellent. Outliers are named in the result (and by the
 * CLI on stderr); with drop_outliers the fit is repeated without them.
 */
#ifndef LR_CALIB_CAMCAL_H
#define LR_CALIB_CAMCAL_H

#include <stdbool.h>

#include "calib/board.h"
#include "calib/intrinsics.h"
#include "render/base/progress.h"

#define LR_CAMCAL_KIND "camera_intrinsics"
#define LR_SUBPIX_AUTO (-1)

typedef struct lr_camcal_view {
    char *image;  /* path as given */
    double error; /* RMS reprojection error of this view (px) */
    bool outlier;
    bool used;    /* false when dropped as an outlier */
} lr_camcal_view;

typedef struct lr_camcal_reject {
    char *image;
    char *reason; /* "9x6 chessboard not found", "size 612x459 differs from the first good
                   * view's 640x480 (NAME)", or the read error */
} lr_camcal_reject;

typedef struct lr_camcal {
    lr_intrinsics k;
    double rms;   /* RMS over all points of the used views (px) */
    lr_board board;
    bool fix_aspect;
    int subpix_window; /* as used: > 0 fixed, LR_SUBPIX_AUTO */
    int nviews;
    lr_camcal_view *views;
    int nrejected;
    lr_camcal_reject *rejected;
} lr_camcal;

typedef struct lr_camcal_desc {
    const char *const *images; /* paths */
    int nimages;
    lr_board board;
    bool fix_aspect;          /* fx = fy (OpenCV CALIB_FIX_ASPECT_RATIO with ratio 1) */
    bool drop_outliers;       /* refit without the outlier views */
    double outlier_factor;    /* 0 -> 3 */
    double outlier_floor_px;  /* 0 -> 0.5 */
    int min_views;            /* 0 -> 3 */
    /* Chessboard corner refinement half-window (px): 0 -> 11, OpenCV's calibration sample
     * (and the setting behind OpenCV's own result for its sample photos); LR_SUBPIX_AUTO ->
     * 0.4 x the corner spacing in each image, at most 11, better when the board is small in
     * some views (see calib/README.md, "calib camera"). */
    int subpix_window;
    const lr_progress *progress;
} lr_camcal_desc;

/* Runs the calibration; on success *out holds the result. On failure out->rejected still
 * lists the images skipped so far (with the reasons), so a caller can show them; free *out
 * with lr_camcal_free in both cases. */
int lr_camcal_run(const lr_camcal_desc *d, lr_camcal *out, lr_err *e);
void lr_camcal_free(lr_camcal *c);

/* Median of the used views' errors. */
double lr_camcal_median_error(const lr_camcal *c);

/* {"version":1, "kind":"camera_intrinsics", "fx","fy","cx","cy","dist":[5], "rms",
 *  "image_size":[w,h], "board":{...}, "fix_aspect", "views":[{"image","error","outlier",
 *  "used"}], "outliers":[names], "rejected":[{"image","reason"}]} */
int lr_camcal_save(const char *path, const lr_camcal *c, lr_err *e);
int lr_camcal_load(const char *path, lr_camcal *out, lr_err *e);
/* Reads the members above from an already parsed document. */
int lr_camcal_from_json(const lr_json *j, lr_jnode root, lr_camcal *out, lr_err *e);

#endif
