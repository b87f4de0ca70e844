/* lamprig plan — prints the planner's choice for a scene and nothing else: per object the
 * measured model and settings, predicted error and time, and why (render/plan/plan.h). */
#include "firmware/cmd_plan.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "firmware/args.h"
#include "firmware/cli.h"
#include "render/plan/plan.h"
#include "render/scene/scene.h"

const char lr_plan_summary[] = "choose per object the cheapest measured settings that meet the "
                               "scene's quality budget";

const char lr_plan_usage[] =
    "usage: lamprig plan --scene FILE [--max-error E] [--frame-ms T] [--table CSV] [--json]\n"
    "                    [--models directional_dipole|standard_dipole|all]\n"
    "\n"
    "Prints, per object of the scene, the cheapest measured model and settings (K, N, N_vpl,\n"
    "map and G-buffer sizes, frames, VPLs on or off) that meet the budget, the predicted error\n"
    "(relative RMSE against the physical reference) and time, and the reasons: the measured\n"
    "scene the rows come from, whether any receiver sees the object (else no VPL pass), how\n"
    "many maps cover its surface (convex objects need fewer), infeasible budgets.\n"
    "\n"
    "  --scene FILE     the scene (configs/scenes/*.json); its \"quality\" block is the budget\n"
    "  --max-error E    relative RMSE budget (replaces the scene's quality block with --frame-ms)\n"
    "  --frame-ms T     milliseconds per accumulation frame\n"
    "  --table CSV      the measured table (default: build/bench/results.csv when at least as\n"
    "                   new as configs/bench/front.csv, else that one)\n"
    "  --json           one JSON object instead of text\n"
    "  --models LIST    models to choose from: directional_dipole, standard_dipole or all\n"
    "                   (default all; the renderer runs both, per object)\n"
    "\n"
    "Exit status: 0 planned (an infeasible budget is planned to the closest setting and said\n"
    "so); 1 the table cannot be read or has no usable row; 2 bad arguments, scene or budget.\n"
    "\n"
    "Example:\n"
    "  lamprig plan --scene configs/scenes/candle.json --max-error 0.05";

static int usage_error(const char *msg)
{
    char buf[LR_ERR_MSG_MAX];
    snprintf(buf, sizeof buf, "%s", msg);
    for (char *c = buf; *c; c++)
        if ((unsigned char)*c < 0x20 || *c == 0x7f)
            *c = '?';
    fprintf(stderr, "lamprig plan: %s (see `lamprig help plan`)\n", buf);
    return LR_EXIT_USAGE;
}

static int budget_arg(const lr_args *a, const char *flag, double *out)
{
    lr_err e = {0};
    const char *v = lr_args_get(a, flag);
    if (!v)
        return LR_EXIT_OK;
    if (lr_args_number(flag, v, out, &e))
        return usage_error(e.msg);
    if (!(*out > 0)) {
        char m[128];
        snprintf(m, sizeof m, "%s %s: must be > 0", flag, v);
        return usage_error(m);
    }
    return LR_EXIT_OK;
}

static int models_arg(const char *v, unsigned *out)
{
    *out = 0;
    if (!v)
        return LR_EXIT_OK;
    char buf[128];
    snprintf(buf, sizeof buf, "%s", v);
    for (char *tok = strtok(buf, ","); tok; tok = strtok(NULL, ",")) {
        if (!strcmp(tok, "all"))
            *out |= LR_PLAN_MODEL_DIRECTIONAL | LR_PLAN_MODEL_STANDARD;
        else if (!strcmp(tok, "directional_dipole"))
            *out |= LR_PLAN_MODEL_DIRECTIONAL;
        else if (!strcmp(tok, "standard_dipole"))
            *out |= LR_PLAN_MODEL_STANDARD;
        else {
            char m[200];
            snprintf(m, sizeof m, "--models %.100s: expected directional_dipole, standard_dipole or all",
                     tok);
            return usage_error(m);
        }
    }
    if (!*out)
        return usage_error("--models: empty");
    return LR_EXIT_OK;
}

int lr_cmd_plan(int argc, char **argv)
{
    static const lr_argspec specs[] = {{"--scene", 1}, {"--max-error", 1}, {"--frame-ms", 1},
                                       {"--table", 1}, {"--json", 0},      {"--models", 1},
                                       {NULL, 0}};
    lr_args a;
    lr_err e = {0};
    if (lr_args_parse(argc - 1, argv + 1, specs, 0, &a, &e))
        return usage_error(e.msg);
    const char *scene_path = lr_args_get(&a, "--scene");
    if (!scene_path)
        return usage_error("--scene FILE is required");
    lr_plan_budget b = {0};
    unsigned models;
    int st;
    if ((st = budget_arg(&a, "--max-error", &b.max_error)) ||
        (st = budget_arg(&a, "--frame-ms", &b.frame_ms)) ||
        (st = models_arg(lr_args_get(&a, "--models"), &models)))
        return st;

    lr_scene *scene = NULL;
    if (lr_scene_load(scene_path, NULL, &scene, &e)) {
        if (e.code == LR_EIO) {
            fprintf(stderr, "lamprig plan: %s\n", e.msg);
            return LR_EXIT_FAIL;
        }
        return usage_error(e.msg);
    }
    if (!(b.max_error > 0) && !(b.frame_ms > 0) && !lr_plan_budget_from_scene(scene, &b)) {
        lr_scene_destroy(scene);
        return usage_error("the scene has no quality budget (quality.max_error or "
                           "quality.frame_ms): give --max-error or --frame-ms");
    }
    char table[1024];
    const char *why = "given";
    const char *tp = lr_args_get(&a, "--table");
    lr_plan_table *t = NULL;
    lr_plan *plan = calloc(1, sizeof *plan);
    char *text = NULL;
    st = LR_EXIT_FAIL;
    if (!plan)
        goto done;
    if (tp)
        snprintf(table, sizeof table, "%s", tp);
    else if (lr_plan_default_table(table, sizeof table, &why, &e))
        goto fail;
    if (lr_plan_table_load(table, &t, &e))
        goto fail;
    if (lr_plan_create(scene, t, &b, &(lr_plan_options){.models = models}, plan, &e))
        goto fail;
    bool json = lr_args_has(&a, "--json");
    size_t need = json ? lr_plan_format_json(plan, NULL, 0) : lr_plan_format(plan, NULL, 0);
    if (!(text = malloc(need + 1)))
        goto done;
    if (json)
        lr_plan_format_json(plan, text, need + 1);
    else
        lr_plan_format(plan, text, need + 1);
    if (!json)
        printf("plan: table %s (%s)\n", table, why);
    fputs(text, stdout);
    st = LR_EXIT_OK;
    goto done;
fail:
    fprintf(stderr, "lamprig plan: %s\n", e.msg);
done:
    free(text);
    free(plan);
    lr_plan_table_destroy(t);
    lr_scene_destroy(scene);
    return st;
}
