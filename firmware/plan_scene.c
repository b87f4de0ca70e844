/* lamprig — applying the planner to a scene (see plan_scene.h). */
#include "firmware/plan_scene.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int lr_plan_scene(lr_scene *scene, const char *table, bool models_only,
                  lr_plan_scene_result *res, lr_err *e)
{
    memset(res, 0, sizeof *res);
    res->vpl = true;
    lr_plan_budget b;
    if (!lr_plan_budget_from_scene(scene, &b))
        return LR_OK;
    int rc;
    if (table) {
        snprintf(res->table, sizeof res->table, "%s", table);
        res->table_why = "given";
    } else if ((rc = lr_plan_default_table(res->table, sizeof res->table, &res->table_why, e))) {
        return rc;
    }
    lr_plan_table *t;
    if ((rc = lr_plan_table_load(res->table, &t, e)))
        return rc;
    rc = lr_plan_create(scene, t, &b, NULL, &res->plan, e);
    lr_plan_table_destroy(t);
    if (!rc)
        rc = models_only ? lr_plan_apply_models(&res->plan, scene, NULL, e)
                         : lr_plan_apply(&res->plan, scene, NULL, e);
    if (rc)
        return rc;
    res->planned = true;
    res->vpl = res->plan.vpl;
    return LR_OK;
}

int lr_plan_scene_replanner(const lr_scene *scene, const lr_plan_scene_result *res,
                            lr_replan **out, lr_err *e)
{
    *out = NULL;
    if (!res->planned)
        return lr_err_set(e, LR_EINVAL, "re-plan: the scene was not planned");
    lr_plan_table *t;
    int rc = lr_plan_table_load(res->table, &t, e);
    return rc ? rc : lr_replan_create(scene, t, &res->plan, NULL, out, e);
}

char *lr_plan_scene_text(const lr_plan_scene_result *res, bool verbose)
{
    size_t (*format)(const lr_plan *, char *, size_t) =
        verbose ? lr_plan_format : lr_plan_format_brief;
    size_t need = format(&res->plan, NULL, 0);
    size_t head = verbose ? strlen(res->table) + 64 : 1;
    char *buf = malloc(head + need + 1);
    if (!buf)
        return NULL;
    int n = verbose ? snprintf(buf, head, "plan: table %s (%s)\n", res->table,
                               res->table_why ? res->table_why : "given")
                    : 0;
    format(&res->plan, buf + n, need + 1);
    return buf;
}
