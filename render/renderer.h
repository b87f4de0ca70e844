/* lamprig — the renderer: seed 003's passes over a scene, scheduled by what changed.
 *
 * This is the one interface the CLI (`lamprig render`), the firmware's main loop, the bench and
 * the calibration comparison runs use. The estimators each pass computes are fixed in
 * render/passes/PIPELINE.md; render/cpu/ is their CPU twin.
 *
 * Scheduling (docs/ARCHITECTURE.md, "Data flow"): the caller changes the scene with lr_scene_set(), which
 * returns LR_DIRTY_* flags, and hands them to lr_renderer_invalidate(). The next
 * lr_renderer_frame() runs only the passes lr_dirty_passes() (render/schedule.h) names.
 * Composition renders one linear image per light at unit intensity for the current view (objects and receivers); the
 * blend pass sums them with the lights' intensity x colour x flicker, tone-maps and writes the
 * output. So a dimmer, colour, flicker or exposure change runs the blend alone (one fullscreen
 * pass; transport is linear in intensity); a camera change composition and the blend (the
 * receivers' emergent light comes from view-independent irradiance grids, redrawn only with
 * the VPLs or the receivers); a material change the radiosity maps, VPLs, grids, composition
 * and blend; light or geometry changes everything. With nothing dirty, frames keep accumulating radiosity samples until
 * `render.frames` have been accumulated, then lr_renderer_needs_frame() turns false and the
 * caller only re-presents. Where nothing is sampled per frame (every object's B solved or
 * evaluated: translucent_radiosity, diffusion_grid, sh_translucency; no area light) the first
 * accumulation frame is the converged one, and lr_renderer_needs_frame() turns false after
 * it whatever render.frames says (lr_frame_stats.deterministic).
 */
#ifndef LR_RENDERER_H
#define LR_RENDERER_H

#include <stdbool.h>

#include "render/base/cancel.h"
#include "render/base/err.h"
#include "render/gl/gl.h"
#include "render/gl/tex.h"
#include "render/image/image.h"
#include "render/schedule.h"
#include "render/scene/scene.h"

typedef struct lr_renderer lr_renderer;

typedef struct lr_renderer_desc {
    lr_gl *gl;             /* current context; the renderer does not own it */
    lr_scene *scene;       /* read at every frame; owned by the caller */
    int width, height;     /* output image; 0 = 640 x 480 */
    bool no_vpl;           /* skip emergent light (pass 4) */
    bool vpl_visibility;   /* shadow the VPLs by the objects (beyond seed 003; costs
                            * N_vpl x 32 cube-map lookups per receiver pixel); on when this
                            * or the scene's render.vpl_visibility is true */
    unsigned seed;         /* base of the per-texel/map/frame sample seeds; 0 = 1 */
    bool half_maps;        /* RGBA16F radiosity maps even where RGBA32F blending exists (the
                            * fallback for drivers without EXT_float_blend; for its tests) */
    bool images_only;      /* the caller blends lr_renderer_images itself (render/async): the
                            * renderer never runs its own blend pass (the output image, 10-70 ms
                            * a preview on the proxy), and read_hdr / read_rgba8 / present fail */
    /* > 0: the most GPU memory (MB: textures and renderbuffers, lr_gl_memory) the renderer
     * may take; settings that need more are refused at create or at the frame that applies
     * them (LR_ENOMEM, naming what they need). 0: no limit. */
    double gpu_budget_mb;
    /* Another renderer on the same context and thread whose GLSL programs this one uses
     * instead of building its own (their defines do not depend on the scene or settings):
     * render/async's preview renderer, which then costs no compile. It must outlive this one.
     * NULL: its own. */
    const struct lr_renderer *programs_of;
} lr_renderer_desc;


typedef struct lr_frame_stats {
    int index;                   /* frames rendered since create */
    unsigned passes;             /* LR_PASS_* bits that ran this frame */
    double ms[LR_PASS_COUNT];    /* per pass, GPU time when timer queries exist, else CPU+finish */
    double total_ms;
    int samples;                 /* radiosity frames accumulated in the maps after this frame */
    bool converged;              /* samples reached render.frames, or 1 where deterministic */
    /* The maps' every frame is the same (no object's B is sampled per frame, no area light
     * is sampled per frame): they converged after their first frame, and further frames
     * cannot change the image (render/README.md, "When accumulation stops"). */
    bool deterministic;
    double time_s;               /* the clock the frame was composed at (0 without one) */
    size_t gpu_bytes;            /* lr_renderer_gpu_bytes after the frame */
} lr_frame_stats;

int lr_renderer_create(const lr_renderer_desc *desc, lr_renderer **out, lr_err *e);
void lr_renderer_destroy(lr_renderer *r);

