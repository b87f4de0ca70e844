/* lamprig firmware — what the main loop draws with: a small table of back ends with the
 * shape of render/renderer.h (invalidate by dirty flags, needs_frame, frame with stats,
 * RGBA8 readback, present), so the loop schedules frames the same way whichever is built in.
 *
 *   "passes"   render/renderer.h, seed 003's passes (the default; needs GL, surfaceless
 *              headless)
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
} lr_rig_view_desc;

/* Comma-separated names of the back ends built in, default first ("passes, preview"). */
const char *lr_rig_view_names(void);
/* Whether a back end needs a GL context even headless. */
bool lr_rig_view_needs_gl(const char *name);

int lr_rig_view_create(const lr_rig_view_desc *desc, lr_rig_view **out, lr_err *e);
void lr_rig_view_destroy(lr_rig_view *v);
const char *lr_rig_view_name(const lr_rig_view *v);
void lr_rig_view_invalidate(lr_rig_view *v, unsigned dirty);
bool lr_rig_view_needs_frame(const lr_rig_view *v);
/* The view's clock, seconds since the rig started (the renderer's flicker,
 * lr_renderer_set_time); back ends without one ignore it. */
void lr_rig_view_set_time(lr_rig_view *v, double t_seconds);
int lr_rig_view_frame(lr_rig_view *v, lr_frame_stats *stats, lr_err *e);
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
    void (*invalidate)(void *impl, unsigned dirty);
    bool (*needs_frame)(const void *impl);
    void (*set_time)(void *impl, double t_seconds); /* may be NULL */
    int (*frame)(void *impl, lr_frame_stats *stats, lr_err *e);
    int (*read_rgba8)(void *impl, unsigned char *rgba, lr_err *e);
    int (*present)(void *impl, lr_err *e);
} lr_rig_view_ops;

extern const lr_rig_view_ops lr_rig_view_passes;
extern const lr_rig_view_ops lr_rig_view_preview;

#endif
