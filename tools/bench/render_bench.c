/* Section "render": the GPU renderer (render/renderer.h) on the headless EGL context.
 *
 * (1) Timing, for candle and lampshade at 640x480 and 1280x720 at the scenes' own settings:
 *     FULL_FRAMES full updates (the light is invalidated before each: every pass runs and the
 *     maps restart), median per pass and of the total; ACCUM_FRAMES accumulation frames
 *     (nothing dirty: radiosity + vpl + compose; render.frames is set to 1 + ACCUM_FRAMES so
 *     that the maps have converged after them), median total; DIMMER_FRAMES dimmer-only frames
 *     (light.intensity alternately halved and restored: the blend pass alone), median total;
 *     CAMERA_FRAMES camera-only frames (compose + blend; wall time; with the per-pixel gather
 *     at every move, then as shipped, from the surface cache: issue 11's camera ratio; the
 *     first move, which draws the cache, and the still frame after a move apart); the floor
 *     (issue 11): a fullscreen pass reading one RGBA16F texture into the output
 *     (lr_renderer_debug_floor_ms), timed as a frame's pass is (inside a renderer timer section; wall time glFinish to glFinish
 *     around the whole, as for the dimmer frames). Ratios: full update / dimmer, compose /
 *     dimmer (the dimmer against a composition), dimmer / floor by the timers and by wall
 *     time, compose / camera.
 * (2) Error against accumulated frames, at ERR_W x ERR_H with reduced settings (ERR_K maps of
 *     ERR_MAP^2, ERR_N samples): relative RMSE of the GPU image after 1, 4, 16 and 64 frames,
 *     sqrt(sum (g - r)^2 / sum r^2) over the bands of the masked pixels, in linear light,
 *     against (a) the converged CPU reference of the model (lr_cpu_render, LR_CPU_REFERENCE,
 *     the scene's N_vpl VPLs so that the VPL discretisation is the GPU's) and (b) the
 *     renderer's own SELF_FRAMES-frame image (pure sampling noise of the progressive maps;
 *     scaled by 1/sqrt(1 - F/SELF_FRAMES), since that image contains the first F frames).
 *     The CPU reference's own relative standard error (from its variance image) is printed
 *     against the GPU's 64-frame noise.
 *     Masks: object pixels are those whose camera ray hits an object's BVH; receiver pixels
 *     the rest where the CPU reference is non-zero (the background is 0).
 *
 * Files: build/bench/render.csv and build/bench/render-error.csv (atomic writes; a file is
 * only replaced when its part ran). LRB_RENDER_PARTS=timing or =error runs one part. About
 * 6 minutes on 2 shared cores with llvmpipe (timing 3.3, error 2.5). */
#include "tools/bench/bench.h"

#include <GLES3/gl31.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "render/base/atomic_file.h"
#include "render/base/median.h"
#include "render/base/paths.h"
#include "render/cpu/frame.h"
#include "render/gl/gl.h"
#include "render/mesh/bvh.h"
#include "render/image/image.h"
#include "render/renderer.h"
#include "render/renderer_debug.h"
#include "render/scene/scene.h"

enum { FULL_FRAMES = 3, ACCUM_FRAMES = 4, DIMMER_FRAMES = 5, CAMERA_FRAMES = 5, FLOOR_REPS = 9 };
enum { ERR_W = 160, ERR_H = 120, ERR_K = 8, ERR_MAP = 64, ERR_N = 4, SELF_FRAMES = 256,
       REF_SAMPLES = 4096 };

static const char *const scene_names[] = {"candle", "lampshade"};
static const int sizes[][2] = {{640, 480}, {1280, 720}};
static const int err_frames[] = {1, 4, 16, 64};


static lr_scene *load(const char *name)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/scenes/%s.json", lr_configs_dir(), name);
    lr_scene *s = NULL;
    lr_err e = {0};
    if (lr_scene_load(path, &(const lr_warn_sink){lr_warn_stderr, "lamprig-bench"}, &s, &e))
        fprintf(stderr, "bench render: %s\n", e.msg);
    return s;
}

