/* lamprig — the renderer off the caller's loop: light transport on a worker thread, the
 * latest per-light images blended on the caller's thread at every frame.
 *
 * The renderer (render/renderer.h) does a frame's work in one call: a material change re-runs
 * the maps, a diffusion grid's or translucent radiosity's CPU solve, the VPLs and
 * composition, 0.1-7 s on the 2-core proxy, and everything the caller's loop does waits for
 * it. lr_async splits the renderer at its one linear step (render/passes/PIPELINE.md
 * "Linearity"): a worker thread owns a second GL context (lr_gl_create_shared), a copy of the
 * scene (lr_scene_clone) and an lr_renderer over the copy, and publishes each composition's
 * per-light unit-intensity images; the caller's thread owns the blend (render/passes/
 * blend.h) and weighs the newest published images by its own scene's intensity x colour x
 * flicker and exposure. So a dimmer, flicker, colour or exposure change is one blend at the
 * next frame whatever the worker is doing, and the caller never waits for transport.
 *
 * Changes reach the worker through the caller's scene journal (lr_scene_set_journal): every
 * lr_scene_set on the caller's scene is recorded, and lr_async_commit hands the batch to the
 * worker, which replays it on its copy between its frames (so the copy sees the same
 * changes and dirty flags, in order) and renders until converged, publishing every frame
 * that composed new images. Batches queued while the worker is busy are replayed together
 * before its next frame: a knob turned during a solve costs one more solve, not one per
 * event.
 *
 * Cutting stale work (render/base/cancel.h, lr_renderer_set_cancel): a batch that changes
 * transport while the worker runs a full (non-preview) frame cuts that frame short at its
 * next cancellation poll (between passes, inside the grid's, translucent radiosity's and the
 * receiver bounce's solves): its state is already stale, and the new state's preview (or
 * full frame) starts at once instead of after it. A preview frame is never cut by a batch
 * (it is the cheap image of a state, and the newest batch is previewed right after it), and
 * after a cut the next full frame runs to its end if nothing was published since, so a knob
 * turned without rest still shows a new image per full frame. lr_async_stop and destroy cut
 * whatever runs.
 *
 * Progressive stages: with desc.preview set (assignments such as "render.K=1"), the first
 * worker frame after a change that re-runs the maps renders with them applied (a coarse, cheap image of
 * the new state), then the worker restores the scene's own values and refines; each published
 * image says which stage it is (lr_async_stage). Images never mix states: all of a
 * publication's layers come from one worker frame, and the blend weights come from the
 * caller's scene at the caller's frame.
 *
 * Publication is double-buffered in textures both contexts share, ordered by fences: the
 * worker copies into the slot the caller is not reading (after the caller's fence on it) and
 * fences; the caller takes a publication only once its fence has signalled (polled, never
 * waited on). lr_async_event_fd becomes readable when a publication is ready, for the
 * caller's poll set.
 *
 * Threads: every call below is made on the caller's thread with its context current.
 */
#ifndef LR_ASYNC_H
#define LR_ASYNC_H

#include <stdbool.h>
#include <stdint.h>

#include "render/async/cache.h"
#include "render/base/err.h"
#include "render/gl/gl.h"
#include "render/renderer.h"
#include "render/scene/scene.h"

typedef struct lr_async lr_async;

#define LR_ASYNC_MAX_PREVIEW 16

typedef enum lr_async_stage {
    LR_ASYNC_NONE = 0,  /* nothing published yet */
    LR_ASYNC_PREVIEW,   /* the preview settings, first frame after a transport change */
    LR_ASYNC_REFINING,  /* the scene's own settings, still accumulating */
    LR_ASYNC_FINAL,     /* the scene's own settings, converged */
    LR_ASYNC_CACHED,    /* the state's converged images, built ahead (render/async/cache.h) */
    LR_ASYNC_INTERPOLATED, /* interpolated between cached states around it */
} lr_async_stage;
#define LR_ASYNC_STAGES (LR_ASYNC_INTERPOLATED + 1)

