/* lamprig render — renders a scene headless (EGL surfaceless) through the renderer of
 * render/renderer.h, writes the image, the linear HDR image and per-frame statistics. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>

#include "firmware/commands/commands.h"
#include "firmware/plan_scene.h"
#include "firmware/render_events.h"
#include "render/base/atomic_file.h"
#include "render/base/json_write.h"
#include "render/gl/gl.h"
#include "render/image/image.h"
#include "render/optics/optics.h"
#include "render/plan/limits.h"
#include "render/renderer.h"
#include "render/renderer_debug.h"
#include "render/scene/scene.h"

#define MAX_SETS 64

static int run_render(const lr_cli *c);

static const lr_argspec opts[] = {
    {.name = "--scene", .type = LR_ARG_PATH, .flags = LR_ARG_REQUIRED,
     .help = "the scene (configs/scenes/*.json)"},
    {.name = "--frames", .type = LR_ARG_INT, .min = 1, .max = 1000000,
     .help = "frames to render (default: until the maps have accumulated\n"
             "render.frames frames and every event has been applied)"},
    {.name = "--width", .type = LR_ARG_INT, .metavar = "W", .min = 1, .max = 16384,
     .help = "output width (default 640)"},
    {.name = "--height", .type = LR_ARG_INT, .metavar = "H", .min = 1, .max = 16384,
     .help = "output height (default 480)"},
    {.name = "--out", .type = LR_ARG_PATH, .metavar = "F.png", .flags = LR_ARG_OUTPUT,
     .help = "tone-mapped 8-bit sRGB image (exposure render.exposure)"},
    {.name = "--hdr", .type = LR_ARG_PATH, .metavar = "F.pfm", .flags = LR_ARG_OUTPUT,
     .help = "linear RGB radiance, W/(mm^2 sr), PFM"},
    {.name = "--stats", .type = LR_ARG_PATH, .metavar = "F.json", .flags = LR_ARG_OUTPUT,
     .help = "{\"scene\",\"width\",\"height\",\"uncovered_pixels\",\"renderer\",\n"
             "\"gpu_mb\",\"peak_rss_mb\",\n"
             "\"settings\",\"frames\":[{\"index\",\n"
             "\"passes\":[...],\"ms\":{pass:ms},\"total_ms\",\"samples\",\n"
             "\"converged\",\"time_s\"},...]}"},
    {.name = "--no-vpl", .help = "no emergent light on the receivers (direct light only)"},
    {.name = "--vpl-visibility",
     .help = "shadow the VPLs' light by the objects (beyond seed 003; slower);\n"
             "the same as --set render.vpl_visibility=true"},
    {.name = "--set", .type = LR_ARG_STRING, .metavar = "key=value", .repeat = MAX_SETS,
     .help = "change a scene parameter before rendering (repeatable), names as\n"
             "in the scene file: light.intensity=0.01, render.K=8,\n"
             "camera.position=0,-400,200"},
    {.name = "--events", .type = LR_ARG_PATH,
     .help = "one change per line, FRAME PARAMETER VALUE (e.g. '4 light.intensity\n"
             "0.5'), applied before that frame; '#' starts a comment line"},
    {.name = "--fps", .type = LR_ARG_NUMBER, .metavar = "F", .flags = LR_ARG_ABOVE_MIN,
     .min = 0, .max = 1e6,
     .help = "the renderer's clock: frame i is composed at i / F seconds, which\n"
             "drives the lights' flicker (default 30; lights[0].flicker.amplitude=0\n"
             "makes a light steady)"},
    {.name = "--no-plan", .help = "keep the scene's render settings even when it has a quality budget"},
    {.name = "--plan-models",
     .help = "take the plan's model per object but keep the scene's render settings\n"
             "(K, N, N_vpl, maps, frames, lpv) and its VPL pass"},
    {.name = "--allow-dark",
     .help = "render even when no light lights anything the renderer draws (every\n"
             "light inside a closed object's material, or of zero power): the image\n"
             "is black; without it such a scene is refused (exit status 2)"},
    {.name = "--help-scene", .flags = LR_ARG_ALONE,
     .help = "print every scene field (type, range, default, what a change\n"
             "re-renders) as markdown, and exit"},
    {.name = "--table", .type = LR_ARG_PATH, .metavar = "CSV",
     .help = "the planner's measured table (default: see `lamprig help plan`)"},
    LR_CLI_QUIET_OPT,
    {.name = "--verbose",
     .help = "the plan's every line (as `lamprig plan --verbose`) instead of its sentence"},
    {0},
};

const lr_command lr_render_command = {
    .name = "render",
    .summary = "render a scene headless: PNG, linear PFM, per-pass statistics",
    .about = "Renders FILE (configs/scenes/*.json) with seed 003's passes (light G-buffer, scattered-\n"
             "radiosity maps, virtual point lights, composition) on a headless EGL context.",
    .opts = opts,
    .notes =
        "A scene with a \"quality\" block (max_error, frame_ms) is planned first (`lamprig plan`):\n"
        "the chosen settings replace its render settings and one line per object says the choice,\n"
        "predicted error and time; --set render.* is applied after the plan and wins.\n"
        "--plan-models takes the plan's model per object and keeps the scene's render settings\n"
        "(how `make run` renders the candle); --no-plan keeps the scene's models too.\n"
        "\n"
        "Files are written atomically. Output paths (--out, --hdr, --stats) are checked before\n"
        "anything renders: a directory or a missing folder is a bad argument.\n"
        "The loader's warnings (a mesh repaired, a light that lights nothing) go to stderr.\n"
        "A scene in which no light lights anything the renderer draws (every light inside a\n"
        "closed object's material, or of zero power) is refused before rendering: its image\n"
        "would be black; --allow-dark renders it anyway.\n"
        "\n"
        "Exit status: 0 done; 1 rendering or I/O failed; 2 bad arguments or a scene that\n"
        "lights nothing (one line on stderr).\n"
        "\n"
        "Example:\n"
        "  lamprig render --scene configs/scenes/candle.json --out candle.png --stats s.json",
    .run = run_render,
};

/* Every event of the script applied in order to a scratch copy of the scene (with the --set
 * assignments), before anything renders: a bad parameter or value is bad input at start,
 * named FILE:LINE, not a failure after the frames before it were drawn. */