static int set_num(lr_scene *s, const char *key, double v, unsigned *dirty)
{
    char val[64];
    snprintf(val, sizeof val, "%.17g", v);
    lr_err e = {0};
    unsigned d = 0;
    if (lr_scene_set(s, key, val, &d, &e)) {
        fprintf(stderr, "bench render: %s=%s: %s\n", key, val, e.msg);
        return 1;
    }
    if (dirty)
        *dirty |= d;
    return 0;
}

static int ensure_dir(void)
{
    if ((mkdir("build", 0777) && errno != EEXIST) || (mkdir("build/bench", 0777) && errno != EEXIST)) {
        fprintf(stderr, "bench render: cannot create build/bench: %s\n", strerror(errno));
        return 1;
    }
    return 0;
}

/* ---- timing ----------------------------------------------------------------------------- */

typedef struct timing_row {
    const char *scene;
    int w, h;
    double pass_ms[LR_PASS_COUNT], total_ms, accum_ms, dimmer_ms;
    double floor_ms;  /* one RGBA16F fetch per pixel into the output (the floor, issue 11),
                       * wall time glFinish to glFinish, inside a renderer timer section as a
                       * frame's pass is */
    double floor_timer_ms; /* the same draw by the renderer's timer (as dimmer_ms is) */
    double dimmer_wall_ms; /* a dimmer frame the same way: lr_renderer_frame + glFinish */
    double camera_ms; /* camera-only change (compose + blend) as shipped: B from the surface
                       * cache (render.surface_cache_moves), wall */
    double camera_gather_ms; /* the same with the per-pixel gather at every move */
    double camera_first_ms;  /* the first move on new maps: surface pass + compose + blend */
    double still_ms;         /* the frame after a move: compose (gather) + blend */
    double surface_ms;       /* the surface pass of the first move (renderer's timer) */
} timing_row;

static int frame(lr_renderer *r, lr_frame_stats *st)
{
    lr_err e = {0};
    if (lr_renderer_frame(r, st, &e)) {
        fprintf(stderr, "bench render: %s\n", e.msg);
        return 1;
    }
    return 0;
}