/* Whether a stage shows the state converged (final or cached). */
bool lr_async_stage_converged(lr_async_stage s);

const char *lr_async_stage_name(lr_async_stage s);

typedef struct lr_async_desc {
    lr_gl *gl;          /* the caller's context, current on the calling thread */
    lr_scene *scene;    /* the caller's scene: copied for the worker, its journal set to this
                         * lr_async until lr_async_destroy */
    int width, height;  /* 0: 640 x 480 */
    bool no_vpl;
    /* "key=value" assignments for the preview stage (NULL-terminated or n_preview long);
     * none: no preview stage. Keys the scene rejects are an error at create. */
    const char *preview[LR_ASYNC_MAX_PREVIEW];
    int n_preview;
    /* Changes whose flags are only these need no preview (default: a light move, camera,
     * receivers and settings changes get one; material changes too). 0: every transport
     * change gets one. */
    unsigned no_preview_dirty;
    /* A preview whose frame took more than half the last full frame that re-ran the maps
     * (both dominated by a CPU solve the preview settings do not shrink) only delays the
     * image: it is skipped until a full frame gets dearer again. true: always drawn. */
    bool preview_always;
    double gpu_budget_mb; /* the worker's renderer's (lr_renderer_desc); 0: no limit */
    /* The control-space cache (render/async/cache.h): the keys whose values name a state,
     * and the memory its images may take. None, or cache_mb 0: no cache. */
    const lr_cache_key *cache_keys;
    int n_cache_keys;
    double cache_mb;
    /* The worker's renderer ends a slice of its long GPU passes about every slice_ms, so a
     * change cuts a stale frame after about that long (lr_renderer_set_slice_ms); 0: fixed
     * slices. */
    double slice_ms;
    /* The preview's image side over the view's, 0 < s <= 1 (0: 1): the preview is drawn by a
     * renderer of its own at that size (so the view's renderer keeps its maps and grids
     * across previews) and shown scaled up to the view (nearest texel). */
    double preview_scale;
} lr_async_desc;

/* A state the caller may ask for next: assignments on top of the scene as last committed. */
#define LR_ASYNC_STATE_SETS 16
typedef struct lr_async_state {
    int n;
    char key[LR_ASYNC_STATE_SETS][LR_CACHE_KEY_MAX];
    char value[LR_ASYNC_STATE_SETS][LR_CACHE_VALUE_MAX];
} lr_async_state;
#define LR_ASYNC_MAX_STATES 48

typedef struct lr_async_frame_stats {
    lr_frame_stats worker;   /* the worker frame whose images are shown */
    lr_async_stage stage;    /* of the shown images */
    uint64_t batch;          /* the last batch (lr_async_commit) the shown images include */
    bool new_images;         /* this frame took a newer publication */
    double blend_ms;         /* the caller's blend, CPU wall time including submission */
} lr_async_frame_stats;

/* Creates the worker (thread, shared context, scene copy, renderer) and queues the first
 * frame. Errors: the shared context, the scene copy, the preview assignments; errors of the
 * renderer itself come later from lr_async_error. */
int lr_async_create(const lr_async_desc *desc, lr_async **out, lr_err *e);
/* Stops the worker (a solve under way ends at its next cancellation poll, tens of ms) and
 * frees everything; clears the scene's journal. */
void lr_async_destroy(lr_async *a);

/* Asks the worker to stop (cutting its frame short) and detaches from the caller's scene
 * (which may then be destroyed), without waiting: a scene switch retires the old one this
 * way and destroys it once lr_async_stopped says its worker has exited (then
 * lr_async_destroy does not wait). Nothing but lr_async_stopped, lr_async_cancelled and
 * lr_async_destroy may be called after it. */
void lr_async_stop(lr_async *a);
bool lr_async_stopped(const lr_async *a);