static int check_events(const char *scene_path, const char *const *sets, int nsets,
                        const lr_render_events *ev, lr_err *e)
{
    if (!ev->count)
        return LR_OK;
    lr_scene *scratch = NULL;
    int rc = lr_scene_load(scene_path, NULL, &scratch, e);
    for (int i = 0; !rc && i < nsets; i++)
        rc = lr_scene_set_assignment(scratch, sets[i], NULL, e);
    for (int i = 0; !rc && i < ev->count; i++) {
        unsigned dirty = 0;
        if (lr_scene_set(scratch, ev->ev[i].key, ev->ev[i].value, &dirty, e)) {
            lr_err inner = *e;
            rc = lr_err_set(e, LR_EINVAL, "%s:%d: %s", ev->path, ev->ev[i].line, inner.msg);
        }
    }
    lr_scene_destroy(scratch);
    return rc;
}

typedef struct stats_log {
    lr_frame_stats *v;
    int n, cap;
} stats_log;

static int log_push(stats_log *l, const lr_frame_stats *s)
{
    if (l->n == l->cap) {
        int cap = l->cap ? 2 * l->cap : 64;
        lr_frame_stats *n = realloc(l->v, (size_t)cap * sizeof *n);
        if (!n)
            return -1;
        l->v = n;
        l->cap = cap;
    }
    l->v[l->n++] = *s;
    return 0;
}

/* Why the render drew fewer frames than asked or than render.frames (issue 33): the maps
 * converged early (deterministic ones after their first frame), and with --frames the
 * frames that could not change the image were not drawn. */