static int time_one(lr_gl *gl, const char *name, int w, int h, timing_row *row)
{
    lr_scene *s = load(name);
    if (!s)
        return 1;
    lr_renderer *r = NULL;
    lr_err e = {0};
    int rc = 1;
    /* Accumulation converges after the last accumulation frame, so that the dimmer frames
     * run composition alone (while accumulating, every frame also adds a radiosity frame). */
    if (set_num(s, "render.frames", 1 + ACCUM_FRAMES, NULL))
        goto done;
    if (lr_renderer_create(&(lr_renderer_desc){.gl = gl, .scene = s, .width = w, .height = h}, &r,
                           &e)) {
        fprintf(stderr, "bench render: %s\n", e.msg);
        goto done;
    }
    *row = (timing_row){.scene = name, .w = w, .h = h};
    double full[LR_PASS_COUNT][FULL_FRAMES], total[FULL_FRAMES], acc[ACCUM_FRAMES],
        dim[DIMMER_FRAMES], dimw[DIMMER_FRAMES];
    lr_frame_stats st;
    for (int i = 0; i < FULL_FRAMES; i++) {
        lr_renderer_invalidate(r, LR_DIRTY_LIGHT_GEOMETRY);
        if (frame(r, &st))
            goto done;
        for (int p = 0; p < LR_PASS_COUNT; p++)
            full[p][i] = (st.passes & (1u << p)) ? st.ms[p] : NAN;
        total[i] = st.total_ms;
    }
    for (int i = 0; i < ACCUM_FRAMES; i++) {
        if (frame(r, &st))
            goto done;
        acc[i] = st.total_ms;
    }
    double I0 = lr_scene_light_at(s, 0)->intensity;
    for (int i = 0; i < DIMMER_FRAMES; i++) {
        unsigned dirty = 0;
        if (set_num(s, "light.intensity", i % 2 ? I0 : 0.5 * I0, &dirty))
            goto done;
        lr_renderer_invalidate(r, dirty);
        glFinish();
        double w0 = lrb_now();
        if (frame(r, &st))
            goto done;
        glFinish();
        dimw[i] = (lrb_now() - w0) * 1e3;
        if (st.passes != LR_PASS_BLEND)
            fprintf(stderr, "bench render: dimmer frame ran passes 0x%x, not the blend alone\n",
                    st.passes);
        dim[i] = st.total_ms;
    }
    /* Camera-only changes: the camera moved 1 mm sideways and back, wall time glFinish to
     * glFinish; first with the per-pixel gather at every move (render.surface_cache_moves
     * false: Algorithm 1 per object pixel, the composition before the cache), then as shipped
     * (render.surface_cache_moves: a move composes from the surface cache). Switching to the
     * shipped path is a view change that draws the cache and composes from it, as the first
     * move after the maps change does ("first move"); the frame after it composes the still
     * image with the gather ("still"); then the moves. */
    double cam[2][CAMERA_FRAMES];
    lr_vec3 c0 = lr_scene_camera(s)->position;
    for (int pass = 0; pass < 2; pass++) {
        unsigned dirty = 0;
        if (lr_scene_set(s, "render.surface_cache_moves", pass ? "true" : "false", &dirty, &e)) {
            fprintf(stderr, "bench render: render.surface_cache_moves: %s\n", e.msg);
            goto done;
        }
        lr_renderer_invalidate(r, dirty);
        glFinish();
        double w0 = lrb_now();
        if (frame(r, &st))
            goto done;
        glFinish();
        if (pass) {
            row->camera_first_ms = (lrb_now() - w0) * 1e3;
            row->surface_ms = st.ms[6];
            if (!(st.passes & LR_PASS_SURFACE))
                fprintf(stderr, "bench render: the first move drew no surface cache\n");
            glFinish();
            w0 = lrb_now();
            if (frame(r, &st))
                goto done;
            glFinish();
            row->still_ms = (lrb_now() - w0) * 1e3;
        }
        for (int i = 0; i < CAMERA_FRAMES; i++) {
            char val[96];
            snprintf(val, sizeof val, "%.17g,%.17g,%.17g", c0.x + (i % 2 ? 0.0 : 1.0), c0.y, c0.z);
            dirty = 0;
            if (lr_scene_set(s, "camera.position", val, &dirty, &e)) {
                fprintf(stderr, "bench render: camera.position: %s\n", e.msg);
                goto done;
            }
            lr_renderer_invalidate(r, dirty);
            glFinish();
            w0 = lrb_now();
            if (frame(r, &st))
                goto done;
            glFinish();
            cam[pass][i] = (lrb_now() - w0) * 1e3;
            if (st.passes != (LR_PASS_COMPOSE | LR_PASS_BLEND))
                fprintf(stderr, "bench render: camera move ran passes 0x%x, not compose + "
                        "blend\n", st.passes);
        }
    }
    if (lr_renderer_debug_floor_ms(r, FLOOR_REPS, &row->floor_ms, &row->floor_timer_ms, &e)) {
        fprintf(stderr, "bench render: floor pass: %s\n", e.msg);
        goto done;
    }
    row->camera_gather_ms = lr_median_finite(cam[0], CAMERA_FRAMES);
    row->camera_ms = lr_median_finite(cam[1], CAMERA_FRAMES);
    row->dimmer_wall_ms = lr_median_finite(dimw, DIMMER_FRAMES);
    for (int p = 0; p < LR_PASS_COUNT; p++)
        row->pass_ms[p] = lr_median_finite(full[p], FULL_FRAMES);
    row->total_ms = lr_median_finite(total, FULL_FRAMES);
    row->accum_ms = lr_median_finite(acc, ACCUM_FRAMES);
    row->dimmer_ms = lr_median_finite(dim, DIMMER_FRAMES);
    fprintf(stderr, "bench render: %s %dx%d timed\n", name, w, h);
    rc = 0;
done:
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
    return rc;
}

/* ---- error -------------------------------------------------------------------------------- */

/* Relative RMSE of g against r over the pixels where mask is set: sqrt(sum (g-r)^2 / sum r^2),
 * all bands. NaN when the reference is zero on the mask. */
static double rel_rmse(const float *g, const float *r, const unsigned char *mask, size_t n)
{
    double num = 0.0, den = 0.0;
    for (size_t i = 0; i < n; i++)
        if (mask[i])
            for (int c = 0; c < 3; c++) {
                double d = (double)g[3 * i + c] - (double)r[3 * i + c];
                num += d * d;
                den += (double)r[3 * i + c] * r[3 * i + c];
            }
    return den > 0.0 ? sqrt(num / den) : NAN;
}

