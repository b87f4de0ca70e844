/* lamprig-bench dimmer — a dimmer frame against the floor (issue 11: within 1.5x), paired.
 *
 * The `render` section times the dimmer frames and the floor pass in separate runs of a few
 * repetitions each; on a loaded machine the load changes between them and the ratio with it.
 * Here each repetition is a pair, one after the other in the same process: a dimmer frame
 * (a light.intensity change, which runs the blend pass alone) and one floor pass (a fullscreen
 * pass reading one RGBA16F texture into the same output target, lr_debug_floor_run: its
 * program made once, before the first pair), both wall time glFinish to glFinish with the renderer's timer
 * section around the draw, as a frame is timed. Reported per scene and size: median and min
 * of each, the ratio of the medians, the median of the per-pair ratios and the ratio of the
 * mins; and the same pairs in process CPU time (CLOCK_PROCESS_CPUTIME_ID: every thread,
 * llvmpipe's rasteriser threads included), which a loaded machine disturbs much less than
 * wall time (waiting for a core is not counted) and which is what a flickering rig's idle CPU
 * is made of. Old and new binaries are compared by running this section from each,
 * alternately (tools/bench/README.md).
 *
 * The scenes' own settings except render.frames = 1 and render.N = 1: the blend reads the
 * per-light images whatever their values (no per-pixel branch), so a converged image is not
 * needed and the first frame is cheaper. LRB_DIMMER_REPS (default 60, 1..1000) pairs;
 * LRB_DIMMER_SCENES ("candle,lampshade"-style list; default both). Runs with the other
 * sections under `make bench` (about a minute); an A/B comparison runs it from two binaries
 * alternately (tools/bench/README.md, "Dimmer against the floor").
 */
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

enum { REPS_DEFAULT = 60, REPS_MAX = 1000 };

static const char *const scene_names[] = {"candle", "lampshade"};
static const int sizes[][2] = {{640, 480}, {1280, 720}};

static int set_num(lr_scene *s, const char *key, double v, unsigned *dirty)
{
    char val[64];
    snprintf(val, sizeof val, "%.17g", v);
    return lrb_scene_set("bench dimmer", s, key, val, dirty);
}