typedef struct stop_info {
    int requested;    /* --frames, 0: none */
    int skipped_from; /* --frames: the first frame (from 0) not drawn, -1: none */
    bool last_drawn;  /* with skipped_from: frame requested - 1 was drawn (a flickering light) */
    char why[1024]; /* "" when nothing stopped early */
} stop_info;

static void stop_explain(stop_info *s, const lr_scene *scene, const stats_log *log)
{
    s->why[0] = '\0';
    if (!log->n)
        return;
    const lr_frame_stats *last = &log->v[log->n - 1];
    int target = lr_scene_render(scene)->frames;
    bool early = last->converged && last->deterministic && last->samples < target;
    char conv[512];
    if (early) {
        /* The objects' models: each B solved or evaluated, none sampled (renderer.h). */
        char models[128] = "";
        size_t used = 0;
        for (int i = 0; i < lr_scene_object_count(scene) && used < sizeof models; i++) {
            const lr_scene_object *o = lr_scene_object_at(scene, i);
            int w = snprintf(models + used, sizeof models - used, "%s%s %s", i ? ", " : "",
                             o->name, lr_sss_model_name(o->sss_model));
            used += w > 0 ? (size_t)w : 0;
        }
        snprintf(conv, sizeof conv, "converged after %d frame%s: deterministic (%s: nothing "
                 "sampled per frame, so render.frames = %d would redraw the same maps)",
                 last->samples, last->samples == 1 ? "" : "s", models, target);
    } else {
        snprintf(conv, sizeof conv, "converged after %d frames (render.frames)", last->samples);
    }
    if (s->skipped_from < 0) {
        if (early)
            snprintf(s->why, sizeof s->why, "%s", conv);
        return;
    }
    /* Frames counted from 1 here, as --frames counts them. */
    if (s->last_drawn)
        snprintf(s->why, sizeof s->why, "%s; frames %d-%d of %d not drawn (they could not "
                 "change the image), frame %d composed at its clock (t = %g s)", conv,
                 s->skipped_from + 1, s->requested - 1, s->requested, s->requested,
                 last->time_s);
    else
        snprintf(s->why, sizeof s->why, "%s; frames %d-%d of %d not drawn (they could not "
                 "change the image)", conv, s->skipped_from + 1, s->requested, s->requested);
}