/* Relative standard error of the reference on the mask: sqrt(sum var / sum r^2). */
static double rel_stderr(const float *var, const float *r, const unsigned char *mask, size_t n)
{
    double num = 0.0, den = 0.0;
    for (size_t i = 0; i < n; i++)
        if (mask[i])
            for (int c = 0; c < 3; c++) {
                num += var[3 * i + c];
                den += (double)r[3 * i + c] * r[3 * i + c];
            }
    return den > 0.0 ? sqrt(num / den) : NAN;
}

/* GPU HDR (bottom up) into top-down rows. */
static int read_top_down(lr_renderer *r, float *out, float *tmp, int w, int h)
{
    lr_err e = {0};
    if (lr_renderer_read_hdr(r, tmp, &e)) {
        fprintf(stderr, "bench render: %s\n", e.msg);
        return 1;
    }
    for (int y = 0; y < h; y++)
        memcpy(out + (size_t)y * w * 3, tmp + (size_t)(h - 1 - y) * w * 3,
               (size_t)w * 3 * sizeof *out);
    return 0;
}

typedef struct error_row {
    const char *scene;
    int frames;
    double obj, rec;           /* against the CPU reference */
    double obj_self, rec_self; /* against the GPU's SELF_FRAMES-frame image */
} error_row;

typedef struct error_info {
    double ref_se_obj, ref_se_rec; /* relative standard error of the CPU reference */
    double ref_s, self_s;          /* seconds */
    long obj_px, rec_px;
} error_info;

static int error_one(lr_gl *gl, const char *name, error_row rows[4], error_info *info)
{
    lr_scene *s = load(name);
    if (!s)
        return 1;
    int rc = 1;
    const int w = ERR_W, h = ERR_H;
    const size_t n = (size_t)w * h;
    lr_renderer *r = NULL;
    lr_image ref = {0}, var = {0};
    float *img[4] = {0}, *self = malloc(n * 3 * sizeof(float)), *tmp = malloc(n * 3 * sizeof(float));
    unsigned char *mobj = calloc(n, 1), *mrec = calloc(n, 1);
    for (int f = 0; f < 4; f++)
        img[f] = malloc(n * 3 * sizeof(float));
    lr_err e = {0};
    if (!self || !tmp || !mobj || !mrec || !img[0] || !img[1] || !img[2] || !img[3])
        goto done;
    if (set_num(s, "render.K", ERR_K, NULL) || set_num(s, "render.map_size", ERR_MAP, NULL) ||
        set_num(s, "render.N", ERR_N, NULL) || set_num(s, "render.frames", SELF_FRAMES, NULL))
        goto done;

    /* Converged CPU reference of the model, with the GPU's VPL count. */
    double t0 = lrb_now();
    lr_cpu_render_stats cst;
    if (lr_cpu_render(&(lr_cpu_render_desc){.scene = s, .width = w, .height = h,
                                            .mode = LR_CPU_REFERENCE, .samples = REF_SAMPLES,
                                            .vpl_count = lr_scene_render(s)->N_vpl},
                      &ref, &var, &cst, &e)) {
        fprintf(stderr, "bench render: %s\n", e.msg);
        goto done;
    }
    info->ref_s = lrb_now() - t0;
    fprintf(stderr, "bench render: %s CPU reference %.0f s\n", name, info->ref_s);

    /* Masks. */
    info->obj_px = info->rec_px = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            lr_vec3 o, d;
            lr_cpu_camera_ray(s, w, h, x, y, &o, &d);
            bool hit = false;
            for (int k = 0; k < lr_scene_object_count(s) && !hit; k++)
                hit = lr_bvh_occluded(lr_scene_object_at(s, k)->bvh, o, d, 0.0, 1e30);
            size_t i = (size_t)y * w + x;
            const float *p = ref.rgb + 3 * i;
            if (hit)
                mobj[i] = 1, info->obj_px++;
            else if (p[0] > 0.0f || p[1] > 0.0f || p[2] > 0.0f)
                mrec[i] = 1, info->rec_px++;
        }
    info->ref_se_obj = rel_stderr(var.rgb, ref.rgb, mobj, n);
    info->ref_se_rec = rel_stderr(var.rgb, ref.rgb, mrec, n);

    /* GPU: 1, 4, 16, 64 frames, then on to SELF_FRAMES. */
    if (lr_renderer_create(&(lr_renderer_desc){.gl = gl, .scene = s, .width = w, .height = h}, &r,
                           &e)) {
        fprintf(stderr, "bench render: %s\n", e.msg);
        goto done;
    }
    t0 = lrb_now();
    lr_frame_stats st = {0};
    int next = 0;
    while (st.samples < SELF_FRAMES) {
        if (frame(r, &st))
            goto done;
        if (next < 4 && st.samples == err_frames[next]) {
            if (read_top_down(r, img[next], tmp, w, h))
                goto done;
            next++;
        }
        if (st.index > 2 * SELF_FRAMES) {
            fprintf(stderr, "bench render: accumulation stalled at %d frames\n", st.samples);
            goto done;
        }
    }
    if (next < 4 || read_top_down(r, self, tmp, w, h))
        goto done;
    info->self_s = lrb_now() - t0;
    /* The SELF_FRAMES-frame mean contains the first F frames: with independent frames,
     * Var(mean_F - mean_S) = sigma^2 (1/F - 1/S), so the measured RMSE is scaled by
     * 1 / sqrt(1 - F/S) to give the error against the true mean of the model. */
    double self_fix[4];
    for (int f = 0; f < 4; f++)
        self_fix[f] = 1.0 / sqrt(1.0 - (double)err_frames[f] / SELF_FRAMES);
    for (int f = 0; f < 4; f++)
        rows[f] = (error_row){.scene = name,
                              .frames = err_frames[f],
                              .obj = rel_rmse(img[f], ref.rgb, mobj, n),
                              .rec = rel_rmse(img[f], ref.rgb, mrec, n),
                              .obj_self = rel_rmse(img[f], self, mobj, n) * self_fix[f],
                              .rec_self = rel_rmse(img[f], self, mrec, n) * self_fix[f]};
    rc = 0;
