/* lamprig calib — what the calib subcommands share: their command objects (one file each,
 * firmware/commands/calib_*.c, gathered by calib.c), the option-table entries several of them
 * take (board, projector size, decoding thresholds) and the helpers reading them and the
 * glob expansion (progress: lr_cli_progress, firmware/cli.h). Every result is computed in full before its file is written,
 * and written atomically after validation, so a failed run leaves the previous calibration
 * untouched (exit status 1, one-line reason on stderr). */
#ifndef LR_CALIB_CLI_H
#define LR_CALIB_CLI_H

#include <glob.h>

#include "calib/board.h"
#include "render/base/progress.h"
#include "firmware/cli.h"

extern const lr_command lr_calib_camera;
extern const lr_command lr_calib_projector;         /* patterns, capture, decode, calibrate */
extern const lr_command lr_calib_projector_capture; /* calib_capture.c */
extern const lr_command lr_calib_camera_response;
extern const lr_command lr_calib_projector_response; /* patterns, capture, fit */
extern const lr_command lr_calib_projresp_capture;   /* calib_capture.c */
extern const lr_command lr_calib_color;
extern const lr_command lr_calib_pose;
extern const lr_command lr_calib_albedo;
extern const lr_command lr_calib_ar_frame;
extern const lr_command lr_calib_check;

#define LR_CALIB_EXIT_NOTE                                                                      \
    "Exit status: 0 success, 1 failure (the output file is left as it was), 2 bad arguments."

/* Option-table entries. */
#define LR_CALIB_BOARD_OPTS(req)                                                                \
    {.name = "--board", .type = LR_ARG_STRING, .metavar = "COLSxROWS", .flags = (req),         \
     .help = "the board's inner corners (or circles) per row and column"},                     \
    {.name = "--square", .type = LR_ARG_NUMBER, .metavar = "MM",                               \
     .flags = (req) | LR_ARG_ABOVE_MIN, .max = 1e4,                                            \
     .help = "the board's square (or circle spacing), mm"},                                    \
    {.name = "--pattern", .type = LR_ARG_CHOICE, .metavar = "P",                               \
     .choices = "chessboard|circles|acircles",                                                 \
     .help = "chessboard (default), circles or acircles"}
#define LR_CALIB_PROJ_OPT(req, what)                                                            \
    {.name = "--proj", .type = LR_ARG_SIZE, .flags = (req), .help = (what)}
#define LR_CALIB_DECODE_OPTS                                                                    \
    {.name = "--contrast", .type = LR_ARG_INT, .min = 1, .max = 255,                           \
     .help = "least pattern/inverse difference of a decoded bit, 8-bit (default 5)"},              \
    {.name = "--shadow", .type = LR_ARG_INT, .min = 1, .max = 255,                             \
     .help = "white - black at or below this is shadow, 8-bit (default 40)"}
#define LR_CALIB_SUBPIX_OPT                                                                     \
    {.name = "--subpix-window", .type = LR_ARG_STRING, .metavar = "N|auto",                    \
     .help = "corner refinement half-window, 1..100 px, or auto (default 11)"}

/* --board, --square and --pattern into b (a usage error names the bad one). LR_EXIT_*. */
int lr_calib_board(const lr_cli *c, lr_board *b);
/* --subpix-window: 0 when absent, LR_SUBPIX_AUTO, or 1..100. LR_EXIT_*. */
int lr_calib_subpix(const lr_cli *c, int *out);
/* Sorted glob matches; LR_EXIT_FAIL (message printed) when nothing matches. */
int lr_calib_glob(const lr_cli *c, const char *pattern, glob_t *g);

#endif