/* The renderer's clock in seconds, given by the caller (`lamprig render`: frame index / fps;
 * `lamprig run`: the wall clock since start; tests: any value, so frames are reproducible).
 * Each light's flicker (lr_light.flicker) scales its intensity by lr_light_flicker_at(light,
 * t): band-limited noise around flicker.frequency_hz (three seeded sines), mean 1, within
 * 1 +- amplitude. It enters at composition only, like a dimmer: a new time with a flickering
 * light (amplitude > 0, intensity > 0) marks composition due and never restarts accumulation.
 * Until the first call the lights are steady (factor 1), as in the CPU twin and the physical
 * reference. Position jitter (flicker.jitter_mm) is not rendered: the transport is computed at
 * the light's mean position, because the sway (candle.json: 0.3 mm) is far below the
 * diffusion length 1/sigma_tr of wax (8-17 mm), so it changes the emergent light by ~sigma_tr
 * jitter <= 4 %, and the direct light on receivers hundreds of mm away by ~2 jitter / d < 0.3 %;
 * re-running the light G-buffer and maps for it would restart accumulation at every frame.
 * A caller that wants a large sway moves the light through lr_scene_set. */
void lr_renderer_set_time(lr_renderer *r, double t_seconds);
/* The factor on light l's intensity at the current clock: lr_light_flicker_at's, or 1 before
 * the first lr_renderer_set_time, for a steady light, or l out of range. */
double lr_renderer_flicker(const lr_renderer *r, int l);

/* Marks what changed (LR_DIRTY_* bits from lr_scene_set). */
void lr_renderer_invalidate(lr_renderer *r, unsigned dirty);
/* True while something is dirty or accumulation has not converged. */
bool lr_renderer_needs_frame(const lr_renderer *r);
/* Runs the passes that are due and leaves the image in the renderer's output target. */
int lr_renderer_frame(lr_renderer *r, lr_frame_stats *stats, lr_err *e);
/* A token lr_renderer_frame polls (NULL: never cancelled; render/base/cancel.h): between
 * passes, between the slices of the long GPU passes (render/passes/slice.h: each map and light
 * of the radiosity pass, each band of the irradiance grids; with a token set every slice end
 * waits for its GPU work, so a cut leaves at most one slice queued) and inside the CPU solves
 * they run (the diffusion grid's iterations, translucent radiosity's and the receiver bounce's
 * builds and sweeps). Once it is requested the frame returns LR_ECANCELED with nothing
 * composed and everything it would have done still due: the next frame (after the owner
 * resets the token) redoes it, and its image is the one an uninterrupted frame would have
 * given (to the solvers' tolerances: a cut solve's partial iterate is the next one's warm
 * start). A cut inside the radiosity pass (LR_CANCEL_RESTART or above only) restarts the
 * maps' accumulation instead: the image then converges to a fresh renderer's. The pointer
 * must stay valid until the renderer is destroyed or it is set again. For a caller that runs
 * the renderer on a thread of its own (render/async). */
void lr_renderer_set_cancel(lr_renderer *r, const lr_cancel *cancel);

/* With a token: the longest GPU passes end a slice about every `ms` (> 0; the rows of a band
 * sized from the last bands' times, render/passes/slice.h), so a change waits about that long
 * for the cut; 0 (the default): fixed bands (a map, 64 grid rows). The image is the same. */
void lr_renderer_set_slice_ms(lr_renderer *r, double ms);

/* Linear RGB radiance of the last frame, width*height*3 floats, rows bottom to top (PFM order). */
int lr_renderer_read_hdr(lr_renderer *r, float *rgb, lr_err *e);
/* Tone-mapped sRGB, width*height*4 bytes, rows top to bottom (PNG order). */
int lr_renderer_read_rgba8(lr_renderer *r, unsigned char *rgba, lr_err *e);
/* Draws the last frame to the context's default framebuffer (projector) and presents it. */
int lr_renderer_present(lr_renderer *r, lr_err *e);

/* The GPU memory (bytes) the renderer holds: what its context's textures and renderbuffers
 * (lr_gl_memory) gained since it was made, measured at each allocation and frame. */
size_t lr_renderer_gpu_bytes(const lr_renderer *r);

/* The per-light images of the last composition (render/passes/compose.h): a 2D array of
 * *n layers, layer l holding scale[l] times light l's unit-intensity linear radiance (the
 * blend weighs it by intensity x colour x flicker / scale[l]); NULL before the first
 * composition. For render/async/, which copies them to the caller's thread. scale has room
 * for LR_SCENE_MAX_LIGHTS values. */
const lr_tex *lr_renderer_images(const lr_renderer *r, int *n, float *scale);

/* One line naming the GL renderer, the map format (RGBA32F, or RGBA16F and why) and the
 * timer kind, for stats and logs. */
const char *lr_renderer_info(const lr_renderer *r);
/* Output size. */
void lr_renderer_size(const lr_renderer *r, int *width, int *height);
/* The tone mapping the output uses (exposure from render.exposure), so that a PNG written
 * from lr_renderer_read_hdr matches lr_renderer_read_rgba8. */
void lr_renderer_tonemap(const lr_renderer *r, lr_tonemap *tm);


#endif
