/* lamprig calib — live capture: show a frame on the projector, let it settle, grab a camera
 * frame, save it; for every frame of a sequence (Gray code, flat levels).
 *
 * The camera is a V4L2 device opened through OpenCV's VideoCapture. The projector is
 * whatever show callback the caller passes (lr_gc_show_fn): the firmware's DRM/KMS output
 * once it exists, an external viewer fed through a file, or a person pressing Enter. The
 * camera is opened before anything is shown, so a missing camera fails at once with a
 * message naming the device.
 */
#ifndef LR_CALIB_CAPTURE_H
#define LR_CALIB_CAPTURE_H

#include "calib/graycode.h"
#include "render/base/progress.h"

/* A frame sequence for a pw x ph projector, shown frame by frame (lr_gc_run_sequence and
 * lr_projresp_run_sequence have this shape). */
typedef int (*lr_sequence_fn)(int pw, int ph, lr_gc_show_fn show, void *ctx, lr_err *e);

typedef struct lr_capture_desc {
    const char *device;         /* "/dev/video0" */
    int width, height;          /* camera mode; 0 keeps the driver's default */
    int settle_ms;              /* wait after each frame is shown; 0 -> 150 ms */
    int discard;                /* stale frames dropped before the one kept; 0 -> 3 */
    lr_gc_show_fn show;         /* the projector */
    void *show_ctx;
    const lr_progress *progress;
} lr_capture_desc;

/* Runs the sequence, writing one capture per frame into out_dir (created) under the frame's
 * name. For the Gray-code sequence it also writes sequence.json, so the folder decodes on
 * its own. */
int lr_capture_run(const lr_capture_desc *d, lr_sequence_fn sequence, int pw, int ph,
                   const char *out_dir, lr_err *e);

/* Show callbacks for the CLI until the firmware's projector output plugs in. */
/* ctx: a path; each frame is written there atomically for an external full-screen viewer
 * (e.g. one that reloads the file when it changes). */
int lr_capture_show_file(void *ctx, int index, const lr_img *frame, const char *name,
                         lr_err *e);
/* ctx: the folder the patterns were written to; asks on stderr to show NAME from it and
 * waits for Enter on stdin. */
int lr_capture_show_prompt(void *ctx, int index, const lr_img *frame, const char *name,
                           lr_err *e);

#endif