static int write_stats(const char *path, const lr_scene *scene, lr_renderer *r,
                       const stats_log *log, const stop_info *stop, lr_err *e)
{
    /* Object pixels of the final image that no radiosity map sees (PIPELINE.md, pass 3). */
    int uncovered = -1;
    if (log->n)
        lr_renderer_debug_uncovered(r, &uncovered, NULL);
    lr_atomic_file *af;
    int rc = lr_atomic_file_open(path, &af, e);
    if (rc)
        return rc;
    lr_jw *jw = lr_jw_create(lr_atomic_file_stream(af));
    if (!jw) {
        lr_atomic_file_abort(af);
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
    }
    int w, h;
    lr_renderer_size(r, &w, &h);
    const lr_render_settings *rs = lr_scene_render(scene);
    lr_jw_object(jw, NULL);
    lr_jw_string(jw, "scene", lr_scene_name(scene));
    lr_jw_int(jw, "width", w);
    lr_jw_int(jw, "height", h);
    lr_jw_int(jw, "uncovered_pixels", uncovered);
    lr_jw_string(jw, "renderer", lr_renderer_info(r));
    /* Memory: the renderer's textures and renderbuffers (lr_renderer_gpu_bytes) and the
     * process's peak resident set (getrusage: the CPU solvers, meshes, BVHs, llvmpipe). */
    struct rusage ru;
    lr_jw_number(jw, "gpu_mb", lr_renderer_gpu_bytes(r) / 1048576.0);
    if (getrusage(RUSAGE_SELF, &ru) == 0)
        lr_jw_number(jw, "peak_rss_mb", ru.ru_maxrss / 1024.0);
    lr_jw_object(jw, "settings");
    lr_jw_int(jw, "K", rs->K);
    lr_jw_int(jw, "N", rs->N);
    lr_jw_int(jw, "N_vpl", rs->N_vpl);
    lr_jw_int(jw, "map_size", rs->map_size);
    lr_jw_int(jw, "gbuffer_size", rs->gbuffer_size);
    lr_jw_int(jw, "vpl_map_size", rs->vpl_map_size);
    lr_jw_int(jw, "frames", rs->frames);
    lr_jw_object_end(jw);
    /* Per object the model it rendered with (the scene's, or the plan's). */
    lr_jw_object(jw, "models");
    for (int i = 0; i < lr_scene_object_count(scene); i++) {
        const lr_scene_object *o = lr_scene_object_at(scene, i);
        lr_jw_string(jw, o->name, lr_sss_model_name(o->sss_model));
    }
    lr_jw_object_end(jw);
    if (stop->requested)
        lr_jw_int(jw, "frames_requested", stop->requested);
    else
        lr_jw_null(jw, "frames_requested");
    lr_jw_int(jw, "frames_drawn", log->n);
    if (stop->why[0])
        lr_jw_string(jw, "stopped_early", stop->why);
    else
        lr_jw_null(jw, "stopped_early");
    lr_jw_array(jw, "frames");
    for (int i = 0; i < log->n; i++) {
        const lr_frame_stats *s = &log->v[i];
        lr_jw_object(jw, NULL);
        lr_jw_int(jw, "index", s->index);
        lr_jw_array(jw, "passes");
        for (int p = 0; p < LR_PASS_COUNT; p++)
            if (s->passes & (1u << p))
                lr_jw_string(jw, NULL, lr_pass_name(p));
        lr_jw_array_end(jw);
        lr_jw_object(jw, "ms");
        for (int p = 0; p < LR_PASS_COUNT; p++)
            if (s->passes & (1u << p))
                lr_jw_number_or_null(jw, lr_pass_name(p), s->ms[p]);
        lr_jw_object_end(jw);
        lr_jw_number_or_null(jw, "total_ms", s->total_ms);
        lr_jw_int(jw, "samples", s->samples);
        lr_jw_bool(jw, "converged", s->converged);
        lr_jw_bool(jw, "deterministic", s->deterministic);
        lr_jw_number_or_null(jw, "time_s", s->time_s);
        lr_jw_object_end(jw);
    }
    lr_jw_array_end(jw);
    lr_jw_object_end(jw);
    if ((rc = lr_jw_finish(jw, e))) {
        lr_atomic_file_abort(af);
        return rc;
    }
    return lr_atomic_file_commit(af, e);
}

/* The planner (firmware/plan_scene.h) for a scene with a quality budget: applies its settings
 * (with --plan-models its models alone) and prints its lines. A missing or unusable table
 * is not fatal: the scene's own settings render, and a "plan: skipped: WHY" line says so. */
static int plan(const char *path, lr_scene *scene, const char *table, bool models_only,
                bool verbose, bool *no_vpl, bool *planned)
{
    lr_plan_scene_result *res = calloc(1, sizeof *res);
    if (!res)
        return LR_EXIT_FAIL;
    lr_err e = {0};
    if (lr_plan_scene(scene, table, models_only, res, &e)) {
        /* Informational like the plan itself (stdout): the render goes on. */
        printf("plan: skipped: %s; rendering with the scene's settings\n", e.msg);
    } else if (res->planned) {
        char *text = lr_plan_scene_text(res, verbose);
        if (text)
            fputs(text, stdout);
        free(text);
        *planned = true;
        if (models_only) { /* the scene's settings, which the models-only apply left */
            const lr_render_settings *own = lr_scene_render(scene);
            printf("plan: --plan-models: the plan's models, the scene's render settings (K=%d "
                   "N=%d N_vpl=%d map_size=%d gbuffer_size=%d frames=%d)\n",
                   own->K, own->N, own->N_vpl, own->map_size, own->gbuffer_size, own->frames);
        } else if (!res->vpl) {
            *no_vpl = true;
        }
    }
    free(res);
    return LR_EXIT_OK;
}