/* Ends a batch of the scene's changes (those made since the last commit) and hands it to the
 * worker when it changes light transport; `dirty` is what the caller's own lr_scene_set calls
 * returned (intensity and display changes only mark the caller's next blend due). Returns
 * the batch number (counting from 1), or 0 when there was nothing to hand over. */
uint64_t lr_async_commit(lr_async *a, unsigned dirty);

/* The control-space cache.
 *
 * lr_async_commit looks the committed state up (its tag over desc.cache_keys): an entry of
 * its own shows at the next frame as LR_ASYNC_CACHED and the worker renders nothing for it;
 * an interpolation of cached states around it shows as LR_ASYNC_INTERPOLATED (its images
 * mixed once, render/passes/mix.h) until the worker's converged image of the exact state
 * replaces it (the worker skips the preview stage for it). A committed change to any key
 * outside the cache's keys that changes light transport drops every entry: they were built
 * on a scene that no longer is.
 *
 * lr_async_anticipate replaces the list of states to build ahead: whenever the worker has
 * nothing else to do (no batch queued, the shown state converged) it renders the next one
 * not yet cached to convergence (each frame cut by a transport batch, as a full frame is),
 * stores its images, and restores its copy of the scene. A state that does not fit the
 * budget (after evicting the least recently used) ends the list. The states are read when
 * built, so they are relative to the scene as committed then. Errors: more than
 * LR_ASYNC_MAX_STATES states. */
int lr_async_anticipate(lr_async *a, const lr_async_state *states, int n, lr_err *e);
/* The cache's counters (zeroes without a cache); *pending: states of the list not yet
 * visited. */
void lr_async_cache_stats(const lr_async *a, lr_state_cache_stats *st, int *pending);

/* The renderer's clock (lr_renderer_set_time): flicker enters the blend. */
void lr_async_set_time(lr_async *a, double t_seconds);

/* True when a frame would show something new: a publication is ready, or the blend is due
 * (an intensity/display change, a flickering light's new time). */
bool lr_async_needs_frame(const lr_async *a);
/* True while the worker has work (a batch queued or frames left to converge). */
bool lr_async_busy(const lr_async *a);
/* The number of the last batch the worker has published images for (0: none). */
uint64_t lr_async_published(const lr_async *a);

/* Takes the newest signalled publication, if any, and blends. Never waits for the worker.
 * Before the first publication there is no image: nothing is drawn, st->stage is
 * LR_ASYNC_NONE. */
int lr_async_frame(lr_async *a, lr_async_frame_stats *st, lr_err *e);

/* Blocks until the worker has published an image of batch `batch` or later (0: any) -- with
 * `final`, and has then nothing left to do (converged) -- or failed (its error), or
 * timeout_ms passed (LR_ETIMEOUT). For start-up, tools and tests, never in a loop. */
int lr_async_wait(lr_async *a, uint64_t batch, bool final, int timeout_ms, lr_err *e);

/* The worker's last error (once: cleared by the call), LR_OK when none. */
int lr_async_error(lr_async *a, lr_err *e);

/* How many images the worker has published at `stage` (for the stats and tests). */
uint64_t lr_async_publications(const lr_async *a, lr_async_stage stage);

/* How many worker frames were cut short, by a newer batch or a stop (for the stats and
 * tests; may be called after lr_async_stop, once lr_async_stopped). */
uint64_t lr_async_cancelled(const lr_async *a);
/* True while the worker runs a full frame that a transport batch would cut (tests, stats). */
bool lr_async_cuttable(const lr_async *a);

/* Readable (POLLIN) when a publication is ready; lr_async_frame drains it. */
int lr_async_event_fd(const lr_async *a);

int lr_async_read_rgba8(lr_async *a, unsigned char *rgba, lr_err *e);
int lr_async_read_hdr(lr_async *a, float *rgb, lr_err *e);
int lr_async_present(lr_async *a, lr_err *e);
void lr_async_size(const lr_async *a, int *width, int *height);

#endif
