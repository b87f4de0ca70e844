/* lamprig-bench camera — a camera move per composition path, interleaved (issue 11: a
 * camera-only change >= 10x cheaper than the composition of the time the issue was filed).
 *
 * Per scene at 640x480 one renderer per composition path in the same process and GL context:
 * "gather" (render.surface_cache and render.surface_cache_moves false: seed 003's Algorithm 1
 * per object pixel at every move) and "cache" (the shipped default, render.surface_cache_moves:
 * a move composes B from the surface cache, render/passes/PIPELINE.md "Surface cache"; its
 * first move, which draws the cache, is the throw-away one below). Each repetition
 * moves every renderer's camera by 1 mm (alternately there and back) and renders one frame
 * (compose + blend), the paths one after the other, so the machine's load changes alike for
 * both. Wall time glFinish to glFinish and process CPU time (CLOCK_PROCESS_CPUTIME_ID, every
 * thread, llvmpipe's included: waiting for a core is not counted). Reported: median (min) of
 * each and gather / cache of the medians.
 *
 * The scenes' own settings except render.frames = 1 and render.N = 1: neither composition
 * path's cost depends on the values (no data-dependent loop), so a converged image is not
 * needed. LRB_CAMERA_REPS (default 15, 1..1000) repetitions; LRB_CAMERA_SCENES
 * ("candle,lampshade"-style list; default both); LRB_CAMERA_SIZE ("WxH", default 640x480). */
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <GLES3/gl31.h>

#include "render/base/median.h"
#include "render/base/paths.h"
#include "render/gl/gl.h"
#include "render/renderer.h"
#include "render/renderer_debug.h"
#include "render/scene/scene.h"
#include "tools/bench/bench.h"

enum { REPS_DEFAULT = 15, REPS_MAX = 1000, N_PATHS = 2 };

static const char *const scene_names[] = {"candle", "lampshade"};
static const char *const path_names[N_PATHS] = {"gather", "cache"};

/* One renderer per path on its own copy of the scene. */
typedef struct path_state {
    lr_scene *s;
    lr_renderer *r;
    lr_vec3 c0;
} path_state;

static int path_open(lr_gl *gl, const char *name, int p, int w, int h, path_state *ps)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/scenes/%s.json", lr_configs_dir(), name);
    lr_err e = {0};
    if (lr_scene_load(path, &(const lr_warn_sink){lr_warn_stderr, "lamprig-bench"}, &ps->s, &e)) {
        fprintf(stderr, "bench camera: %s\n", e.msg);
        return 1;
    }
    const char *who = "bench camera";
    if (lrb_scene_set(who, ps->s, "render.frames", "1", NULL) ||
        lrb_scene_set(who, ps->s, "render.N", "1", NULL) ||
        lrb_scene_set(who, ps->s, "render.surface_cache", "false", NULL) ||
        lrb_scene_set(who, ps->s, "render.surface_cache_moves", p == 1 ? "true" : "false",
                      NULL))
        return 1;
    if (lr_renderer_create(&(lr_renderer_desc){.gl = gl, .scene = ps->s, .width = w, .height = h},
                           &ps->r, &e) ||
        lr_renderer_frame(ps->r, NULL, &e)) {
        fprintf(stderr, "bench camera: %s %s: %s\n", name, path_names[p], e.msg);
        return 1;
    }
    ps->c0 = lr_scene_camera(ps->s)->position;
    return 0;
}

static void path_close(path_state *ps)
{
    lr_renderer_destroy(ps->r);
    lr_scene_destroy(ps->s);
}

/* One camera move of 1 mm (there at odd i, back at even i) and its frame. */
static int move(path_state *ps, int i, bool first, double *wall, double *cpu)
{
    char val[96];
    snprintf(val, sizeof val, "%.17g,%.17g,%.17g", ps->c0.x + (i % 2 ? 1.0 : 0.0), ps->c0.y,
             ps->c0.z);
    unsigned dirty = 0;
    if (lrb_scene_set("bench camera", ps->s, "camera.position", val, &dirty))
        return 1;
    lr_renderer_invalidate(ps->r, dirty);
    lr_err e = {0};
    lr_frame_stats st;
    glFinish();
    double t0 = lrb_now(), c0 = lrb_process_cpu_ms();
    if (lr_renderer_frame(ps->r, &st, &e)) {
        fprintf(stderr, "bench camera: %s\n", e.msg);
        return 1;
    }
    glFinish();
    *wall = (lrb_now() - t0) * 1e3;
    *cpu = lrb_process_cpu_ms() - c0;
    /* The first move may draw the surface cache (LR_PASS_SURFACE); the others may not. */
    if (!first && st.passes != (LR_PASS_COMPOSE | LR_PASS_BLEND)) {
        fprintf(stderr, "bench camera: a camera move ran passes 0x%x, not compose + blend\n",
                st.passes);
        return 1;
    }
    return 0;
}

