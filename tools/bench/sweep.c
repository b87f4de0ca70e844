/* Section "sweep": speed against error against the physical reference, for every scene in
 * configs/scenes/ (issue 6 items 2 and 4).
 *
 * Per scene: the physical reference at LRB_SWEEP_W x LRB_SWEEP_H, LRB_SWEEP_SPP samples per
 * pixel, through lr_ref_render_cached in configs/bench/references/ (keyed by the scene hash;
 * committed, because rendering the four references takes longer than the bench may on two
 * cores: tools/bench/README.md, "Speed against error"); object and receiver masks by ray casting;
 * then every
 * setting of sweep_settings.c as a GPU frame series (render/eval/series.c) with its errors
 * after 1, 4, 16 (and 64) frames, its bias (the converged series vs the reference) and noise
 * (F frames vs the converged series).
 *
 * Writes build/bench/results.csv, build/bench/pareto.png, build/bench/summary.md (atomically);
 * with --update-front also configs/bench/front.csv (the planner's measured table). */
#include "tools/bench/sweep.h"

#include <dirent.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "render/base/paths.h"

enum { MAX_SCENES = 16, MAX_ROWS = 1024 };

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* Base names of the .json files in configs/scenes, sorted. */
static int list_scenes(char names[MAX_SCENES][64])
{
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/scenes", lr_configs_dir());
    DIR *d = opendir(dir);
    if (!d) {
        fprintf(stderr, "bench sweep: %s: %s\n", dir, strerror(errno));
        return 0;
    }
    int n = 0;
    struct dirent *de;
    while ((de = readdir(d)) && n < MAX_SCENES) {
        size_t l = strlen(de->d_name);
        if (l > 5 && l < 64 && !strcmp(de->d_name + l - 5, ".json")) {
            memcpy(names[n], de->d_name, l - 5);
            names[n][l - 5] = '\0';
            n++;
        }
    }
    closedir(d);
    char *p[MAX_SCENES];
    for (int i = 0; i < n; i++)
        p[i] = names[i];
    qsort(p, (size_t)n, sizeof p[0], cmp_str);
    char sorted[MAX_SCENES][64];
    for (int i = 0; i < n; i++)
        memcpy(sorted[i], p[i], 64);
    memcpy(names, sorted, sizeof sorted[0] * (size_t)n);
    return n;
}

/* Scenes the physical reference cannot resolve at the bench's sample count, left out unless
 * named in LRB_SWEEP_SCENES: "sphere" (a point light at the centre of a non-absorbing marble
 * ball, the energy test) comes out of render/reference with every non-zero pixel a single
 * sample (relative standard error 1.0 at 16 spp), so no error against it would mean anything. */
static bool skipped(const char *name)
{
    return !strcmp(name, "sphere");
}

/* A sweep restricted or changed by the diagnosis variables is not the measured table the
 * planner reads (lr_plan_default_table takes build/bench/results.csv when it is newer than
 * the committed front): its files get a "-partial" suffix instead, and --update-front is
 * refused. The variable that makes it so, or NULL. */
static const char *partial_because(void)
{
    static const char *const vars[] = {"LRB_SWEEP_SCENES", "LRB_SWEEP_SETTINGS",
                                       "LRB_SWEEP_MODEL",  "LRB_SWEEP_SET",
                                       "LRB_SWEEP_LPV",    "LRB_SWEEP_SUPERSAMPLE",
                                       "LRB_SWEEP_SEED"};
    for (size_t i = 0; i < sizeof vars / sizeof vars[0]; i++)
        if (getenv(vars[i]) && *getenv(vars[i]))
            return vars[i];
    return NULL;
}

