/* Section "models": what each per-object model (objects[i].model, issue 14) costs at the
 * moments a designer waits for, on the shipped scenes candle, lampshade and votive, for every
 * model the scene's objects can take (lr_scene_object_model_unmet):
 *
 *   cold        lr_renderer_create + the first frame (G-buffers, the model's setup: the grid's
 *               solve, the patches' transfer, the SH projection; radiosity, VPLs, compose);
 *   light move  a frame after lights[0].position moved by LIGHT_MOVE_MM (alternately there and
 *               back): LR_DIRTY_LIGHT_GEOMETRY;
 *   material    a frame after objects[*].material.scale grew by MATERIAL_STEP (a sigma edit:
 *               sigma_a and sigma_s' scale together; each run a material not seen before):
 *               LR_DIRTY_MATERIAL;
 *   dimmer      a frame after light.intensity was halved or restored: LR_DIRTY_INTENSITY, the
 *               blend pass alone for every model (the contract of issue 14).
 *
 * Each is the median of RUNS runs, wall time from glFinish to glFinish (what a caller waits:
 * the CPU work of the grid and the patches included). One settings block for every model
 * (render.K etc. below) with render.frames = 1, so that after a change exactly one frame of
 * each due pass runs. The on-disk caches point at an empty folder of the section (cleared
 * before each cold start), so cold starts and material edits pay their rebuilds. The planner
 * reads material_ms (configs/bench/models.csv, committed from this file) against a scene's
 * quality.change_ms. Progress on stderr; build/bench/models.csv (atomic). LRB_MODELS_SCENES
 * (comma-separated) runs a subset. */
#include "tools/bench/bench.h"

#include <GLES3/gl31.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <ftw.h>
#include <sys/stat.h>

#include "render/base/atomic_file.h"
#include "render/base/median.h"
#include "render/base/paths.h"
#include "render/gl/gl.h"
#include "render/plan/limits.h"
#include "render/renderer.h"
#include "render/scene/scene.h"

enum { RUNS = 3, W = 320, H = 240, MAX_ROWS = 32 };
#define LIGHT_MOVE_MM 1.5
#define MATERIAL_STEP 1.05

static const char *const scene_names[] = {"candle", "lampshade", "votive"};
static const char *const settings[][2] = {{"render.K", "8"},        {"render.N", "4"},
                                          {"render.N_vpl", "64"},   {"render.map_size", "64"},
                                          {"render.gbuffer_size", "128"},
                                          {"render.frames", "1"}};

typedef struct row {
    const char *scene;
    const char *model;
    double cold_ms, light_ms, material_ms, dimmer_ms;
    unsigned dimmer_passes;
} row;

static lr_scene *load(const char *name, const char *model)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/scenes/%s.json", lr_configs_dir(), name);
    lr_scene *s = NULL;
    lr_err e = {0};
    if (lr_scene_load(path, &(const lr_warn_sink){lr_warn_stderr, "lamprig-bench"}, &s, &e)) {
        fprintf(stderr, "bench models: %s\n", e.msg);
        return NULL;
    }
    for (size_t k = 0; k < sizeof settings / sizeof *settings; k++)
        if (lrb_scene_set("bench models", s, settings[k][0], settings[k][1], NULL))
            goto fail;
    for (int i = 0; i < lr_scene_object_count(s); i++) {
        char key[32];
        snprintf(key, sizeof key, "objects[%d].model", i);
        if (lrb_scene_set("bench models", s, key, model, NULL))
            goto fail;
    }
    return s;
fail:
    lr_scene_destroy(s);
    return NULL;
}

/* One frame, wall time glFinish to glFinish. NAN on error. */
static double timed_frame(lr_renderer *r, unsigned *passes)
{
    lr_err e = {0};
    lr_frame_stats st;
    glFinish();
    double t0 = lrb_now();
    if (lr_renderer_frame(r, &st, &e)) {
        fprintf(stderr, "bench models: %s\n", e.msg);
        return NAN;
    }
    glFinish();
    if (passes)
        *passes = st.passes;
    return (lrb_now() - t0) * 1e3;
}

/* Whether every object of the scene can take model m: its geometry
 * (lr_scene_object_model_unmet) and the model's validity limits for its material
 * (render/plan/limits.h; the shade's porcelain is 6 diffusion lengths per grid cell, where the
 * grid's solve does not converge). *why: the first reason it cannot. */
static bool takes(const char *scene, enum lr_sss_model m, char *why, size_t cap)
{
    lr_scene *s = load(scene, "directional_dipole");
    if (!s) {
        snprintf(why, cap, "the scene does not load");
        return false;
    }
    bool ok = true;
    for (int i = 0; i < lr_scene_object_count(s) && ok; i++) {
        const lr_scene_object *o = lr_scene_object_at(s, i);
        const char *w = lr_scene_object_model_unmet(o, m);
        if (!w)
            w = lr_plan_model_limit(o, m, why, cap);
        if (w) {
            if (w != why)
                snprintf(why, cap, "%s", w);
            ok = false;
        }
    }
    lr_scene_destroy(s);
    return ok;
}

