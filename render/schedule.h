/* lamprig — the renderer's scheduler: which passes a scene change makes due.
 *
 * The scene reports what changed (LR_DIRTY_* of render/scene/dirty.h, returned by
 * lr_scene_set); it knows nothing of render passes. The mapping from those changes to the
 * passes to re-run lives here, with the renderer (docs/ARCHITECTURE.md, "Data flow" table; issue 15).
 */
#ifndef LR_SCHEDULE_H
#define LR_SCHEDULE_H

#include <stdbool.h>

#include "render/base/err.h"
#include "render/scene/dirty.h"

/* The render passes (issue 3), as bits. Bit index order is not the order they run in:
 * irradiance runs before compose (render/renderer.c's pass table gives the order). */
enum lr_pass {
    LR_PASS_GBUFFER = 1u << 0,   /* light G-buffer */
    LR_PASS_RADIOSITY = 1u << 1, /* K scattered-radiosity maps (restart accumulation) */
    LR_PASS_VPL = 1u << 2,       /* virtual point lights on the outer surface */
    LR_PASS_COMPOSE = 1u << 3,   /* composition: one unit-intensity linear image per light */
    LR_PASS_BLEND = 1u << 4,     /* sum_l I_l image_l, tone mapping, output (passes/blend.h) */
    LR_PASS_IRRADIANCE = 1u << 5, /* receiver irradiance grids from the VPLs (before compose) */
    LR_PASS_SURFACE = 1u << 6,    /* the objects' B per refined vertex (passes/surface.h) */
    LR_PASS_LPV = 1u << 7,        /* render.lpv: the light-propagation volume (before the
                                   * radiosity pass; passes/lpv_pass.h) */
};

/* gbuffer, radiosity, vpl, compose, blend, irradiance, surface, lpv (bit index order). */
enum { LR_PASS_COUNT = 8 };

typedef struct lr_renderer lr_renderer; /* render/renderer.h */

/* One render pass, as the renderer allocates, schedules, runs and times it (issue 15; the
 * shape kmscube gives its back ends: a table of function pointers). Adding a pass is a new
 * row of the table in render/renderer.c (its hooks call the pass's own functions with the
 * inputs it reads), a bit above, and its state in struct lr_renderer. */
typedef struct lr_pass_desc {
    const char *name;  /* timer section and stats name */
    unsigned bit;      /* LR_PASS_* */
    unsigned dirty;    /* LR_DIRTY_* bits that make it due */
    unsigned feeds;    /* LR_PASS_* bits of the passes that read its output: due whenever it
                        * runs; they come later in the table */
    bool emergent;     /* a pass of the emergent light: never runs with the renderer's no_vpl */
    /* Resources for the settings the renderer was (re)allocated for; NULL: none, or made on
     * first use. free releases them (also after a failed alloc; idempotent). */
    int (*alloc)(lr_renderer *r, lr_err *e);
    void (*free)(lr_renderer *r);
    /* Due with nothing dirty (accumulation going on, a result not yet made); NULL: never. */
    bool (*due)(const lr_renderer *r);
    /* One run; dirty is the frame's LR_DIRTY_* mask. */
    int (*run)(lr_renderer *r, unsigned dirty, lr_err *e);
    /* Whether the pass is switched on by the settings (NULL: always); a pass that is off never
     * runs, whatever makes it due. */
    bool (*on)(const lr_renderer *r);
} lr_pass_desc;

/* The renderer's passes, LR_PASS_COUNT of them in the order they run (render/renderer.c). */
const lr_pass_desc *lr_pass_table(void);

/* The passes a dirty mask (LR_DIRTY_* bits) requires (0 for an empty mask: keep
 * accumulating): those whose `dirty` bits it has. */
unsigned lr_dirty_passes(unsigned dirty);

/* A frame's passes from those its changes require (lr_dirty_passes): adds the passes that
 * are due by themselves (the table's `due`) and, transitively, those that read the output of
 * a pass that runs (`feeds`); with no_emergent, drops the emergent-light passes; drops the
 * passes whose `on` says they are off. */
unsigned lr_schedule_close(const lr_renderer *r, unsigned passes, bool no_emergent);

/* "gbuffer", "radiosity", "vpl", "compose", "blend", "irradiance", "surface", "lpv" for bit
 * index 0..7; "?" otherwise. */
const char *lr_pass_name(int index);

#endif
