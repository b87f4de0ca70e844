/* lamprig planner — the material-dependent validity limits of the models (see limits.h). */
#include "render/plan/limits.h"

#include <stdio.h>

const char *lr_plan_model_limit(const lr_scene_object *o, enum lr_sss_model m, char *buf,
                                size_t cap)
{
    lr_err le = {0};
    if (lr_sss_model_check_medium(m, &o->material.medium, &le)) { /* the model's numerics */
        snprintf(buf, cap, "%s", le.msg);
        return buf;
    }
    const lr_model_ops *ops = lr_model_of(m); /* its own limits (render/models/model.h) */
    return ops && ops->limit ? ops->limit(o, buf, cap) : NULL;
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