done:
    lr_renderer_destroy(r);
    lr_image_free(&ref);
    lr_image_free(&var);
    for (int f = 0; f < 4; f++)
        free(img[f]);
    free(self);
    free(tmp);
    free(mobj);
    free(mrec);
    lr_scene_destroy(s);
    return rc;
}

/* ---- section ------------------------------------------------------------------------------ */

static int write_csvs(const timing_row *t, int nt, const error_row *er, int ne)
{
    if (ensure_dir())
        return 1;
    lr_err e = {0};
    lr_atomic_file *af;
    FILE *f;
    if (!nt)
        goto errors; /* timing not run: keep the previous file */
    if (lr_atomic_file_open("build/bench/render.csv", &af, &e))
        goto fail;
    f = lr_atomic_file_stream(af);
    fprintf(f, "scene,resolution,gbuffer_ms,radiosity_ms,vpl_ms,compose_ms,total_ms,accum_ms,"
               "dimmer_ms,ratio,blend_ms,floor_ms,camera_ms,dimmer_wall_ms,floor_timer_ms,"
               "surface_ms,camera_gather_ms,camera_first_ms,still_ms\n");
    for (int i = 0; i < nt; i++)
        fprintf(f, "%s,%dx%d,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.2f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,"
                   "%.3f,%.3f,%.3f\n",
                t[i].scene,
                t[i].w, t[i].h, t[i].pass_ms[0], t[i].pass_ms[1], t[i].pass_ms[2],
                t[i].pass_ms[3], t[i].total_ms, t[i].accum_ms, t[i].dimmer_ms,
                t[i].total_ms / t[i].dimmer_ms, t[i].pass_ms[4], t[i].floor_ms, t[i].camera_ms,
                t[i].dimmer_wall_ms, t[i].floor_timer_ms, t[i].surface_ms, t[i].camera_gather_ms,
                t[i].camera_first_ms, t[i].still_ms);
    if (lr_atomic_file_commit(af, &e))
        goto fail;
errors:
    if (!ne)
        return 0;
    if (lr_atomic_file_open("build/bench/render-error.csv", &af, &e))
        goto fail;
    f = lr_atomic_file_stream(af);
    fprintf(f, "scene,frames,rel_rmse_object,rel_rmse_receivers,rel_rmse_object_self,"
               "rel_rmse_receivers_self\n");
    for (int i = 0; i < ne; i++)
        fprintf(f, "%s,%d,%.5f,%.5f,%.5f,%.5f\n", er[i].scene, er[i].frames, er[i].obj, er[i].rec,
                er[i].obj_self, er[i].rec_self);
    if (lr_atomic_file_commit(af, &e))
        goto fail;
    return 0;
fail:
    fprintf(stderr, "bench render: %s\n", e.msg);
    return 1;
}

