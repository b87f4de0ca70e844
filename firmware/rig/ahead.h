/* lamprig firmware — the control space built ahead (issue 32, item 3): which scene keys name
 * a state of the rig's controls, and which states the designer may ask for next, handed to
 * the view's control-space cache (render/async/cache.h through lr_rig_view_anticipate).
 *
 * Keys: the parameter of every cycle binding (a material preset; not "scene") and of every
 * level binding whose writes change light transport (a material's scale or tint: found by
 * writing the current value into a copy and reading the flags; a dimmer or a flicker knob is
 * one blend and needs no cache), interpolated per band in the value; and the keys a re-plan
 * writes (every object's model, the render settings), so a preset that the planner answers
 * with another model is another state.
 *
 * States, in this order: the state shown now (no assignment: the sample an interpolation
 * around it needs), then each the controls as they stand with one moved: every other value of
 * each cycle binding (the next one first, then the previous, then the rest), then for each
 * transport level binding `samples` positions evenly spaced over its travel (0, 1/(n-1), ...,
 * 1: the control's own scale, its curve applied as the map applies it), nearest the current
 * position first. Each state's assignments are what the control map and the re-planner would
 * write (lr_control_map_what_if, lr_replan_what_if on a copy of the scene), recorded through
 * the copy's journal.
 *
 * The list is made in steps, one state per lr_rig_ahead_step (a scene copy and a what-if:
 * the copy alone measured 6-8 ms for the candle and the votive and 16 ms for the lamp shade
 * on the 2-core proxy under load; the sim rig's longest whole step, idle, 13 ms: under one
 * frame interval; the rig logs its longest step),
 * once the controls have rested LR_RIG_AHEAD_REST_S seconds after the last transport change,
 * and handed to the view after each step (the worker starts on the first states while the
 * rest are made).
 */
#ifndef LR_RIG_AHEAD_H
#define LR_RIG_AHEAD_H

#include <stdbool.h>
#include <stdint.h>

#include "firmware/rig/control_map.h"
#include "render/async/async.h"
#include "render/base/err.h"
#include "render/plan/replan.h"
#include "render/scene/scene.h"

#define LR_RIG_AHEAD_REST_S 0.3

/* The cache keys for map over scene; *n their count (at most max). */
int lr_rig_ahead_keys(const lr_control_map *map, const lr_scene *scene, lr_cache_key *keys,
                      int max, int *n, lr_err *e);

typedef struct lr_rig_ahead lr_rig_ahead;

/* samples: positions per level binding (2..LR_ASYNC_MAX_STATES). */
int lr_rig_ahead_create(int samples, lr_rig_ahead **out, lr_err *e);
void lr_rig_ahead_destroy(lr_rig_ahead *h);
/* The controls changed light transport at now_ns: the list starts again after the rest. */
void lr_rig_ahead_changed(lr_rig_ahead *h, int64_t now_ns);
/* Whether a step is due at now_ns (rested and the list not finished). */
bool lr_rig_ahead_due(const lr_rig_ahead *h, int64_t now_ns);
/* When the next step may be due (the end of the rest), INT64_MAX when the list is done. */
int64_t lr_rig_ahead_wake_ns(const lr_rig_ahead *h);
/* Makes the next state of the list from map, scene (copied; replan may be NULL), and returns
 * the list so far in *states, *n (owned by h, valid until the next call), *done when it is
 * complete. A state the copy refuses is left out (not an error). */
int lr_rig_ahead_step(lr_rig_ahead *h, const lr_control_map *map, const lr_scene *scene,
                      const lr_replan *replan, int64_t now_ns, const lr_async_state **states,
                      int *n, bool *done, lr_err *e);

#endif