/* One row: reps pairs of (dimmer frame, floor pass). */
static int row(lr_gl *gl, const char *name, int w, int h, int reps, FILE *out)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/scenes/%s.json", lr_configs_dir(), name);
    lr_scene *s = NULL;
    lr_renderer *r = NULL;
    lr_debug_floor *fl = NULL;
    lr_err e = {0};
    int rc = 1;
    double *t = calloc((size_t)reps * 6, sizeof *t);
    if (!t) {
        fprintf(stderr, "bench dimmer: out of memory\n");
        return 1;
    }
    double *dim = t, *flo = t + reps, *ratio = t + 2 * reps;
    double *cdim = t + 3 * reps, *cflo = t + 4 * reps, *cratio = t + 5 * reps;
    if (lr_scene_load(path, &(const lr_warn_sink){lr_warn_stderr, "lamprig-bench"}, &s, &e)) {
        fprintf(stderr, "bench dimmer: %s\n", e.msg);
        goto done;
    }
    if (set_num(s, "render.frames", 1, NULL) || set_num(s, "render.N", 1, NULL))
        goto done;
    if (lr_renderer_create(&(lr_renderer_desc){.gl = gl, .scene = s, .width = w, .height = h}, &r,
                           &e) ||
        lr_renderer_frame(r, NULL, &e) || lr_debug_floor_create(r, &fl, &e)) {
        fprintf(stderr, "bench dimmer: %s %dx%d: %s\n", name, w, h, e.msg);
        goto done;
    }
    /* A throw-away floor run: llvmpipe compiles a program's variant at its first draw (the
     * blend's ran in the first frame). */
    double w_ms, g_ms, c_ms;
    if (lr_debug_floor_run(fl, &w_ms, &g_ms, &c_ms, &e)) {
        fprintf(stderr, "bench dimmer: floor pass: %s\n", e.msg);
        goto done;
    }
    double I0 = lr_scene_light_at(s, 0)->intensity;
    for (int i = 0; i < reps; i++) {
        unsigned dirty = 0;
        if (set_num(s, "light.intensity", i % 2 ? I0 : 0.5 * I0, &dirty))
            goto done;
        lr_renderer_invalidate(r, dirty);
        lr_frame_stats st;
        glFinish();
        double t0 = lrb_now(), c0 = lrb_process_cpu_ms();
        if (lr_renderer_frame(r, &st, &e)) {
            fprintf(stderr, "bench dimmer: %s\n", e.msg);
            goto done;
        }
        glFinish();
        dim[i] = (lrb_now() - t0) * 1e3;
        cdim[i] = lrb_process_cpu_ms() - c0;
        if (st.passes != LR_PASS_BLEND) {
            fprintf(stderr, "bench dimmer: a dimmer frame ran passes 0x%x, not the blend alone\n",
                    st.passes);
            goto done;
        }
        double timer_ms;
        if (lr_debug_floor_run(fl, &flo[i], &timer_ms, &cflo[i], &e)) {
            fprintf(stderr, "bench dimmer: floor pass: %s\n", e.msg);
            goto done;
        }
        ratio[i] = dim[i] / flo[i];
        cratio[i] = cdim[i] / cflo[i];
    }
    double md = lr_median_finite(dim, reps), mf = lr_median_finite(flo, reps);
    double nd = lrb_min(dim, reps), nf = lrb_min(flo, reps);
    fprintf(out, "| %s | %d×%d | %d | %.2f (%.2f) | %.2f (%.2f) | %.2f | %.2f | %.2f | %.2f | %.2f "
                 "| %.2f |\n",
            name, w, h, reps, md, nd, mf, nf, md / mf, lr_median_finite(ratio, reps), nd / nf,
            lr_median_finite(cdim, reps), lr_median_finite(cflo, reps),
            lr_median_finite(cratio, reps));
    fflush(out);
    rc = 0;
done:
    lr_debug_floor_destroy(fl);
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
    free(t);
    return rc;
}

static int run(FILE *out)
{
    const char *rs = getenv("LRB_DIMMER_REPS");
    int reps = rs ? atoi(rs) : REPS_DEFAULT;
    if (reps < 1 || reps > REPS_MAX) {
        fprintf(stderr, "bench dimmer: LRB_DIMMER_REPS=%s: must be 1..%d\n", rs, REPS_MAX);
        return 2;
    }
    const char *scenes = getenv("LRB_DIMMER_SCENES");
    lr_gl *gl = NULL;
    lr_err e = {0};
    if (lr_gl_create(NULL, &gl, &e)) {
        fprintf(stderr, "bench dimmer: no GL context: %s\n", e.msg);
        return 1;
    }
    fprintf(out, "| scene | size | pairs | dimmer ms median (min) | floor ms median (min) | "
                 "dimmer / floor, medians | median of pair ratios | mins | dimmer CPU ms | "
                 "floor CPU ms | CPU, median of pair ratios |\n"
                 "|---|---|---|---|---|---|---|---|---|---|---|\n");
    int rc = 0;
    for (size_t k = 0; k < sizeof scene_names / sizeof scene_names[0] && !rc; k++)
        if (lrb_wanted(scenes, scene_names[k]))
            for (size_t j = 0; j < sizeof sizes / sizeof sizes[0] && !rc; j++)
                rc = row(gl, scene_names[k], sizes[j][0], sizes[j][1], reps, out);
    lr_gl_destroy(gl);
    return rc;
}

const lrb_section lrb_dimmer_section = {
    .name = "dimmer",
    .summary = "a dimmer frame against the floor pass, paired repetitions (issue 11)",
    .run = run,
};
