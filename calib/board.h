/* lamprig calib — the planar calibration target: chessboard or circle grid.
 *
 * cols x rows counts inner corners (chessboard) or circles, as OpenCV does; square_mm is the
 * spacing between neighbouring points, so every length the calibration reports (poses,
 * projector-camera baseline) is in millimetres.
 */
#ifndef LR_CALIB_BOARD_H
#define LR_CALIB_BOARD_H

#include <stdbool.h>

#include "calib/cv_shim.h"
#include "calib/image.h"
#include "render/base/json_write.h"
#include "render/base/json.h"

typedef struct lr_board {
    int cols, rows;
    double square_mm;
    int pattern; /* enum lr_board_pattern */
} lr_board;

int lr_board_check(const lr_board *b, lr_err *e);
int lr_board_points(const lr_board *b);

/* "9x6" -> 9, 6. */
int lr_board_parse_size(const char *s, int *cols, int *rows, lr_err *e);
/* "chessboard" | "circles" | "acircles". */
int lr_board_parse_pattern(const char *s, int *pattern, lr_err *e);
const char *lr_board_pattern_name(int pattern);

/* Board-frame coordinates (mm, z = 0) of the points in the order detection returns them. */
void lr_board_object_points(const lr_board *b, double *xyz);

/* Finds the board in an 8-bit grey image; *found = false when it is not visible.
 * subpix_half: corner refinement half-window (see lr_cv_find_board; <= 0 adapts). */
int lr_board_detect(const lr_board *b, const lr_img *gray, int subpix_half, double *xy,
                    bool *found, lr_err *e);

/* "board": {"cols", "rows", "square_mm", "pattern"}. */
void lr_board_write(lr_jw *w, const char *key, const lr_board *b);
int lr_board_read(const lr_json *j, lr_jnode obj, const char *key, lr_board *b, lr_err *e);

#endif
