#include "calib/board.h"

#include <stdio.h>
#include <string.h>

#include "calib/calfile.h"

static const char *const pattern_names[] = {"chessboard", "circles", "acircles"};

int lr_board_check(const lr_board *b, lr_err *e)
{
    if (b->cols < 2 || b->rows < 2 || b->cols > 100 || b->rows > 100)
        return lr_err_set(e, LR_EINVAL, "board %dx%d: need 2..100 points each way", b->cols,
                          b->rows);
    if (!(b->square_mm > 0 && b->square_mm < 1e4))
        return lr_err_set(e, LR_EINVAL, "board square %g mm: must be in (0, 10000)",
                          b->square_mm);
    if (b->pattern < LR_BOARD_CHESSBOARD || b->pattern > LR_BOARD_ACIRCLES)
        return lr_err_set(e, LR_EINVAL, "board pattern %d unknown", b->pattern);
    /* A square chessboard has no defined orientation: OpenCV may return its corners rotated
     * between views, which silently corrupts the calibration. */
    if (b->pattern == LR_BOARD_CHESSBOARD && b->cols == b->rows)
        return lr_err_set(e, LR_EINVAL,
                          "board %dx%d: a chessboard needs different counts each way "
                          "(a square one is ambiguous under rotation)",
                          b->cols, b->rows);
    return LR_OK;
}

int lr_board_points(const lr_board *b) { return b->cols * b->rows; }

int lr_board_parse_size(const char *s, int *cols, int *rows, lr_err *e)
{
    int c, r, n = 0;
    if (sscanf(s, "%dx%d%n", &c, &r, &n) != 2 || s[n] != '\0' || c < 2 || r < 2)
        return lr_err_set(e, LR_EINVAL, "board size '%s': expected COLSxROWS, e.g. 9x6", s);
    *cols = c;
    *rows = r;
    return LR_OK;
}

int lr_board_parse_pattern(const char *s, int *pattern, lr_err *e)
{
    for (int i = 0; i < 3; i++)
        if (strcmp(s, pattern_names[i]) == 0) {
            *pattern = i;
            return LR_OK;
        }
    return lr_err_set(e, LR_EINVAL, "board pattern '%s': expected chessboard, circles or acircles",
                      s);
}

const char *lr_board_pattern_name(int pattern)
{
    return pattern >= 0 && pattern < 3 ? pattern_names[pattern] : "unknown";
}

void lr_board_object_points(const lr_board *b, double *xyz)
{
    for (int r = 0; r < b->rows; r++)
        for (int c = 0; c < b->cols; c++) {
            double *p = xyz + 3 * (r * b->cols + c);
            /* Asymmetric grids shift every other row by half a period (OpenCV's layout). */
            p[0] = (b->pattern == LR_BOARD_ACIRCLES ? 2 * c + r % 2 : c) * b->square_mm;
            p[1] = r * b->square_mm;
            p[2] = 0;
        }
}

int lr_board_detect(const lr_board *b, const lr_img *gray, int subpix_half, double *xy,
                    bool *found, lr_err *e)
{
    return lr_cv_find_board(gray, b->pattern, b->cols, b->rows, subpix_half, xy, found, e);
}

void lr_board_write(lr_jw *w, const char *key, const lr_board *b)
{
    lr_jw_object(w, key);
    lr_jw_int(w, "cols", b->cols);
    lr_jw_int(w, "rows", b->rows);
    lr_jw_number(w, "square_mm", b->square_mm);
    lr_jw_string(w, "pattern", lr_board_pattern_name(b->pattern));
    lr_jw_object_end(w);
}

int lr_board_read(const lr_json *j, lr_jnode obj, const char *key, lr_board *b, lr_err *e)
{
    lr_jnode o;
    int rc = lr_calfile_object(j, obj, NULL, key, &o, e);
    if (rc)
        return rc;
    long cols, rows;
    char name[32];
    if ((rc = lr_calfile_int(j, o, key, "cols", 2, 100, &cols, e)) ||
        (rc = lr_calfile_int(j, o, key, "rows", 2, 100, &rows, e)) ||
        (rc = lr_calfile_number(j, o, key, "square_mm", 1e-6, 1e4, &b->square_mm, e)) ||
        (rc = lr_json_get_string(j, o, "pattern", true, name, sizeof name, e)))
        return rc;
    b->cols = (int)cols;
    b->rows = (int)rows;
    lr_err sub = {0};
    if (lr_board_parse_pattern(name, &b->pattern, &sub))
        return lr_json_fail(j, lr_json_get(j, o, "pattern"), "board.pattern", e, LR_EINVAL, "%s",
                            sub.msg);
    return LR_OK;
}
