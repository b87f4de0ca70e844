/* lamprig planner — re-planning an object when a control changes its material (issue 14,
 * item 5).
 *
 * The plan made at scene load (lr_plan_create) chose each object's model and settings from
 * rows measured with the scene's shipped material. A control may then give the object another
 * material (a preset button, a translucency knob, a coefficient). For each object whose model
 * the planner chose, lr_replan_update chooses again with the new material:
 *
 *   rows       the table has no rows for the new material: it holds each measured scene with
 *              its shipped material. The object (its geometry features from the load-time
 *              analysis, its size in diffusion lengths radius x mean sigma_tr from the new
 *              material) is matched to the measured scenes by the planner's feature distance
 *              (light enclosed, shell, convex, |ln| size ratio), its own scene included at its
 *              shipped material, and that scene's rows are used. The predicted error and time
 *              are those rows' measured figures: the nearest measured material, not a
 *              measurement of this one, and the reasons say how far it is (|ln| of the size
 *              ratio). Back on the shipped material the re-plan is the load-time plan.
 *   limits     models outside their validity limits for the new material are left out
 *              (render/plan/limits.h: the diffusion grid must resolve the diffusion length;
 *              the SH attenuation is clamped inside one transport mean free path), as are
 *              models the object cannot take (lr_scene_object_model_unmet).
 *   VPL rows   the view's VPL pass is fixed at load, so only rows with its VPL state are
 *              candidates (any row when no receiver sees the object).
 *
 * Applying: a new model goes through lr_scene_set("objects[i].model") (LR_DIRTY_MATERIAL:
 * the object's maps re-run, which the material change needed anyway); the scene-wide
 * settings are recomputed as at load (the largest of the choices) and written only where they
 * differ from what the plan last wrote and nothing else (the config's scene_set, a control)
 * has changed them since.
 *
 * Not re-planned: an object whose model someone else set (its model differs from the one the
 * planner last applied: the config's scene_set or a control set it; from then on it stays
 * pinned), or when the changes carry no LR_DIRTY_MATERIAL (a dimmer is LR_DIRTY_INTENSITY
 * only: blend-only, never a re-plan), or when the object's optical coefficients and
 * thickness_mm are what they were when it was last planned (a model or normalisation change,
 * a control writing the same value).
 */
#ifndef LR_PLAN_REPLAN_H
#define LR_PLAN_REPLAN_H

#include <stdbool.h>

#include "render/base/err.h"
#include "render/plan/plan.h"
#include "render/scene/scene.h"

typedef struct lr_replan lr_replan;

/* Keeps what re-planning needs after plan p was made for scene s and applied to it: the
 * table (taken over: destroyed with the re-planner, also on error), the budget, the objects'
 * choices and analyses, each object's material as planned, and the features of every scene
 * the table measures (loaded from CONFIGS/scenes/NAME.json at its shipped material;
 * configs_dir NULL: lr_configs_dir(); a scene that does not load is left out of matching). */
int lr_replan_create(const lr_scene *s, lr_plan_table *t, const lr_plan *p,
                     const lr_plan_options *opt, lr_replan **out, lr_err *e);
void lr_replan_destroy(lr_replan *r);

/* Re-plans after scene changes that ORed `changed` (their LR_DIRTY_* flags): see the top of
 * this file. Writes the new model and settings into s, ORing their flags into *dirty (may be
 * NULL). *text (may be NULL) receives a malloc'd log text, one line per re-planned object as
 * lr_plan_format_choice writes it, a line saying whether its model changed, and one scene
 * line; only for objects whose chosen row changed (a knob fading through materials re-plans
 * on every frame of the fade, mostly to the same row); NULL when nothing was said. *replanned (may be NULL): the objects
 * re-planned. An object whose re-plan finds no usable row keeps its model, and the text says
 * so (not an error). Errors: LR_ENOMEM; a rejected lr_scene_set (cannot happen for values the
 * table's parser accepted, but reported). */
int lr_replan_update(lr_replan *r, lr_scene *s, unsigned changed, unsigned *dirty, char **text,
                     int *replanned, lr_err *e);

/* What lr_replan_update would write into s after changes `changed`, written into s (a copy
 * of the planned scene with a state to come: render/async/'s states built ahead), r itself
 * left as it is. */
int lr_replan_what_if(const lr_replan *r, lr_scene *s, unsigned changed, unsigned *dirty,
                      lr_err *e);

/* The plan as it stands after the last re-plan. */
const lr_plan *lr_replan_plan(const lr_replan *r);
/* Whether object i is left to its own model (see the top of this file). */
bool lr_replan_pinned(const lr_replan *r, int index);
/* Re-plans done so far (for logs and tests). */
int lr_replan_count(const lr_replan *r);

#endif
