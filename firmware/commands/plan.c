/* lamprig plan — prints the planner's choice for a scene and nothing else: per object the
 * measured model and settings, predicted error and time, and why (render/plan/plan.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "firmware/commands/commands.h"
#include "render/plan/plan.h"
#include "render/scene/scene.h"

static int run_plan(const lr_cli *c);

static const lr_argspec opts[] = {
    {.name = "--scene", .type = LR_ARG_PATH, .flags = LR_ARG_REQUIRED,
     .help = "the scene (configs/scenes/*.json); its \"quality\" block is the budget"},
    {.name = "--max-error", .type = LR_ARG_NUMBER, .metavar = "E", .flags = LR_ARG_ABOVE_MIN,
     .help = "error budget (alone or with --frame-ms and --converge-ms, replaces the\n"
             "scene's max_error, frame_ms and converge_ms)"},
    {.name = "--frame-ms", .type = LR_ARG_NUMBER, .metavar = "T", .flags = LR_ARG_ABOVE_MIN,
     .help = "milliseconds per accumulation frame (the same)"},
    {.name = "--converge-ms", .type = LR_ARG_NUMBER, .metavar = "T", .flags = LR_ARG_ABOVE_MIN,
     .help = "milliseconds from a change to the converged image (the same)"},
    {.name = "--change-ms", .type = LR_ARG_NUMBER, .metavar = "T", .flags = LR_ARG_ABOVE_MIN,
     .help = "longest wait after a material change: models measured slower\n"
             "(configs/bench/models.csv) are left out (default: the scene's\n"
             "quality.change_ms)"},
    {.name = "--table", .type = LR_ARG_PATH, .metavar = "CSV",
     .help = "the measured table (default: build/bench/results.csv when at least as\n"
             "new as configs/bench/front.csv, else that one)"},
    {.name = "--json", .help = "one JSON object instead of text (every detail)"},
    {.name = "--verbose",
     .help = "the table used, a line per object with its settings, predicted error parts\n"
             "and reasons, the budget line and the light transport (default: one sentence)"},
    {.name = "--models", .type = LR_ARG_STRING,
     .metavar = "MODEL,...|all",
     .help = "models to choose from, comma-separated objects[].model names\n"
             "(default all; an object that cannot take a model, such as the\n"
             "multipole without thickness_mm, skips its rows)"},
    {0},
};

const lr_command lr_plan_command = {
    .name = "plan",
    .summary = "choose per object the cheapest measured settings that meet the scene's quality "
               "budget",
    .about =
        "Prints in one sentence the model and maps chosen, the predicted error and frame time,\n"
        "and whether the budget holds. --verbose prints, per object of the scene, the cheapest\n"
        "measured model and settings (K, N, N_vpl, map and G-buffer sizes, frames, VPLs on or off)\n"
        "that meet the budget, the predicted error (against the physical reference) and time, and\n"
        "the reasons: the measured scene the rows come from, whether any receiver sees the object\n"
        "(else no VPL pass), how many maps cover its surface (convex objects need fewer),\n"
        "infeasible budgets.",
    .opts = opts,
    .notes =
        "Exit status: 0 planned (an infeasible budget is planned to the closest setting and said\n"
        "so); 1 the table cannot be read or has no usable row; 2 bad arguments, scene or budget.\n"
        "\n"
        "Example:\n"
        "  lamprig plan --scene configs/scenes/candle.json --max-error 0.05",
    .run = run_plan,
};

static int models_arg(const lr_cli *c, const char *v, unsigned *out)
{
    *out = 0;
    if (!v)
        return LR_EXIT_OK;
    char buf[128];
    snprintf(buf, sizeof buf, "%s", v);
    for (char *tok = strtok(buf, ","); tok; tok = strtok(NULL, ",")) {
        enum lr_sss_model m;
        if (!strcmp(tok, "all"))
            *out |= LR_PLAN_MODEL_ALL;
        else if (lr_sss_model_parse(tok, &m))
            *out |= LR_PLAN_MODEL_BIT(m);
        else
            return lr_cli_usage(c->path, "--models %.100s: expected a model name "
                                         "(`lamprig render --help-scene`, objects[].model) or all",
                                tok);
    }
    if (!*out)
        return lr_cli_usage(c->path, "--models: empty");
    return LR_EXIT_OK;
}

static int run_plan(const lr_cli *c)
{
    const lr_args *a = &c->args;
    lr_err e = {0};
    const char *scene_path = lr_args_get(a, "--scene");
    lr_plan_budget given = {0}, b;
    unsigned models;
    int st;
    if ((st = lr_cli_check(c, lr_args_double(a, "--max-error", &given.max_error, &e) ||
                                  lr_args_double(a, "--frame-ms", &given.frame_ms, &e) ||
                                  lr_args_double(a, "--converge-ms", &given.converge_ms, &e) ||
                                  lr_args_double(a, "--change-ms", &given.change_ms, &e),
                           &e)) ||
        (st = models_arg(c, lr_args_get(a, "--models"), &models)))
        return st;

    lr_scene *scene = NULL;
    lr_warn_sink warn = lr_cli_warn_sink(c->path);
    if (lr_scene_load(scene_path, &warn, &scene, &e)) {
        if (e.code == LR_EIO)
            return lr_cli_fail(c->path, "%s", e.msg);
        return lr_cli_usage(c->path, "%s", e.msg);
    }
    if (!lr_plan_budget_resolve(scene, &given, &b)) {
        lr_scene_destroy(scene);
        return lr_cli_usage(c->path, "the scene has no quality budget (quality.max_error, "
                           "quality.frame_ms or quality.converge_ms): give --max-error, "
                           "--frame-ms or --converge-ms");
    }
    char table[1024];
    const char *why = "given";
    const char *tp = lr_args_get(a, "--table");
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
    bool json = lr_args_has(a, "--json"), verbose = lr_args_has(a, "--verbose");
    size_t (*format)(const lr_plan *, char *, size_t) =
        json ? lr_plan_format_json : verbose ? lr_plan_format : lr_plan_format_brief;
    size_t need = format(plan, NULL, 0);
    if (!(text = malloc(need + 1)))
        goto done;
    format(plan, text, need + 1);
    if (verbose && !json)
        printf("plan: table %s (%s)\n", table, why);
    fputs(text, stdout);
    st = LR_EXIT_OK;
    goto done;
fail:
    lr_cli_fail(c->path, "%s", e.msg);
done:
    free(text);
    free(plan);
    lr_plan_table_destroy(t);
    lr_scene_destroy(scene);
    return st;
}
