/* lamprig — GPU passes in slices (issue 32, "a frame budget"): the long passes end their work
 * in pieces and, between pieces, let a waiting change cut the frame.
 *
 * A pass issues GL commands that the driver runs later; a cancellation poll between passes
 * (render/renderer.c) therefore returns at once while the whole pass still runs on the GPU, and
 * the next frame's first commands queue behind it. With a cancellation token set
 * (lr_renderer_set_cancel: the rig's worker, render/async/), each slice end waits for the
 * slice's GPU work (glFinish) and then polls the token, so a cut leaves at most one slice
 * behind it. Without a token nothing waits and nothing is cut: the commands, the tests and the
 * CPU twin run exactly as before.
 *
 * The slices (render/passes/PIPELINE.md "Slices"):
 *   radiosity   one per map and light (K x lights a frame); cut at LR_CANCEL_RESTART only,
 *               since a part-accumulated frame is a running mean with some maps one sample
 *               ahead: the cut sets the maps to restart (their frame count to 0), which the
 *               change that asked for it does anyway;
 *   irradiance  one per band of LR_SLICE_ROWS grid rows of each plane receiver; cut at
 *               LR_CANCEL_STALE (the grids are drawn whole again while the pass is due).
 */
#ifndef LR_PASSES_SLICE_H
#define LR_PASSES_SLICE_H

#include "render/base/cancel.h"
#include "render/base/err.h"

/* Rows of a receiver's irradiance grid (LR_RECV_GRID = 256) per slice: 64, about 17 ms of the
 * candle's 135 ms pass at 16 VPLs on the 2-core proxy's llvmpipe. */
#define LR_SLICE_ROWS 64

typedef struct lr_slicer lr_slicer;

/* Called at every slice end with the count of slices ended so far (1, 2, ...), before the
 * poll: a test requests its token from it to cut a frame at a chosen slice. */
typedef void (*lr_slice_fn)(void *ctx, long slice);

int lr_slicer_create(lr_slicer **out, lr_err *e);
void lr_slicer_destroy(lr_slicer *s);
/* The token polled at slice ends; NULL: no waits, no cuts. */
void lr_slicer_set_cancel(lr_slicer *s, const lr_cancel *cancel);
void lr_slicer_set_hook(lr_slicer *s, lr_slice_fn fn, void *ctx);
/* Slices ended since the slicer was made. */
long lr_slicer_count(const lr_slicer *s);

/* Ends a slice of pass `what`: with a token, waits for the GPU work issued so far and returns
 * LR_ECANCELED ("WHAT: cancelled") when the token is requested at `level` or above; LR_OK
 * otherwise. s may be NULL (a pass run outside a renderer): LR_OK. */
int lr_slice_end(lr_slicer *s, enum lr_cancel_level level, const char *what, lr_err *e);

#endif
