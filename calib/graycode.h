/* lamprig calib — Gray-code structured light between the projector and the camera.
 *
 * The projector shows a sequence of frames: a full white and a full black reference, then
 * OpenCV's GrayCodePattern images (each column bit and each row bit as a pattern and its
 * inverse). The camera captures each one; decoding tells, for every camera pixel, which
 * projector pixel lit it. Seed 000 section 6.2 and seed 001 section 4.1 calibrate their
 * projector-camera pairs before measuring; this is the correspondence step of that.
 *
 * Frame names (both the generated patterns and a capture folder use them):
 *   white.png, black.png, pattern_00.png ... pattern_NN.png   (+ sequence.json)
 * sequence.json: {"version": 1, "kind": "graycode_sequence", "projector": [w, h],
 *                 "frames": ["white.png", "black.png", "pattern_00.png", ...]}
 *
 * Decoding classifies each camera pixel:
 *   LR_GC_SHADOW        white - black <= shadow (the projector does not reach it)
 *   LR_GC_LOW_CONTRAST  some pattern/inverse pair differs by less than contrast
 *   LR_GC_OUT_OF_RANGE  the code names a pixel outside the projector
 *   LR_GC_VALID         otherwise, with the projector pixel (x, y)
 * Thresholds are 8-bit digital values; defaults are OpenCV's (contrast 5, shadow 40).
 */
#ifndef LR_CALIB_GRAYCODE_H
#define LR_CALIB_GRAYCODE_H

#include <stdbool.h>

#include "calib/cv_shim.h"
#include "calib/image.h"
#include "render/base/progress.h"

#define LR_GC_SEQUENCE_KIND "graycode_sequence"
#define LR_GC_DEFAULT_CONTRAST 5
#define LR_GC_DEFAULT_SHADOW 40

/* Frames in the sequence for a pw x ph projector (white + black + patterns). */
int lr_gc_frame_count(int pw, int ph, int *count, lr_err *e);
/* File name of frame i ("white.png", "black.png", "pattern_07.png"). */
void lr_gc_frame_name(int i, char *buf, size_t cap);

/* Shows each frame in turn: show(ctx, i, frame, name). This is where the firmware's
 * projector output plugs in (and the live capture grabs a camera frame after each). A
 * non-zero return from show stops the sequence and is returned. */
typedef int (*lr_gc_show_fn)(void *ctx, int index, const lr_img *frame, const char *name,
                             lr_err *e);
int lr_gc_run_sequence(int pw, int ph, lr_gc_show_fn show, void *ctx, lr_err *e);

/* Writes the frames as PNGs into dir (created if missing) plus sequence.json. */
int lr_gc_write_patterns(const char *dir, int pw, int ph, const lr_progress *progress,
                         lr_err *e);
/* sequence.json of a pattern or capture folder: the projector size. */
int lr_gc_write_sequence(const char *dir, int pw, int ph, lr_err *e);
int lr_gc_read_sequence(const char *dir, int *pw, int *ph, lr_err *e);

typedef struct lr_gc_params {
    int contrast; /* 0 -> LR_GC_DEFAULT_CONTRAST */
    int shadow;   /* 0 -> LR_GC_DEFAULT_SHADOW */
} lr_gc_params;

/* Per-camera-pixel decoding result. */
typedef struct lr_gc_map lr_gc_map;

/* Decodes the captures in dir. pw, ph: projector size, or 0, 0 to take it from the folder's
 * sequence.json. */
int lr_gc_decode_dir(const char *dir, int pw, int ph, const lr_gc_params *params,
                     const lr_progress *progress, lr_gc_map **out, lr_err *e);
void lr_gc_map_destroy(lr_gc_map *m);

int lr_gc_map_width(const lr_gc_map *m);
int lr_gc_map_height(const lr_gc_map *m);
void lr_gc_map_projector_size(const lr_gc_map *m, int *pw, int *ph);
/* Status of camera pixel (x, y) (enum lr_gc_status); *px, *py set when LR_GC_VALID. */
int lr_gc_map_get(const lr_gc_map *m, int x, int y, int *px, int *py);
/* Number of camera pixels with this status. */
long lr_gc_map_count(const lr_gc_map *m, int status);
const char *lr_gc_status_name(int status);

/* 16-bit RGB PNG: R = projector x, G = projector y, B = status (0 = valid). For inspection
 * and for later steps (spatial AR) that need the raw correspondence. */
int lr_gc_map_save(const lr_gc_map *m, const char *path, lr_err *e);
int lr_gc_map_load(const char *path, int pw, int ph, lr_gc_map **out, lr_err *e);

/* Projector positions of points seen by the camera (board corners) through local
 * homographies (Moreno & Taubin 2012): the valid decoded pixels in a (2 half + 1)^2 window
 * around each point give a camera->projector homography (RANSAC, so stray decoding errors do
 * not count), which maps the point with subpixel precision although each decoded pixel is
 * quantised to a whole projector pixel. */
typedef struct lr_gc_local_params {
    int half_window;  /* 0 -> 23 (the 47 x 47 window of Moreno & Taubin) */
    int min_points;   /* valid pixels needed in the window; 0 -> 50 */
    double ransac_px; /* inlier threshold in projector pixels; 0 -> 2 */
} lr_gc_local_params;

/* cam_xy, proj_xy: n points (x, y). ok[i] false (and proj_xy NaN) where the window held too
 * few valid pixels or the fit failed. Returns the number of points mapped in *mapped. */
int lr_gc_local_homography(const lr_gc_map *m, const double *cam_xy, int n,
                           const lr_gc_local_params *params, double *proj_xy, bool *ok,
                           int *mapped, lr_err *e);

#endif
