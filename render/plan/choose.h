/* lamprig planner — the parts the start plan (plan.c) and the re-plan after a material change
 * (replan.c) share. Internal to render/plan/. */
#ifndef LR_PLAN_CHOOSE_H
#define LR_PLAN_CHOOSE_H

#include <stddef.h>

#include "render/plan/plan.h"

/* Picks object `index`'s row among the rows of c->table_scene (set by the caller, with
 * c->analysis), by the budget rules of lr_plan_create, leaving out models not in `models`,
 * models the object cannot take (lr_scene_object_model_unmet) and models outside their
 * validity limits for its material (lr_plan_model_limit). vpl_rows: -1 any row; 0 or 1 only
 * rows with that VPL state. time_scene (NULL: c->table_scene): the measured scene whose
 * times (frame_ms, ms_gbuffer, ms_lpv, the models table's change cost) a row is costed with,
 * from its row of the same model and settings (any frames; the slowest when measured more
 * than once) where it has one: the re-plan takes errors from the scene nearest by material
 * but times from the object's own scene, since a frame's cost follows the geometry, the
 * receivers and the image, not the material. Fills c->row, vpl, predicted_*, feasible and
 * appends reasons. LR_EINVAL when no row is usable. */
int lr_plan_choose(const lr_scene *s, int index, const lr_plan_table *t, const lr_plan_budget *b,
                   unsigned models, int vpl_rows, const char *time_scene, lr_plan_choice *c,
                   lr_err *e);

/* The distance between two objects' features that matches a scene to the table's (weights:
 * light enclosed 4, shell 4, convex 2, |ln| of the size in diffusion lengths). */
double lr_plan_feature_distance(const lr_plan_features *a, const lr_plan_features *b);
/* "light enclosed, solid, not convex, 6.3 diffusion lengths". */
const char *lr_plan_features_text(const lr_plan_features *f, char *buf, size_t cap);
/* The scene file's base name without extension: what the bench writes in `scene`. */
void lr_plan_scene_key(const lr_scene *s, char *buf, size_t cap);

#endif
