/* lamprig — the planner as `lamprig render` and `lamprig run` use it: when a scene has a
 * quality budget, plan it from the measured table (render/plan/plan.h) and apply the
 * choice to the scene before the explicit settings (--set, the rig's scene_set), which win. */
#ifndef LR_PLAN_SCENE_H
#define LR_PLAN_SCENE_H

#include <stdbool.h>
#include <stddef.h>

#include "render/base/err.h"
#include "render/plan/plan.h"
#include "render/plan/replan.h"
#include "render/scene/scene.h"

typedef struct lr_plan_scene_result {
    bool planned;  /* the scene had a budget and the plan was applied */
    bool vpl;      /* the plan keeps the VPL pass (true when not planned) */
    lr_plan plan;  /* when planned */
    char table[1024];
    const char *table_why; /* "given", "newest bench run", "committed front" */
} lr_plan_scene_result;

/* Plans `scene` when its quality block sets a budget (nothing to do otherwise: *res says
 * planned = false) and applies the settings and models, or with models_only each object's
 * model alone (the scene's render settings stay: `lamprig render --plan-models`). table: a
 * CSV path, or NULL for lr_plan_default_table. Errors (no table, bad table, no usable row)
 * leave the scene as it was; the caller decides whether that is fatal. */
int lr_plan_scene(lr_scene *scene, const char *table, bool models_only,
                  lr_plan_scene_result *res, lr_err *e);

/* A re-planner (render/plan/replan.h) for the scene a successful lr_plan_scene planned, over
 * the same table (loaded again). Call it once the settings that win over the plan (the rig's
 * scene_set) are applied: an object whose model they set is then left alone. */
int lr_plan_scene_replanner(const lr_scene *scene, const lr_plan_scene_result *res,
                            lr_replan **out, lr_err *e);

/* verbose: the plan's lines (lr_plan_format) preceded by "plan: table PATH (WHY)"; else its
 * one sentence (lr_plan_format_brief). Returns a malloc'd string, NULL when out of memory. */
char *lr_plan_scene_text(const lr_plan_scene_result *res, bool verbose);

#endif