static int run_opts(FILE *out, const lrb_options *opt)
{
    const char *partial = partial_because();
    if (partial && opt->update_front) {
        fprintf(stderr, "bench sweep: --update-front needs the whole sweep (%s is set)\n",
                partial);
        return 2;
    }
    const char *sfx = partial ? "-partial" : "";
    char csv[64], png[64], md[64];
    snprintf(csv, sizeof csv, "build/bench/results%s.csv", sfx);
    snprintf(png, sizeof png, "build/bench/pareto%s.png", sfx);
    snprintf(md, sizeof md, "build/bench/summary%s.md", sfx);
    double t0 = lrb_now(), load[2][3] = {{0}};
    getloadavg(load[0], 3);
    if ((mkdir("build", 0777) && errno != EEXIST) || (mkdir("build/bench", 0777) && errno != EEXIST)) {
        fprintf(stderr, "bench sweep: cannot create build/bench: %s\n", strerror(errno));
        return 1;
    }
    lr_gl *gl = NULL;
    lr_err e = {0};
    if (lr_gl_create(NULL, &gl, &e)) {
        fprintf(stderr, "bench sweep: no GL context: %s\n", e.msg);
        return 1;
    }
    char names[MAX_SCENES][64];
    int nscenes = list_scenes(names), nrows = 0, status = 0;
    lr_eval_row *rows = calloc(MAX_ROWS, sizeof *rows);
    lrb_scene_result *res = calloc(MAX_SCENES, sizeof *res);
    if (!rows || !res || !nscenes) {
        free(rows), free(res);
        lr_gl_destroy(gl);
        return 1;
    }
    /* LRB_SWEEP_SCENES=candle,lampshade restricts the scenes (for working on the section). */
    const char *only = getenv("LRB_SWEEP_SCENES");
    int ns = 0;
    for (int k = 0; k < nscenes; k++) {
        if (only && !lrb_listed(only, names[k]))
            continue;
        if (!only && skipped(names[k]))
            continue;
        if (lrb_sweep_scene(gl, names[k], rows, &nrows, MAX_ROWS, &res[ns])) {
            fprintf(stderr, "bench sweep: %s: %s\n", names[k], res[ns].error);
            status = 1;
        }
        ns++;
    }
    /* summary.md's timing table: candle and lamp shade at 640x480. */
    lrb_timing_640 t640[2];
    int nt = 0;
    const char *table_scenes[] = {"candle", "lampshade"};
    for (int k = 0; k < 2; k++)
        if (!only || lrb_listed(only, table_scenes[k])) {
            if (lrb_sweep_time_640(gl, table_scenes[k], &t640[nt]))
                status = 1;
            nt++;
        }
    char info[512] = "unknown";
    {
        lr_scene *s = NULL;
        lr_renderer *r = NULL;
        char path[1024];
        snprintf(path, sizeof path, "%s/scenes/%s.json", lr_configs_dir(), names[0]);
        /* A probe for the renderer string; the scene's sweep prints its warnings. */
        if (!lr_scene_load(path, NULL, &s, &e) &&
            !lr_renderer_create(&(lr_renderer_desc){.gl = gl, .scene = s, .width = 16, .height = 16},
                                &r, &e))
            snprintf(info, sizeof info, "%s", lr_renderer_info(r));
        lr_renderer_destroy(r);
        lr_scene_destroy(s);
    }
    lr_gl_destroy(gl);
    getloadavg(load[1], 3);
    double total = lrb_now() - t0;
    if (lr_eval_csv_write(csv, rows, nrows, &e) ||
        lrb_sweep_plot(png, rows, nrows, res, ns, &e) ||
        lrb_sweep_summary(md, rows, nrows, res, ns, t640, nt, load, total, info, &e)) {
        fprintf(stderr, "bench sweep: %s\n", e.msg);
        status = 1;
    }
    if (!status && opt->update_front) {
        char front[1024];
        snprintf(front, sizeof front, "%s/bench/front.csv", lr_configs_dir());
        if (lr_eval_csv_write(front, rows, nrows, &e)) {
            fprintf(stderr, "bench sweep: %s\n", e.msg);
            status = 1;
        } else
            fprintf(stderr, "bench sweep: wrote %s\n", front);
    }
    fprintf(out, "## Speed against error (`lamprig-bench sweep`)\n\n");
    fprintf(out, "%d rows over %d scenes in %.0f s at %d×%d (load average %.2f → %.2f). Wrote "
                 "%s, %s and %s%s.",
            nrows, ns, total, LRB_SWEEP_W, LRB_SWEEP_H, load[0][0], load[1][0], csv, png, md,
            !status && opt->update_front ? " and configs/bench/front.csv" : "");
    if (partial)
        fprintf(out, " A partial sweep (%s is set): the planner's table build/bench/results.csv "
                     "is left as it was.", partial);
    fprintf(out, "\n\n");
    lrb_sweep_table_md(out, rows, nrows, t640, nt);
    lrb_sweep_fair_md(out, res, ns);
    for (int k = 0; k < ns; k++)
        fprintf(out, "- %s: %s; reference SE %.4f (objects) / %.4f (receivers); units check "
                     "%.4f ± %.4f\n",
                res[k].name, res[k].ok ? "ok" : res[k].error, res[k].ref_se_object,
                res[k].ref_se_receivers, res[k].units_ratio, res[k].units_se);
    fprintf(out, "\n");
    free(rows);
    free(res);
    return status;
}

static int run(FILE *out)
{
    return run_opts(out, &(lrb_options){0});
}

const lrb_section lrb_sweep_section = {
    .name = "sweep",
    .summary = "speed against error vs the physical reference, every scene (results.csv, "
               "pareto.png, summary.md; --update-front)",
    .run = run,
    .run_opts = run_opts,
};
