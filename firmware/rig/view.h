/* lamprig firmware — what the main loop draws with: a small table of back ends with the
 * shape of render/renderer.h (invalidate by dirty flags, needs_frame, frame with stats,
 * RGBA8 readback, present), so the loop schedules frames the same way whichever is built in.
 *
 *   "passes"   seed 003's passes (render/renderer.h) with the light transport on a worker
 *              thread (render/async/async.h): the loop blends the newest per-light images
 *              at every frame and never waits for a solve; after a change that re-runs the
 *              maps the first image is a coarse preview, then it refines (the default;
 *              needs GL, surfaceless headless)
 *   "passes_inline"  the same passes on the loop's own thread: a frame runs whatever
 *              transport is due before the loop goes on (for comparison, and for a driver
 *              that cannot share a context between threads)
 *   "preview"  a CPU stand-in: a glow whose colour is the sum of the lights' intensity times
 *              colour (relative to the lights when the view was created, tone-mapped
 *              1 - exp(-x)), so a frame's brightness follows the dimmer; converged after
 *              one frame. On KMS it clears the screen to the glow's centre colour.
 *
 * The first entry of lr_rig_view_names() is the default.
 */
#ifndef LR_RIG_VIEW_H
#define LR_RIG_VIEW_H

#include <stdbool.h>

#include "firmware/rig/stats.h"
#include "render/base/err.h"
#include "render/gl/gl.h"
#include "render/renderer.h"
#include "render/scene/scene.h"

typedef struct lr_rig_view lr_rig_view;

typedef struct lr_rig_view_desc {
    const char *name; /* NULL or "": the default */
    lr_gl *gl;        /* may be NULL for "preview" headless */
    lr_scene *scene;  /* read at every frame; owned by the caller */
    int width, height;
    bool no_vpl;      /* "passes": skip the VPL pass (the planner found no receiver in sight) */
    bool no_preview;  /* "passes": no coarse preview stage after a change */
    double gpu_budget_mb; /* the renderer's GPU memory budget (output.gpu_memory_mb); 0: none */
    /* "passes": the control-space cache (render/async/cache.h, firmware/rig/ahead.h): the
     * keys naming a state and its memory (output.cache_mb); none or 0: no cache. */
    const lr_cache_key *cache_keys;
    int n_cache_keys;
    double cache_mb;
    double slice_ms; /* the worker's GPU slices (output.slice_ms); 0: fixed */
} lr_rig_view_desc;

/* Comma-separated names of the back ends built in, default first. */
const char *lr_rig_view_names(void);
/* Whether a back end needs a GL context even headless. */
bool lr_rig_view_needs_gl(const char *name);

int lr_rig_view_create(const lr_rig_view_desc *desc, lr_rig_view **out, lr_err *e);
void lr_rig_view_destroy(lr_rig_view *v);
const char *lr_rig_view_name(const lr_rig_view *v);
/* Hands a change (the LR_DIRTY_* flags of the scene changes made since the last call) to the
 * back end. Returns the number the change became (render/async/: its batch; the frames whose
 * lr_rig_frame_info.batch is at least that show it), 0 when the next frame shows it. */
uint64_t lr_rig_view_invalidate(lr_rig_view *v, unsigned dirty);
bool lr_rig_view_needs_frame(const lr_rig_view *v);
/* The view's clock, seconds since the rig started (the renderer's flicker,
 * lr_renderer_set_time); back ends without one ignore it. */
void lr_rig_view_set_time(lr_rig_view *v, double t_seconds);
/* Draws a frame. info says what it shows; stats->passes 0: nothing new (no image yet). */
int lr_rig_view_frame(lr_rig_view *v, lr_frame_stats *stats, lr_rig_frame_info *info,
                      lr_err *e);
/* A descriptor that becomes readable when the back end has something new to show (the
 * worker published images), for the loop's poll set; -1: none. */
int lr_rig_view_event_fd(const lr_rig_view *v);
/* True while the back end has transport work in hand (off the loop). */
bool lr_rig_view_busy(const lr_rig_view *v);
/* The states to build ahead (render/async/async.h lr_async_anticipate); back ends without a
 * cache ignore them. */
int lr_rig_view_anticipate(lr_rig_view *v, const lr_async_state *states, int n, lr_err *e);
/* The cache's counters (zeroes without one). */
void lr_rig_view_cache_stats(const lr_rig_view *v, lr_state_cache_stats *st, int *pending);
/* An error of work done off the loop (once), LR_OK when none. */
int lr_rig_view_error(lr_rig_view *v, lr_err *e);
/* Retires a view without waiting for work under way off the loop (a scene switch): it stops
 * drawing and its scene may be destroyed; destroy it once lr_rig_view_retired is true (then
 * lr_rig_view_destroy does not wait). */
void lr_rig_view_retire(lr_rig_view *v);
bool lr_rig_view_retired(const lr_rig_view *v);
/* Blocks until there is a first image (start-up only), or timeout_ms. */
int lr_rig_view_wait_first(lr_rig_view *v, int timeout_ms, lr_err *e);
/* width*height*4 bytes, rows top to bottom. */
int lr_rig_view_read_rgba8(lr_rig_view *v, unsigned char *rgba, lr_err *e);
int lr_rig_view_present(lr_rig_view *v, lr_err *e);
void lr_rig_view_size(const lr_rig_view *v, int *w, int *h);

/* ---- back-end table (view_*.c) ---- */
typedef struct lr_rig_view_ops {
    const char *name;
    bool needs_gl;
    int (*create)(const lr_rig_view_desc *desc, void **impl, lr_err *e);
    void (*destroy)(void *impl);
    uint64_t (*invalidate)(void *impl, unsigned dirty);
    bool (*needs_frame)(const void *impl);
    void (*set_time)(void *impl, double t_seconds); /* may be NULL */
    /* info is preset to "shows everything, converged as stats say" */
    int (*frame)(void *impl, lr_frame_stats *stats, lr_rig_frame_info *info, lr_err *e);
    int (*read_rgba8)(void *impl, unsigned char *rgba, lr_err *e);
    int (*present)(void *impl, lr_err *e);
    /* Optional (NULL: the back end works on the loop): */
    int (*event_fd)(const void *impl);
    bool (*busy)(const void *impl);
    int (*error)(void *impl, lr_err *e);
    int (*wait_first)(void *impl, int timeout_ms, lr_err *e);
    void (*retire)(void *impl);
    bool (*retired)(const void *impl);
    int (*anticipate)(void *impl, const lr_async_state *states, int n, lr_err *e);
    void (*cache_stats)(const void *impl, lr_state_cache_stats *st, int *pending);
} lr_rig_view_ops;

extern const lr_rig_view_ops lr_rig_view_passes;
extern const lr_rig_view_ops lr_rig_view_inline;
extern const lr_rig_view_ops lr_rig_view_preview;

#endif
