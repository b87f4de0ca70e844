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
 * The slices (render/passes/PIPELINE.md "Slices") are bands of rows of what the pass draws:
 *   radiosity   bands of each map's rows, per map and light; cut at LR_CANCEL_RESTART only,
 *               since a part-accumulated frame is a running mean with some maps one sample
 *               ahead: the cut sets the maps to restart (their frame count to 0), which the
 *               change that asked for it does anyway;
 *   irradiance  bands of the grid rows of each plane receiver; cut at LR_CANCEL_STALE (the
 *               grids are drawn whole again while the pass is due).
 * A band is a scissored draw of the same geometry, so the fragments and their results are the
 * same whatever the bands (each texel is drawn once a frame).
 *
 * How many rows a band has: with a time budget (lr_slicer_set_budget, the rig's
 * output.slice_ms) and a token, as many as the pass's last bands say fit in the budget on this
 * GPU (a running estimate of ms per row, per pass), at least size / LR_SLICE_MAX_BANDS;
 * otherwise the fixed bands
 * below, whose count the tests rely on. The fixed bands were sized for the candle at 16 VPLs
 * (about 17 ms a band); at the planned 64 VPLs they took 40-70 ms, the wait of a change that
 * arrives during the pass.
 */
#ifndef LR_PASSES_SLICE_H
#define LR_PASSES_SLICE_H

#include "render/base/cancel.h"
#include "render/base/err.h"

/* Fixed bands: rows of a receiver's irradiance grid (LR_RECV_GRID = 256) per band, about
 * 17 ms of the candle's 135 ms pass at 16 VPLs on the 2-core proxy's llvmpipe; a radiosity
 * map is one band. */
#define LR_SLICE_ROWS 64

/* With a budget, the rows of a pass's first band, before any estimate. */
#define LR_SLICE_FIRST_ROWS 4
/* With a budget, at most this many bands to a map or a grid: a band costs a few ms beyond its
 * rows on llvmpipe (the draw's set-up and the wait), so bands sized to a budget under that
 * would shrink to one row and multiply the pass's time (the candle's irradiance pass: 1.9 s
 * in 3-row bands against 0.63 s whole). */
#define LR_SLICE_MAX_BANDS 32

/* The passes drawn in bands (each has its own estimate of the time per row). */
enum lr_slice_pass { LR_SLICE_RADIOSITY, LR_SLICE_IRRADIANCE, LR_SLICE_PASSES };

typedef struct lr_slicer lr_slicer;

/* Called at every slice end with the count of slices ended so far (1, 2, ...), before the
 * poll: a test requests its token from it to cut a frame at a chosen slice. */
typedef void (*lr_slice_fn)(void *ctx, long slice);

int lr_slicer_create(lr_slicer **out, lr_err *e);
void lr_slicer_destroy(lr_slicer *s);
/* The token polled at slice ends; NULL: no waits, no cuts. */
void lr_slicer_set_cancel(lr_slicer *s, const lr_cancel *cancel);
void lr_slicer_set_hook(lr_slicer *s, lr_slice_fn fn, void *ctx);
/* A time budget per band in ms (> 0), or 0: the fixed bands. Used only with a token. */
void lr_slicer_set_budget(lr_slicer *s, double ms);
/* Slices ended since the slicer was made. */
long lr_slicer_count(const lr_slicer *s);

/* Starts a band of `pass` at row y of `size` rows: returns its rows (1..size - y) and notes
 * the time, so that lr_slice_end measures it. s may be NULL: the fixed band. */
int lr_slice_band(lr_slicer *s, enum lr_slice_pass pass, int y, int size);

/* Ends a slice of pass `what`: with a token, waits for the GPU work issued so far and returns
 * LR_ECANCELED ("WHAT: cancelled") when the token is requested at `level` or above; LR_OK
 * otherwise. s may be NULL (a pass run outside a renderer): LR_OK. */
int lr_slice_end(lr_slicer *s, enum lr_cancel_level level, const char *what, lr_err *e);

#endif
