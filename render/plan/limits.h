/* lamprig planner — validity limits of the models that depend on the object's material.
 *
 * The measured table holds each scene with its shipped material; a control may give the object
 * another (a preset button, a translucency knob). Some models then leave the range in which
 * their measured error means anything, whatever the table says:
 *
 *   diffusion_grid   the grid (render/diffusion/dgrid.h, 7-point finite differences of seed 001
 *                    Eq. 1) must resolve the diffusion length 1/sigma_tr. Along a grid axis the
 *                    discrete solution of phi'' = sigma_tr^2 phi decays as e^{-lambda x} with
 *                    2 (cosh(lambda h) - 1) / h^2 = sigma_tr^2, i.e.
 *                    lambda h = acosh(1 + (sigma_tr h)^2 / 2): at sigma_tr h = 1 the decay rate
 *                    is 3.8 % low and the error grows as (sigma_tr h)^2 / 24 beyond. The limit
 *                    is LR_PLAN_GRID_MAX_SIGMA_H for the largest band's sigma_tr and the spacing
 *                    the object gets (lr_dscene_spacing). A wall (thickness_mm) thinner than
 *                    that spacing has cells with no interior node and is refused too.
 *   sh_translucency  seed 002 attenuates by the crossed thickness d through
 *                    a_c = exp(-sigma_tr max(d, 1/sigma_t')) (render/optics/sh_translucency.h: the
 *                    clamp at one transport mean free path). A wall (thickness_mm) thinner than
 *                    that mean free path in some band sits wholly in the clamp: the model cannot
 *                    tell that wall from a thicker one, so its figures do not carry over.
 *
 *   max_sigma_tr     a model whose row in render/optics/model.c has one (translucent
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

#define LR_PLAN_GRID_MAX_SIGMA_H 1.0

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