static int rm_entry(const char *path, const struct stat *st, int flag, struct FTW *ftw)
{
    (void)st;
    (void)flag;
    (void)ftw;
    return remove(path);
}

/* Points the on-disk caches (translucent radiosity's F and S, render/transrad/cache.c) at a
 * new empty folder under base: every cold start and material edit below pays its own
 * rebuild, as a designer's first start and first visit of a material do, instead of reading
 * what an earlier run of this section (or the user's renders) left in ~/.cache. */
static void fresh_cache(const char *base, const char *what)
{
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/%s", base, what);
    nftw(dir, rm_entry, 16, FTW_DEPTH | FTW_PHYS);
    setenv("XDG_CACHE_HOME", dir, 1);
}

static int time_model(lr_gl *gl, const char *base, const char *scene, const char *model,
                      row *out)
{
    *out = (row){.scene = scene, .model = model};
    double cold[RUNS], light[RUNS], mat[RUNS], dim[RUNS];
    lr_scene *s = NULL;
    lr_renderer *r = NULL;
    lr_err e = {0};
    /* cold: a new renderer each run, on an empty cache */
    for (int k = 0; k < RUNS; k++) {
        fresh_cache(base, "cold");
        lr_renderer_destroy(r);
        r = NULL;
        lr_scene_destroy(s);
        if (!(s = load(scene, model)))
            return 1;
        glFinish();
        double t0 = lrb_now();
        if (lr_renderer_create(&(lr_renderer_desc){.gl = gl, .scene = s, .width = W, .height = H},
                               &r, &e)) {
            fprintf(stderr, "bench models: %s %s: %s\n", scene, model, e.msg);
            lr_scene_destroy(s);
            return 1;
        }
        double f = timed_frame(r, NULL);
        cold[k] = isfinite(f) ? (lrb_now() - t0) * 1e3 : NAN;
    }
    lr_vec3 p0 = lr_scene_light_at(s, 0)->position;
    double I0 = lr_scene_light_at(s, 0)->intensity;
    int no = lr_scene_object_count(s);
    for (int k = 0; k < RUNS; k++) {
        char v[128];
        unsigned dirty = 0;
        snprintf(v, sizeof v, "%.17g,%.17g,%.17g", p0.x + (k % 2 ? 0.0 : LIGHT_MOVE_MM), p0.y,
                 p0.z);
        if (lrb_scene_set("bench models", s, "lights[0].position", v, &dirty))
            goto fail;
        lr_renderer_invalidate(r, dirty);
        light[k] = timed_frame(r, NULL);

        dirty = 0;
        for (int i = 0; i < no; i++) {
            char key[48];
            snprintf(key, sizeof key, "objects[%d].material.scale", i);
            char cur[64];
            if (lr_scene_get(s, key, cur, sizeof cur, &e)) {
                fprintf(stderr, "bench models: %s\n", e.msg);
                goto fail;
            }
            /* A material not seen before in this section: each edit rebuilds (cumulative
             * steps, never back to an earlier value that a cache could hold). */
            snprintf(v, sizeof v, "%.17g", strtod(cur, NULL) * MATERIAL_STEP);
            if (lrb_scene_set("bench models", s, key, v, &dirty))
                goto fail;
        }
        lr_renderer_invalidate(r, dirty);
        mat[k] = timed_frame(r, NULL);

        dirty = 0;
        snprintf(v, sizeof v, "%.17g", k % 2 ? I0 : 0.5 * I0);
        if (lrb_scene_set("bench models", s, "light.intensity", v, &dirty))
            goto fail;
        lr_renderer_invalidate(r, dirty);
        dim[k] = timed_frame(r, &out->dimmer_passes);
    }
    out->cold_ms = lr_median_finite(cold, RUNS);
    out->light_ms = lr_median_finite(light, RUNS);
    out->material_ms = lr_median_finite(mat, RUNS);
    out->dimmer_ms = lr_median_finite(dim, RUNS);
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
    if (!isfinite(out->cold_ms) || !isfinite(out->light_ms) || !isfinite(out->material_ms)) {
        fprintf(stderr, "bench models: %s %s: frames failed (above)\n", scene, model);
        return 1;
    }
    fprintf(stderr, "bench models: %s %s: cold %.0f ms, light move %.0f ms, material %.0f ms, "
                    "dimmer %.1f ms\n", scene, model, out->cold_ms, out->light_ms,
            out->material_ms, out->dimmer_ms);
    return 0;
fail:
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
    return 1;
}

