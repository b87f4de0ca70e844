/* lamprig planner — validity limits of the models that depend on the object's material.
 *
 * The measured table holds each scene with its shipped material; a control may give the object
 * another (a preset button, a translucency knob). Some models then leave the range in which
 * their measured error means anything, whatever the table says:
 *
 *   a model's own limit  its ops table's limit hook (render/models/model.h): the diffusion
 *                    grid must resolve the diffusion length (render/models/diffusion_grid/
 *                    diffusion_grid.h), SH translucency needs a wall thicker than one transport
 *                    mean free path (render/models/sh_translucency/sh_translucency.c).
 *   max_sigma_tr     a model whose properties (render/models/model.h) have one (translucent
 *                    radiosity: 500 /mm): beyond it (lr_sss_model_check_medium) its numerics
 *                    fail; the scene's loader and lr_scene_set refuse that material with that
 *                    model, and the planner leaves the model out.
 *
 * The other models have no limit that depends on the material here (the multipole needs a
 * thickness_mm, the grid a closed mesh: lr_scene_object_model_unmet, geometry).
 */
#ifndef LR_PLAN_LIMITS_H
#define LR_PLAN_LIMITS_H

#include <stddef.h>

#include "render/base/err.h"
#include "render/scene/scene.h"

/* Why model m is outside its validity limits for object o's current material (written to
 * buf, which is returned), or NULL when it is within them. */
const char *lr_plan_model_limit(const lr_scene_object *o, enum lr_sss_model m, char *buf,
                                size_t cap);

/* A model for a quick preview of object o after a change (render/async/): when o's own model
 * costs a CPU solve (lr_sss_model_props.solves), the first profile model in the enum's order
 * that o can render and that is within its limits for o's material (lr_plan_model_limit),
 * evaluated on the GPU frame by frame; NULL when o's own model needs no solve, or none fits. */
const char *lr_plan_preview_model(const lr_scene_object *o);

/* Refuses a scene an object of which is to render with a model outside these limits for its
 * material (objects[i].model forced by the scene file, `--set` or a control, where the planner
 * would have left the model out: the grid on porcelain otherwise fails after its solver's
 * every iteration): LR_EINVAL "objects[I].model: MODEL is outside its validity limit for
 * 'NAME' in MATERIAL: WHY" (WHY as lr_plan_model_limit). The rule is lr_plan_model_limit's,
 * the planner's own. */
int lr_plan_check_models(const lr_scene *s, lr_err *e);

#endif