/* Builds an lr_image (rows top to bottom) from the renderer's HDR readback (bottom up). */
/* "NAME: MODEL, ..." of the scene's objects, for a message. */
static void object_models(const lr_scene *s, char *buf, size_t cap)
{
    size_t len = 0;
    buf[0] = '\0';
    for (int i = 0; i < lr_scene_object_count(s) && len < cap; i++) {
        const lr_scene_object *o = lr_scene_object_at(s, i);
        int k = snprintf(buf + len, cap - len, "%s%s: %s", i ? ", " : "", o->name,
                         lr_sss_model_name(o->sss_model));
        if (k < 0)
            break;
        len += (size_t)k;
    }
}

static int read_image(lr_renderer *r, lr_image *img, lr_err *e)
{
    int w, h;
    lr_renderer_size(r, &w, &h);
    int rc = lr_image_alloc(img, w, h, e);
    if (rc)
        return rc;
    float *rgb = malloc((size_t)w * h * 3 * sizeof *rgb);
    if (!rgb) {
        lr_image_free(img);
        return lr_err_set(e, LR_ENOMEM, "out of memory");
    }
    if ((rc = lr_renderer_read_hdr(r, rgb, e))) {
        free(rgb);
        lr_image_free(img);
        return rc;
    }
    for (int y = 0; y < h; y++)
        memcpy(img->rgb + (size_t)y * w * 3, rgb + (size_t)(h - 1 - y) * w * 3, (size_t)w * 3 * sizeof *rgb);
    free(rgb);
    return LR_OK;
}

