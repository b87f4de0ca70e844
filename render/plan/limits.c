/* lamprig planner — the material-dependent validity limits of the models (see limits.h). */
#include "render/plan/limits.h"

#include <math.h>
#include <stdio.h>

#include "render/diffusion/dscene.h"

const char *lr_plan_model_limit(const lr_scene_object *o, enum lr_sss_model m, char *buf,
                                size_t cap)
{
    const lr_coeffs *c = &o->coeffs;
    lr_err le = {0};
    if (lr_sss_model_check_medium(m, &o->material.medium, &le)) { /* the model's numerics */
        snprintf(buf, cap, "%s", le.msg);
        return buf;
    }
    if (m == LR_SSS_DIFFUSION_GRID) {
        double h = lr_dscene_spacing(o);
        double s = fmax(c->sigma_tr[0], fmax(c->sigma_tr[1], c->sigma_tr[2]));
        if (!(s * h <= LR_PLAN_GRID_MAX_SIGMA_H)) {
            snprintf(buf, cap, "the grid spacing %.2g mm is %.2g diffusion lengths of the "
                     "material (sigma_tr %.3g /mm in its largest band; at most %g: the "
                     "stencil's decay rate is then %.0f %% low)",
                     h, s * h, s, LR_PLAN_GRID_MAX_SIGMA_H,
                     100.0 * (1.0 - acosh(1.0 + 0.5 * s * h * s * h) / (s * h)));
            return buf;
        }
        /* A wall thinner than the spacing has cells with no interior node: the grid's
         * boundary ghosts have nothing to couple to (render/diffusion/system.c refuses it). */
        if (o->thickness_mm > 0.0 && o->thickness_mm < h) {
            snprintf(buf, cap, "the wall (%.3g mm) is thinner than the grid spacing %.3g mm",
                     o->thickness_mm, h);
            return buf;
        }
    }
    if (m == LR_SSS_SH_TRANSLUCENCY && o->thickness_mm > 0.0) {
        double mfp = fmax(c->mfp[0], fmax(c->mfp[1], c->mfp[2]));
        if (o->thickness_mm < mfp) {
            snprintf(buf, cap, "the wall (%.3g mm) is thinner than one transport mean free path "
                     "of the material (%.3g mm), where the SH attenuation is clamped",
                     o->thickness_mm, mfp);
            return buf;
        }
    }
    return NULL;
}

int lr_plan_check_models(const lr_scene *s, lr_err *e)
{
    for (int i = 0; i < lr_scene_object_count(s); i++) {
        const lr_scene_object *o = lr_scene_object_at(s, i);
        char why[LR_ERR_MSG_MAX];
        if (lr_plan_model_limit(o, o->sss_model, why, sizeof why))
            return lr_err_set(e, LR_EINVAL, "objects[%d].model: %s is outside its validity "
                              "limit for '%s' in %s: %s", i, lr_sss_model_name(o->sss_model),
                              o->name, o->material.name[0] ? o->material.name : "its material",
                              why);
    }
    return LR_OK;
}

const char *lr_plan_preview_model(const lr_scene_object *o)
{
    if (!lr_sss_model_props_of(o->sss_model)->solves)
        return NULL;
    for (int m = 0; m < LR_SSS_MODEL_COUNT; m++) {
        const lr_sss_model_props *p = lr_sss_model_props_of((enum lr_sss_model)m);
        char why[256];
        if (p->solves || p->no_profile || lr_scene_object_model_unmet(o, (enum lr_sss_model)m) ||
            lr_plan_model_limit(o, (enum lr_sss_model)m, why, sizeof why))
            continue;
        return lr_sss_model_name((enum lr_sss_model)m);
    }
    return NULL;
}