static int write_csv(const row *t, int n)
{
    lr_err e = {0};
    if ((mkdir("build", 0777) && errno != EEXIST) ||
        (mkdir("build/bench", 0777) && errno != EEXIST)) {
        fprintf(stderr, "bench models: cannot create build/bench: %s\n", strerror(errno));
        return 1;
    }
    lr_atomic_file *af;
    if (lr_atomic_file_open("build/bench/models.csv", &af, &e))
        goto fail;
    FILE *f = lr_atomic_file_stream(af);
    fprintf(f, "scene,model,cold_ms,light_move_ms,material_ms,dimmer_ms,dimmer_passes\n");
    for (int i = 0; i < n; i++)
        fprintf(f, "%s,%s,%.3f,%.3f,%.3f,%.3f,0x%x\n", t[i].scene, t[i].model, t[i].cold_ms,
                t[i].light_ms, t[i].material_ms, t[i].dimmer_ms, t[i].dimmer_passes);
    if (lr_atomic_file_commit(af, &e))
        goto fail;
    return 0;
fail:
    fprintf(stderr, "bench models: %s\n", e.msg);
    return 1;
}

static int run(FILE *out)
{
    double t_start = lrb_now();
    lr_gl *gl = NULL;
    lr_err e = {0};
    if (lr_gl_create(NULL, &gl, &e)) {
        fprintf(stderr, "bench models: no GL context: %s\n", e.msg);
        return 1;
    }
    row t[MAX_ROWS];
    int n = 0, status = 0;
    char skipped[2048] = "";
    const char *tmp = getenv("TMPDIR");
    char base[512];
    snprintf(base, sizeof base, "%s/lamprig-models-cache.XXXXXX", tmp && *tmp ? tmp : "/tmp");
    char *old_cache = getenv("XDG_CACHE_HOME") ? strdup(getenv("XDG_CACHE_HOME")) : NULL;
    if (!mkdtemp(base)) {
        fprintf(stderr, "bench models: cannot create a cache folder %s: %s\n", base,
                strerror(errno));
        lr_gl_destroy(gl);
        free(old_cache);
        return 1;
    }
    for (size_t si = 0; si < sizeof scene_names / sizeof *scene_names; si++) {
        if (!lrb_wanted(getenv("LRB_MODELS_SCENES"), scene_names[si]))
            continue;
        for (int m = 0; m < LR_SSS_MODEL_COUNT && n < MAX_ROWS; m++) {
            const char *name = lr_sss_model_name((enum lr_sss_model)m);
            char why[256];
            if (!takes(scene_names[si], (enum lr_sss_model)m, why, sizeof why)) {
                size_t l = strlen(skipped);
                snprintf(skipped + l, sizeof skipped - l, "%s%s on %s (%s)", l ? "; " : "",
                         name, scene_names[si], why);
                continue;
            }
            fprintf(stderr, "bench models: %s %s ...\n", scene_names[si], name);
            if (time_model(gl, base, scene_names[si], name, &t[n]) == 0)
                n++;
            else
                status = 1;
        }
    }
    lr_gl_destroy(gl);
    nftw(base, rm_entry, 16, FTW_DEPTH | FTW_PHYS);
    if (old_cache)
        setenv("XDG_CACHE_HOME", old_cache, 1);
    else
        unsetenv("XDG_CACHE_HOME");
    free(old_cache);

    fprintf(out, "## Models (`lamprig-bench models`)\n\n");
    fprintf(out, "Per model and scene, wall time in ms (glFinish to glFinish, median of %d): "
                 "cold = renderer create + first frame; light move = a frame after the light "
                 "moved %.1f mm; material = a frame after material.scale changed by %.0f %% "
                 "(a sigma edit); dimmer = a frame after the light's intensity changed "
                 "(passes it ran in the last column: blend alone is 0x%x). %dx%d, K 8, N 4, "
                 "N_vpl 64, 64² maps, 128² G-buffer, render.frames 1.\n\n",
            RUNS, LIGHT_MOVE_MM, 100.0 * (MATERIAL_STEP - 1.0), LR_PASS_BLEND, W, H);
    fprintf(out, "| scene | model | cold | light move | material | dimmer | dimmer passes |\n");
    fprintf(out, "|---|---|---|---|---|---|---|\n");
    for (int i = 0; i < n; i++)
        fprintf(out, "| %s | %s | %.0f | %.0f | %.0f | %.1f | 0x%x |\n", t[i].scene, t[i].model,
                t[i].cold_ms, t[i].light_ms, t[i].material_ms, t[i].dimmer_ms,
                t[i].dimmer_passes);
    if (skipped[0])
        fprintf(out, "\nNot run: %s.\n", skipped);
    if (write_csv(t, n))
        status = 1;
    fprintf(out, "\nWrote build/bench/models.csv. Section time %.0f s.\n\n", lrb_now() - t_start);
    return status;
}

const lrb_section lrb_models_section = {
    .name = "models",
    .summary = "per model: cold start, frame after a light move, a material change, a dimmer",
    .run = run,
};
