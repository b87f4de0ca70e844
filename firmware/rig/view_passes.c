/* lamprig firmware — the "passes" view: seed 003's passes with the light transport on a
 * worker thread (render/async/async.h); the loop's thread blends the latest per-light images
 * at every frame, so no control waits behind a solve. */
#include "firmware/rig/view.h"

#include <stdlib.h>

#include <stdio.h>

#include "render/async/async.h"
#include "render/plan/limits.h"

/* The first image after a change that re-runs the maps (a material, a light move, a scene
 * switch) is drawn at these settings, then refined at the scene's own: one map, one sample,
 * small maps, one frame, no receiver inter-reflection, the VPLs gathered per pixel; and an object whose model costs a CPU solve (a diffusion grid,
 * translucent radiosity) is drawn with the profile model the planner names for a preview
 * (lr_plan_preview_model: the directional dipole where it fits). A coarse but coherent image
 * of the new state (render/async/). */
static const char *const preview_sets[] = {
    "render.K=1", "render.N=1", "render.map_size=32", "render.gbuffer_size=32",
    "render.vpl_map_size=16", "render.N_vpl=4", "render.frames=1",
    /* The receivers' inter-reflection is a CPU solve (1.3 s of a 1.4 s preview frame on the
     * proxy): the preview shows their direct and emergent light without it. */
    "render.receiver_bounce=false", "render.opening_light=false",
    /* Four VPLs gathered per receiver pixel at composition instead of on two 256^2 grids
     * (the grid pass was about 45 ms of a 180 ms preview frame on the proxy's candle). */
    "render.irradiance_grid=false",
    /* The VPLs' shadows by the objects (32 envelope reads per VPL and receiver pixel): 15 ms
     * of the 37 ms composition of the candle's 320x240 preview on the proxy. */
    "render.vpl_visibility=false",
};
#define N_PREVIEW ((int)(sizeof preview_sets / sizeof preview_sets[0]))
/* The preview is drawn at half the view's width and height and shown scaled up: its
 * composition, per pixel, was 23 of its 35 ms at 320x240 on the proxy. */
#define PREVIEW_SCALE 0.5

static int v_create(const lr_rig_view_desc *d, void **impl, lr_err *e)
{
    if (!d->gl)
        return lr_err_set(e, LR_EINVAL, "renderer 'passes' needs a GL context");
    lr_async_desc ad = {.gl = d->gl, .scene = d->scene, .width = d->width,
                        .height = d->height, .no_vpl = d->no_vpl,
                        .gpu_budget_mb = d->gpu_budget_mb, .cache_keys = d->cache_keys,
                        .n_cache_keys = d->n_cache_keys, .cache_mb = d->cache_mb,
                        .slice_ms = d->slice_ms, .preview_scale = PREVIEW_SCALE};
    char model_sets[LR_ASYNC_MAX_PREVIEW - N_PREVIEW][128];
    if (!d->no_preview) {
        for (int i = 0; i < N_PREVIEW; i++)
            ad.preview[i] = preview_sets[i];
        ad.n_preview = N_PREVIEW;
        int n = lr_scene_object_count(d->scene);
        for (int i = 0; i < n && ad.n_preview < LR_ASYNC_MAX_PREVIEW; i++) {
            const char *m = lr_plan_preview_model(lr_scene_object_at(d->scene, i));
            if (!m)
                continue;
            char *set = model_sets[ad.n_preview - N_PREVIEW];
            snprintf(set, sizeof model_sets[0], "objects[%d].model=%s", i, m);
            ad.preview[ad.n_preview++] = set;
        }
    }
    lr_async *a;
    int rc = lr_async_create(&ad, &a, e);
    if (rc)
        return rc;
    *impl = a;
    return LR_OK;
}

static void v_destroy(void *impl) { lr_async_destroy(impl); }
static uint64_t v_invalidate(void *impl, unsigned dirty) { return lr_async_commit(impl, dirty); }
static bool v_needs_frame(const void *impl) { return lr_async_needs_frame(impl); }
static void v_set_time(void *impl, double t) { lr_async_set_time(impl, t); }

static int v_frame(void *impl, lr_frame_stats *st, lr_rig_frame_info *info, lr_err *e)
{
    lr_async_frame_stats as;
    int rc = lr_async_frame(impl, &as, e);
    if (rc)
        return rc;
    /* The loop's frame is the blend; the worker frame whose images it shows is kept for
     * the samples and convergence. */
    *st = as.worker;
    st->passes = as.stage == LR_ASYNC_NONE ? 0u : (unsigned)LR_PASS_BLEND;
    st->total_ms = as.blend_ms;
    *info = (lr_rig_frame_info){.batch = as.batch, .stage = as.stage,
                                .converged = lr_async_stage_converged(as.stage)};
    return LR_OK;
}

static int v_read(void *impl, unsigned char *rgba, lr_err *e)
{
    return lr_async_read_rgba8(impl, rgba, e);
}

static int v_present(void *impl, lr_err *e) { return lr_async_present(impl, e); }
static int v_event_fd(const void *impl) { return lr_async_event_fd(impl); }
static bool v_busy(const void *impl) { return lr_async_busy(impl); }
static int v_error(void *impl, lr_err *e) { return lr_async_error(impl, e); }

static void v_retire(void *impl) { lr_async_stop(impl); }
static int v_anticipate(void *impl, const lr_async_state *s, int n, lr_err *e)
{
    return lr_async_anticipate(impl, s, n, e);
}
static void v_cache_stats(const void *impl, lr_state_cache_stats *st, int *pending)
{
    lr_async_cache_stats(impl, st, pending);
}
static bool v_retired(const void *impl) { return lr_async_stopped(impl); }

static int v_wait(void *impl, int timeout_ms, lr_err *e)
{
    return lr_async_wait(impl, 0, false, timeout_ms, e);
}

const lr_rig_view_ops lr_rig_view_passes = {
    .name = "passes",
    .needs_gl = true,
    .create = v_create,
    .destroy = v_destroy,
    .invalidate = v_invalidate,
    .needs_frame = v_needs_frame,
    .set_time = v_set_time,
    .frame = v_frame,
    .read_rgba8 = v_read,
    .present = v_present,
    .event_fd = v_event_fd,
    .busy = v_busy,
    .error = v_error,
    .wait_first = v_wait,
    .retire = v_retire,
    .retired = v_retired,
    .anticipate = v_anticipate,
    .cache_stats = v_cache_stats,
};