static int run(FILE *out)
{
    double t_start = lrb_now();
    lr_gl *gl = NULL;
    lr_err e = {0};
    if (lr_gl_create(NULL, &gl, &e)) {
        fprintf(stderr, "bench render: no GL context: %s\n", e.msg);
        return 1;
    }
    int status = 0;
    timing_row t[4];
    int nt = 0;
    /* LRB_RENDER_PARTS=timing or =error runs one half (for working on the section). */
    const char *parts = getenv("LRB_RENDER_PARTS");
    bool do_timing = !parts || !strcmp(parts, "timing"), do_error = !parts || !strcmp(parts, "error");
    for (int si = 0; si < 2 && do_timing; si++)
        for (int ri = 0; ri < 2; ri++)
            if (time_one(gl, scene_names[si], sizes[ri][0], sizes[ri][1], &t[nt]) == 0)
                nt++;
            else
                status = 1;
    double t_timing = lrb_now() - t_start;
    error_row er[8];
    error_info info[2];
    int ne = 0, ok[2] = {0, 0};
    for (int si = 0; si < 2 && do_error; si++)
        if (error_one(gl, scene_names[si], er + ne, &info[si]) == 0)
            ne += 4, ok[si] = 1;
        else
            status = 1;

    /* Renderer line: the first renderer's info (every renderer here shares the context). */
    char info_line[512] = "unknown";
    {
        lr_scene *s = load("candle");
        lr_renderer *r = NULL;
        if (s && !lr_renderer_create(&(lr_renderer_desc){.gl = gl, .scene = s, .width = 16,
                                                         .height = 16},
                                     &r, &e))
            snprintf(info_line, sizeof info_line, "%s", lr_renderer_info(r));
        lr_renderer_destroy(r);
        lr_scene_destroy(s);
    }
    lr_gl_destroy(gl);

    fprintf(out, "## Renderer (`lamprig-bench render`)\n\n");
    if (nt) {
        fprintf(out, "Frame times, ms (full update: every pass, median of %d; accumulation: radiosity "
                     "+ vpl + compose + blend, median of %d; dimmer: the blend alone, median of %d; "
                     "camera: a camera move as shipped (render.surface_cache_moves: compose from "
                     "the objects' surface cache + blend), wall time, median of %d; \"camera, "
                     "gather\": the same with Algorithm 1 per object pixel at every move "
                     "(render.surface_cache_moves false); \"first move\": the first move after "
                     "the maps change, which draws the cache (its pass: \"surface\"); \"still\": "
                     "the frame after a move, which composes the still image with the gather; "
                     "floor: a fullscreen "
                     "pass reading one RGBA16F texture into the output, median of %d). Pass times "
                     "are the renderer's timers; \"wall\" is wall time from glFinish to glFinish "
                     "(what a caller waits). The floor is measured as a frame's pass is: its draw "
                     "inside one section of the renderer's timer (\"floor\", as \"dimmer\"), "
                     "the whole glFinish to glFinish (\"floor wall\", as \"dimmer wall\": the "
                     "frame's CPU work and timer-query overhead included in both), so each "
                     "dimmer / floor ratio compares like with like. Issue 11's camera target is "
                     "\"compose / camera\" against the composition of its time (520 ms on this "
                     "machine). Scenes' own settings (K 16, N 16, 256² maps).\n\n",
                FULL_FRAMES, ACCUM_FRAMES, DIMMER_FRAMES, CAMERA_FRAMES, FLOOR_REPS);
        fprintf(out, "| scene | size | gbuffer | radiosity | vpl | surface | compose | blend | full update | "
                     "accumulation | dimmer | dimmer wall | floor | floor wall | camera | "
                     "full / dimmer | compose / dimmer | dimmer / floor | "
                     "dimmer wall / floor wall | compose / camera | camera, gather | "
                     "gather / camera | first move | still |\n");
        fprintf(out, "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
        for (int i = 0; i < nt; i++) {
            fprintf(out, "| %s | %d×%d | %.1f | %.1f | %.1f | %.1f | %.1f | %.2f | %.1f | %.1f | %.2f | "
                         "%.2f | %.2f | %.2f | %.1f | %.0f | %.0f | %.2f | %.2f | %.2f | %.1f | "
                         "%.1f | %.1f | %.1f |\n",
                    t[i].scene, t[i].w, t[i].h, t[i].pass_ms[0], t[i].pass_ms[1], t[i].pass_ms[2],
                    t[i].surface_ms, t[i].pass_ms[3], t[i].pass_ms[4], t[i].total_ms,
                    t[i].accum_ms, t[i].dimmer_ms,
                    t[i].dimmer_wall_ms, t[i].floor_timer_ms, t[i].floor_ms, t[i].camera_ms,
                    t[i].total_ms / t[i].dimmer_ms, t[i].pass_ms[3] / t[i].dimmer_ms,
                    t[i].dimmer_ms / t[i].floor_timer_ms, t[i].dimmer_wall_ms / t[i].floor_ms,
                    t[i].pass_ms[3] / t[i].camera_ms, t[i].camera_gather_ms,
                    t[i].camera_gather_ms / t[i].camera_ms, t[i].camera_first_ms, t[i].still_ms);
        }
    }
    fprintf(out, "\nRenderer: %s.\n\n", info_line);
    fprintf(out, "Relative RMSE (linear light, sqrt(Σ(g−r)²/Σr²) over the bands of the masked "
                 "pixels) of the GPU image after F accumulated frames, %d×%d, K %d, %d² maps, "
                 "N %d. \"ref\": against the converged CPU reference of the model (%d samples per "
                 "band, the scene's N_vpl VPLs); \"self\": against the renderer's own %d-frame "
                 "image (sampling noise alone; scaled by 1/sqrt(1 − F/%d) because that image contains the first F frames).\n\n",
            ERR_W, ERR_H, ERR_K, ERR_MAP, ERR_N, REF_SAMPLES, SELF_FRAMES, SELF_FRAMES);
    fprintf(out, "| scene | F | objects (ref) | receivers (ref) | objects (self) | receivers (self) |\n");
    fprintf(out, "|---|---|---|---|---|---|\n");
    for (int i = 0; i < ne; i++)
        fprintf(out, "| %s | %d | %.4f | %.4f | %.4f | %.4f |\n", er[i].scene, er[i].frames,
                er[i].obj, er[i].rec, er[i].obj_self, er[i].rec_self);
    fprintf(out, "\n");
    for (int si = 0, k = 0; si < 2; si++) {
        if (!ok[si])
            continue;
        const error_row *r64 = &er[k + 3];
        fprintf(out, "%s: %ld object / %ld receiver pixels; CPU reference %.1f s, relative "
                     "standard error %.4f (objects) / %.4f (receivers) = %.2f / %.2f of the "
                     "GPU's 64-frame noise (self); GPU %d frames %.1f s.\n",
                scene_names[si], info[si].obj_px, info[si].rec_px, info[si].ref_s,
                info[si].ref_se_obj, info[si].ref_se_rec, info[si].ref_se_obj / r64->obj_self,
                info[si].ref_se_rec / r64->rec_self, SELF_FRAMES, info[si].self_s);
        k += 4;
    }
    if (write_csvs(t, nt, er, ne))
        status = 1;
    fprintf(out, "\nWrote build/bench/render.csv and build/bench/render-error.csv. Section time "
                 "%.0f s (timing %.0f s).\n\n",
            lrb_now() - t_start, t_timing);
    return status;
}

const lrb_section lrb_render_section = {
    .name = "render",
    .summary = "GPU renderer: per-pass frame times, dimmer vs full update, error vs frames",
    .run = run,
};
