/* lamprig — the area lights' direct light on the plane receivers (render/area/frames.h,
 * area_direct.c): the running mean over accumulation frames of the direct irradiance from
 * each area light's frame sample p_f, shadowed through that frame's light G-buffer, at the
 * receiver irradiance grid's texel centres (render/core/recv_grid.h). Composition reads it
 * like the VPL grid (four fetches), so it needs no accumulation of its own. */
#ifndef LR_AREA_DIRECT_H
#define LR_AREA_DIRECT_H

#include "render/passes/gbuffer.h"
#include "render/passes/passes.h"

/* One layer per plane receiver and light (layer[i] + l; -1: a box receiver, none). */
typedef struct lr_area_direct {
    lr_tex *grid;
    lr_fb *fb[LR_MAX_RECEIVERS];
    int layer[LR_MAX_RECEIVERS];
    int n_receivers, n_lights;
    int F; /* frames in the running mean */
} lr_area_direct;

/* Whether the scene has an area light (the grid is needed). */
bool lr_area_direct_needed(const lr_scene *s);
/* Whether the pass runs: an area light, or render.lpv > 0 with a point or spot light and a
 * plane receiver (the grid then carries those lights' volume light alone, 0 direct). */
bool lr_area_direct_pass_needed(const lr_scene *s);
/* LR_EUNSUPPORTED when the scene has an area light and a box receiver (no grid there),
 * naming both; else LR_OK. */
int lr_area_direct_check(const lr_scene *s, lr_err *e);
void lr_area_direct_free(lr_area_direct *a);
/* Adds frame F (1-based; 1 restarts the mean) from the G-buffer as drawn for that frame.
 * lpv: render.lpv's receiver grids (render/passes/lpv_pass.h, the same layers as grid), added
 * to every frame's direct light so the running mean carries them; NULL: none. */
int lr_area_direct_run(lr_area_direct *a, const lr_pass_ctx *c, const lr_gbuffer *gb, int F,
                       const lr_tex *lpv, lr_err *e);
/* Receiver i's grid for compose_receiver.frag (unit 16), or u_area_cached = false. */
void lr_area_direct_bind(const lr_area_direct *a, const lr_pass_ctx *c, lr_program *p,
                         int receiver);

#endif