static int row(lr_gl *gl, const char *name, int w, int h, int reps, FILE *out)
{
    path_state ps[N_PATHS];
    memset(ps, 0, sizeof ps);
    double *t = calloc((size_t)reps * 2 * N_PATHS, sizeof *t);
    int rc = 1;
    if (!t) {
        fprintf(stderr, "bench camera: out of memory\n");
        return 1;
    }
    for (int p = 0; p < N_PATHS; p++)
        if (path_open(gl, name, p, w, h, &ps[p]))
            goto done;
    /* One throw-away move each: llvmpipe compiles a program's variant at its first draw. */
    double dw, dc;
    for (int p = 0; p < N_PATHS; p++)
        if (move(&ps[p], 1, true, &dw, &dc))
            goto done;
    for (int i = 0; i < reps; i++)
        for (int p = 0; p < N_PATHS; p++)
            if (move(&ps[p], i, false, &t[(2 * p) * reps + i], &t[(2 * p + 1) * reps + i]))
                goto done;
    double med[N_PATHS][2];
    fprintf(out, "| %s | %d×%d | %d", name, w, h, reps);
    for (int p = 0; p < N_PATHS; p++) {
        med[p][0] = lr_median_finite(&t[(2 * p) * reps], reps);
        med[p][1] = lr_median_finite(&t[(2 * p + 1) * reps], reps);
        fprintf(out, " | %.1f (%.1f) | %.1f (%.1f)", med[p][0], lrb_min(&t[(2 * p) * reps], reps),
                med[p][1], lrb_min(&t[(2 * p + 1) * reps], reps));
    }
    fprintf(out, " | %.2f | %.2f |\n", med[0][0] / med[1][0], med[0][1] / med[1][1]);
    fflush(out);
    rc = 0;
done:
    for (int p = 0; p < N_PATHS; p++)
        path_close(&ps[p]);
    free(t);
    return rc;
}

static int run(FILE *out)
{
    const char *rs = getenv("LRB_CAMERA_REPS");
    int reps = rs ? atoi(rs) : REPS_DEFAULT;
    if (reps < 1 || reps > REPS_MAX) {
        fprintf(stderr, "bench camera: LRB_CAMERA_REPS=%s: must be 1..%d\n", rs, REPS_MAX);
        return 2;
    }
    int w = 640, h = 480;
    const char *sz = getenv("LRB_CAMERA_SIZE");
    if (sz && (sscanf(sz, "%dx%d", &w, &h) != 2 || w < 1 || h < 1 || w > 8192 || h > 8192)) {
        fprintf(stderr, "bench camera: LRB_CAMERA_SIZE=%s: want WxH\n", sz);
        return 2;
    }
    const char *scenes = getenv("LRB_CAMERA_SCENES");
    lr_gl *gl = NULL;
    lr_err e = {0};
    if (lr_gl_create(NULL, &gl, &e)) {
        fprintf(stderr, "bench camera: no GL context: %s\n", e.msg);
        return 1;
    }
    fprintf(out, "| scene | size | moves | gather wall ms median (min) | gather CPU ms | "
                 "cache wall "
                 "ms | cache CPU ms | gather / cache, wall | gather / cache, CPU |\n"
                 "|---|---|---|---|---|---|---|---|---|\n");
    int rc = 0;
    for (size_t k = 0; k < sizeof scene_names / sizeof scene_names[0] && !rc; k++)
        if (lrb_wanted(scenes, scene_names[k]))
            rc = row(gl, scene_names[k], w, h, reps, out);
    lr_gl_destroy(gl);
    return rc;
}

const lrb_section lrb_camera_section = {
    .name = "camera",
    .summary = "a camera move per composition path, interleaved (issue 11)",
    .run = run,
};