static int run_render(const lr_cli *c)
{
    const lr_args *a = &c->args;
    if (lr_args_has(a, "--help-scene")) { /* the scene field reference, from its tables */
        lr_scene_fields_markdown(stdout);
        return LR_EXIT_OK;
    }
    const char *sets[MAX_SETS];
    int nsets = lr_args_values(a, "--set", sets, MAX_SETS);
    int status, frames = 0, width = 640, height = 480;
    double fps = 30.0;
    lr_err e = {0};
    if ((status = lr_cli_check(c, lr_args_int(a, "--frames", &frames, &e) ||
                                      lr_args_int(a, "--width", &width, &e) ||
                                      lr_args_int(a, "--height", &height, &e) ||
                                      lr_args_double(a, "--fps", &fps, &e),
                               &e)))
        return status;
    const char *scene_path = lr_args_get(a, "--scene");
    const char *out = lr_args_get(a, "--out"), *hdr = lr_args_get(a, "--hdr");
    const char *stats_path = lr_args_get(a, "--stats"), *events_path = lr_args_get(a, "--events");
    bool no_vpl = lr_args_has(a, "--no-vpl");
    bool vpl_vis = lr_args_has(a, "--vpl-visibility");
    bool no_plan = lr_args_has(a, "--no-plan"), plan_models = lr_args_has(a, "--plan-models");
    const char *table = lr_args_get(a, "--table");
    for (int i = 0; i < nsets; i++)
        if (!strchr(sets[i], '='))
            return lr_cli_usage(c->path, "--set %s: expected key=value", sets[i]);

    lr_scene *scene = NULL;
    lr_gl *gl = NULL;
    lr_renderer *r = NULL;
    lr_progress_meter *pm = NULL;
    lr_render_events ev = {0};
    stats_log log = {0};
    stop_info stop = {.skipped_from = -1};
    lr_image img = {0};
    lr_warn_sink warn = lr_cli_warn_sink(c->path);
    if (lr_scene_load(scene_path, &warn, &scene, &e)) {
        /* A scene that cannot be read or is invalid is bad input. */
        status = e.code == LR_EIO ? lr_cli_fail(c->path, "%s", e.msg)
                                  : lr_cli_usage(c->path, "%s", e.msg);
        goto done;
    }
    /* --set is checked before the plan (a bad one is a one-line usage error) and applied again
     * after it, so that an explicit render.* setting wins over the plan. */
    for (int i = 0; i < nsets; i++)
        if (lr_scene_set_assignment(scene, sets[i], NULL, &e)) {
            status = lr_cli_usage(c->path, "--set %s: %s", sets[i], e.msg);
            goto done;
        }
    if (events_path && (lr_render_events_load(events_path, &ev, &e) ||
                        check_events(scene_path, sets, nsets, &ev, &e))) {
        status = e.code == LR_EIO ? lr_cli_fail(c->path, "%s", e.msg)
                                  : lr_cli_usage(c->path, "%s", e.msg);
        goto done;
    }
    bool planned = false;
    if (no_plan && plan_models) {
        status = lr_cli_usage(c->path, "--no-plan and --plan-models: choose one");
        goto done;
    }
    if (!no_plan && (status = plan(c->path, scene, table, plan_models, lr_args_has(a, "--verbose"),
                                      &no_vpl, &planned)))
        goto done;
    for (int i = 0; planned && i < nsets; i++) {
        if (lr_scene_set_assignment(scene, sets[i], NULL, &e)) {
            status = lr_cli_usage(c->path, "--set %s: %s", sets[i], e.msg);
            goto done;
        }
        if (!strncmp(sets[i], "render.", 7))
            printf("plan: --set %s overrides the plan\n", sets[i]);
    }
    /* A model forced outside its validity limit for the material (the file's or --set's
     * objects[i].model, which the plan does not replace) is bad input, refused before the
     * renderer spends its solver's iterations on it. */
    if (lr_plan_check_models(scene, &e)) {
        status = lr_cli_usage(c->path, "%s", e.msg);
        goto done;
    }
    /* A scene no light of which lights anything renders all zeros, whatever the model: say so
     * before any pass runs (the loader has named each such light already), and refuse it
     * unless asked (render/scene/dark.c; issue 33). Checked after --set and the plan. */
    {
        char why[LR_ERR_MSG_MAX];
        if (lr_scene_dark(scene, why, sizeof why)) {
            if (!lr_args_has(a, "--allow-dark")) {
                status = lr_cli_usage(c->path, "%s: no light lights anything the renderer draws "
                                      "(%s), so the image would be black; --allow-dark "
                                      "renders it anyway", lr_scene_name(scene), why);
                goto done;
            }
            lr_warn(&warn, "%s: no light lights anything the renderer draws (%s): the image is "
                    "black (--allow-dark)", lr_scene_name(scene), why);
        }
    }
    if (lr_gl_create(NULL, &gl, &e) ||
        lr_renderer_create(&(lr_renderer_desc){.gl = gl, .scene = scene, .width = width,
                                               .height = height, .no_vpl = no_vpl,
                                               .vpl_visibility = vpl_vis},
                           &r, &e)) {
        status = lr_cli_fail(c->path, "%s", e.msg);
        goto done;
    }
    int next_ev = 0;
    /* without --frames: render.frames to converge (events may restart it: then more) */
    int nframes = frames ? frames : lr_scene_render(scene)->frames;
    pm = lr_cli_progress(c);
    const lr_progress *pg = lr_progress_meter_sink(pm);
    lr_progress_report(pg, "frame", 0, nframes);
    for (int i = 0;; i++) {
        if (frames ? i >= frames : (!lr_renderer_needs_frame(r) && next_ev >= ev.count))
            break;
        if (!frames && i >= 1000000)
            break;
        /* --frames N: once the maps converged and every event is applied, frames i .. N - 2
         * cannot change the image (their clock only moves the flicker, which the last frame
         * sets): jump to frame N - 1, composed at its clock, which draws the blend alone for
         * a flickering light and nothing for a steady one (issue 33: deterministic models
         * converge in one frame). */
        if (frames && i > 0 && i < frames - 1 && !lr_renderer_needs_frame(r) &&
            next_ev >= ev.count) {
            stop.skipped_from = i;
            i = frames - 1;
            lr_renderer_set_time(r, i / fps);
            if (!lr_renderer_needs_frame(r))
                break;
            stop.last_drawn = true;
        }
        while (next_ev < ev.count && ev.ev[next_ev].frame <= i) {
            const lr_render_event *x = &ev.ev[next_ev++];
            unsigned dirty = 0;
            if (lr_scene_set(scene, x->key, x->value, &dirty, &e)) {
                status = lr_cli_usage(c->path, "%s:%d: %s", ev.path, x->line, e.msg);
                goto done;
            }
            lr_renderer_invalidate(r, dirty);
        }
        /* The clock after the stop test: flicker alone never keeps the loop going (without
         * --frames it ends once the maps converged and the events are applied). */
        lr_renderer_set_time(r, i / fps);
        lr_frame_stats st;
        if (lr_renderer_frame(r, &st, &e)) {
            status = lr_cli_fail(c->path, "%s", e.msg);
            goto done;
        }
        if (log_push(&log, &st)) {
            status = LR_EXIT_FAIL;
            goto done;
        }
        /* past render.frames (an event restarted the accumulation): the count alone */
        lr_progress_report(pg, "frame", i + 1, i + 1 <= nframes ? nframes : 0);
    }
    lr_progress_meter_destroy(pm);
    pm = NULL;
    for (; next_ev < ev.count; next_ev++)
        fprintf(stderr, "lamprig render: %s:%d: event for frame %d not applied (--frames %d)\n",
                ev.path, ev.ev[next_ev].line, ev.ev[next_ev].frame, frames);
    if (out || hdr) {
        if (read_image(r, &img, &e)) {
            status = lr_cli_fail(c->path, "%s", e.msg);
            goto done;
        }
        /* A NaN or Inf is a numerical failure of a model (its material outside what its
         * numerics hold), never an image: refused, not written as black or white pixels. */
        size_t bad = lr_image_count_nonfinite(&img);
        if (bad) {
            char models[256];
            object_models(scene, models, sizeof models);
            status = lr_cli_fail(c->path, "%zu of %d pixels are not finite (NaN or Inf), "
                                 "objects' models %s: nothing written", bad,
                                 img.width * img.height, models);
            goto done;
        }
        lr_tonemap tm;
        lr_renderer_tonemap(r, &tm);
        if (out && lr_image_write_png(out, &img, &tm, &e)) {
            status = lr_cli_fail(c->path, "%s", e.msg);
            goto done;
        }
        if (hdr && lr_image_write_pfm(hdr, &img, &e)) {
            status = lr_cli_fail(c->path, "%s", e.msg);
            goto done;
        }
    }
    stop.requested = frames;
    stop_explain(&stop, scene, &log);
    if (stop.why[0])
        fprintf(stderr, "lamprig render: %s\n", stop.why);
    if (stats_path && write_stats(stats_path, scene, r, &log, &stop, &e)) {
        status = lr_cli_fail(c->path, "%s", e.msg);
        goto done;
    }
    {
        double total = 0.0;
        for (int i = 0; i < log.n; i++)
            total += isfinite(log.v[i].total_ms) ? log.v[i].total_ms : 0.0;
        printf("lamprig render: %s, %d x %d, %d frames (%d samples), %.0f ms\n", lr_scene_name(scene),
               width, height, log.n, log.n ? log.v[log.n - 1].samples : 0, total);
        if (out)
            printf("wrote %s\n", out);
        if (hdr)
            printf("wrote %s\n", hdr);
        if (stats_path)
            printf("wrote %s\n", stats_path);
    }
done:
    lr_progress_meter_destroy(pm);
    lr_image_free(&img);
    free(log.v);
    lr_render_events_free(&ev);
    lr_renderer_destroy(r);
    lr_gl_destroy(gl);
    lr_scene_destroy(scene);
    return status;
}
