/* The renderer: the pass table, resources, scheduling by dirty flags (render/renderer.h,
 * render/schedule.h), per-pass timing, readback and presentation. The passes are in
 * render/passes/, each with its own state; this file holds them and hands each the inputs it
 * reads. */
#include "render/renderer.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/paths.h"
#include "render/gl/timer.h"
#include "render/models/model.h"
#include "render/passes/area_direct.h"
#include "render/passes/blend.h"
#include "render/passes/compose.h"
#include "render/passes/gbuffer.h"
#include "render/passes/irradiance.h"
#include "render/passes/passes.h"
#include "render/passes/radiosity.h"
#include "render/passes/surface.h"
#include "render/passes/vpl.h"
#include "render/renderer_parts.h"

#define STR_(x) #x
#define STR(x) STR_(x)

struct lr_renderer {
    lr_gl *gl;
    lr_scene *scene;
    int width, height;
    bool no_vpl;
    bool images_only; /* desc: no blend pass, the caller blends the per-light images */
    /* GPU memory (lr_gl_memory): the context's count when the renderer was made, what it has
     * gained since (the renderer's textures and renderbuffers), and the desc's budget. */
    size_t gpu_base, gpu_bytes, gpu_budget;
    bool vpl_visibility;
    unsigned seed;
    const lr_gl_caps *caps;
    lr_tex_format map_format; /* RGBA32F, or RGBA16F when float targets/blending are missing */
    char info[256];           /* renderer string for the stats */
    char shader_dir[512];
    lr_shader_defines defines; /* lr_passes_defines: every program is built with them */
    const lr_cancel *cancel;   /* lr_renderer_set_cancel; NULL: never */
    lr_slicer *slicer;         /* the long passes' slice ends (render/passes/slice.h) */
    lr_timer *timer;
    lr_pass_programs prog;
    bool borrowed_programs; /* prog is desc.programs_of's: not destroyed here */

    /* Settings the resources were made for, and the scene's lights then. */
    lr_render_settings rs;
    int n_lights;
    bool allocated;

    /* Meshes and per-object uniforms (re-uploaded when geometry, receivers or settings
     * change). */
    lr_pass_objects objs;

    /* The passes' own state, one per row of pass_table. */
    lr_gbuffer gbuffer;
    lr_radiosity rad;
    lr_vpl vpl;
    lr_irradiance irr;
    lr_surface surf;
    lr_compose img;
    lr_blend *blend; /* tone-mapped output and HDR sum (render/passes/blend.h) */
    /* Area lights' direct light on the plane receivers, accumulated with the maps
     * (render/passes/area_direct.h); unallocated without area lights. */
    lr_area_direct area;
    /* render.lpv: the light-propagation volume (render/passes/lpv_pass.h). */
    lr_lpv_pass lpv;

    unsigned dirty;
    int frame_index;
    /* render.surface_cache_moves: this frame is a camera move on converged maps, which
     * composes from the surface cache; `coarse`: the current images came from such a frame,
     * so the next frame without a camera change composes them again with the gather. */
    bool move_frame;
    bool coarse;

    /* The clock of lr_renderer_set_time (flicker at composition). */
    bool clock_set;
    double time_s;
};

/* The read-only inputs every pass gets (render/passes/passes.h). */
static lr_pass_ctx pass_ctx(const lr_renderer *r)
{
    lr_pass_ctx c = {.gl = r->gl, .caps = r->caps, .scene = r->scene, .rs = &r->rs,
                     .objs = &r->objs, .prog = &r->prog, .shader_dir = r->shader_dir,
                     .width = r->width, .height = r->height, .n_lights = r->n_lights,
                     .map_format = r->map_format, .seed = r->seed, .no_vpl = r->no_vpl,
                     .vpl_visibility = r->vpl_visibility || r->rs.vpl_visibility,
                     .cancel = r->cancel, .slicer = r->slicer};
    for (int l = 0; l < r->n_lights && l < LR_MAX_LIGHTS; l++) {
        lr_light_rgb(lr_scene_light_at(r->scene, l), c.I[l]);
        double f = lr_renderer_flicker(r, l);
        for (int b = 0; b < 3; b++)
            c.I[l][b] *= f;
    }
    return c;
}

/* A uniform a pass set that its program's shaders do not declare (lr_program_check). */
static int check_programs(lr_renderer *r, lr_err *e)
{
    lr_program *ps[] = {r->prog.surface, r->prog.depth, r->prog.radiosity, r->prog.vpl,
                        r->prog.obj,     r->prog.recv[0], r->prog.irr,
                        r->prog.area,
                        r->prog.cache,   r->prog.obj_cached[0], r->prog.obj_cached[1],
                        r->prog.obj_cached[2], r->prog.obj_cached[3], r->prog.recv[1],
                        r->prog.recv[2], r->prog.recv[3]};
    for (size_t i = 0; i < sizeof ps / sizeof ps[0]; i++) {
        int rc = ps[i] ? lr_program_check(ps[i], e) : LR_OK;
        if (rc)
            return rc;
    }
    return LR_OK;
}

/* ---- the pass table: each row's hooks hand its pass the inputs it reads ------------------- */

static int gbuffer_alloc(lr_renderer *r, lr_err *e)
{
    lr_pass_ctx c = pass_ctx(r);
    return lr_gbuffer_alloc(&r->gbuffer, &c, e);
}
static void gbuffer_free(lr_renderer *r) { lr_gbuffer_free(&r->gbuffer); }
/* An area light's G-buffer is redrawn at each accumulation frame's sample p_f
 * (render/area/frames.h): due while the maps accumulate. */
static bool gbuffer_due(const lr_renderer *r)
{
    return r->rad.F < r->rs.frames && lr_area_direct_needed(r->scene);
}
static int gbuffer_run(lr_renderer *r, unsigned dirty, lr_err *e)
{
    /* The frame the maps add next: 0 after a restart (lr_radiosity_run resets them). */
    bool restart = (lr_dirty_passes(dirty) & LR_PASS_RADIOSITY) != 0;
    long frame = restart ? 0 : r->rad.F;
    lr_pass_ctx c = pass_ctx(r);
    return lr_gbuffer_run(&r->gbuffer, &c, frame, e);
}

/* render.lpv > 0: the volume is on and, once built, read by the area pass and composition. */
static bool lpv_on(const lr_renderer *r) { return r->rs.lpv > 0; }
static const lr_lpv_pass *lpv_live(const lr_renderer *r)
{
    return lpv_on(r) && r->lpv.valid ? &r->lpv : NULL;
}
static void lpv_free(lr_renderer *r) { lr_lpv_pass_free(&r->lpv); }
static bool lpv_due(const lr_renderer *r) { return !r->lpv.valid; }
static int lpv_run(lr_renderer *r, unsigned dirty, lr_err *e)
{
    (void)dirty;
    lr_pass_ctx c = pass_ctx(r);
    return lr_lpv_pass_run(&r->lpv, &c, e);
}

static int radiosity_alloc(lr_renderer *r, lr_err *e)
{
    lr_pass_ctx c = pass_ctx(r);
    return lr_radiosity_alloc(&r->rad, &c, e);
}
/* New settings lay the GPU side out again; the CPU solvers' keyed states stay (a preview's
 * settings and back cost no grid, patch or form-factor rebuild): freed at destroy. */
static void radiosity_free(lr_renderer *r)
{
    lr_radiosity_release(&r->rad);
    lr_area_direct_free(&r->area);
}
/* Accumulating: render.frames not reached (capped for half-float maps). */
static bool radiosity_due(const lr_renderer *r) { return r->rad.F < r->rs.frames; }
static int radiosity_run(lr_renderer *r, unsigned dirty, lr_err *e)
{
    /* A change that makes the maps due restarts their running mean. */
    bool restart = (lr_dirty_passes(dirty) & LR_PASS_RADIOSITY) != 0;
    lr_pass_ctx c = pass_ctx(r);
    int rc = lr_radiosity_run(&r->rad, &c, &r->gbuffer, restart, e);
    /* The area lights' direct light: the same frame's sample, the same running mean. */
    if (!rc && lr_area_direct_pass_needed(r->scene))
        rc = lr_area_direct_run(&r->area, &c, &r->gbuffer, r->rad.F,
                                lpv_live(r) ? r->lpv.recv : NULL, e);
    return rc;
}

static int vpl_alloc(lr_renderer *r, lr_err *e)
{
    lr_pass_ctx c = pass_ctx(r);
    return r->no_vpl ? LR_OK : lr_vpl_alloc(&r->vpl, &c, e);
}
static void vpl_free(lr_renderer *r) { lr_vpl_free(&r->vpl); }
static int vpl_run(lr_renderer *r, unsigned dirty, lr_err *e)
{
    bool geometry = (dirty & (LR_DIRTY_GEOMETRY | LR_DIRTY_SETTINGS)) != 0;
    lr_pass_ctx c = pass_ctx(r);
    return lr_vpl_run(&r->vpl, &c, &r->rad, geometry, e);
}

/* The grids alone: the receiver bounce's F and rows and the openings' kernel are keyed on the
 * scene (about a second to rebuild on llvmpipe's machine): freed at destroy. */
static void irradiance_free(lr_renderer *r) { lr_irradiance_free_grids(&r->irr); }
/* render.irradiance_grid, or what only the grid carries: the receiver bounce, the opening
 * light, a patch-solve model's receiver light. */
static bool irradiance_on(const lr_renderer *r)
{
    if (r->rs.irradiance_grid || r->rs.receiver_bounce || r->rs.opening_light)
        return true;
    for (int i = 0; i < lr_scene_object_count(r->scene); i++)
        if (lr_sss_model_props_of(lr_scene_object_at(r->scene, i)->sss_model)->patch_solve)
            return true;
    return false;
}
static bool irradiance_due(const lr_renderer *r) { return !r->irr.valid && !r->no_vpl; }
static int irradiance_run(lr_renderer *r, unsigned dirty, lr_err *e)
{
    (void)dirty;
    lr_pass_ctx c = pass_ctx(r);
    return lr_irradiance_run(&r->irr, &c, &r->vpl, &r->rad, e);
}

static void surface_free(lr_renderer *r) { lr_surface_free(&r->surf); }
/* Whether this frame composes from the surface cache, and so whether the surface pass is on:
 * always with render.surface_cache; with render.surface_cache_moves only on a camera move
 * (drawn then if the maps changed since: the first move after a change pays for it). */
static bool cache_now(const lr_renderer *r) { return r->rs.surface_cache || r->move_frame; }
/* Not drawn yet, or drawn from other maps (accumulation went on while it was off). */
static bool surface_due(const lr_renderer *r)
{
    return !r->surf.valid || r->surf.gen != r->rad.gen;
}
static int surface_run(lr_renderer *r, unsigned dirty, lr_err *e)
{
    (void)dirty;
    lr_pass_ctx c = pass_ctx(r);
    int rc = lr_surface_run(&r->surf, &c, &r->rad, e);
    r->surf.gen = r->rad.gen;
    return rc;
}

static int compose_alloc(lr_renderer *r, lr_err *e)
{
    lr_pass_ctx c = pass_ctx(r);
    return lr_compose_alloc(&r->img, &c, e);
}
static void compose_free(lr_renderer *r) { lr_compose_free(&r->img); }
/* The images are composed for as many lights as the scene has now. */
static bool compose_due(const lr_renderer *r)
{
    return !r->img.valid || (r->coarse && !r->move_frame);
}
static int compose_run(lr_renderer *r, unsigned dirty, lr_err *e)
{
    (void)dirty;
    lr_pass_ctx c = pass_ctx(r);
    /* The grid off: what it holds is of an earlier state, and composition gathers the VPLs
     * per receiver pixel (u_cached false); drawn again when it comes back on (due). */
    if (!irradiance_on(r))
        r->irr.valid = false;
    lr_compose_inputs in = {.gbuffer = &r->gbuffer, .radiosity = &r->rad, .vpl = &r->vpl,
                            .irradiance = &r->irr, .area = &r->area, .lpv = lpv_live(r),
                            .surface = cache_now(r) && r->surf.valid ? &r->surf : NULL};
    int rc = lr_compose_run(&r->img, &c, &in, e);
    r->coarse = !rc && in.surface && !r->rs.surface_cache;
    return rc;
}

static int blend_alloc(lr_renderer *r, lr_err *e)
{
    lr_blend_desc bd = {.gl = r->gl, .width = r->width, .height = r->height,
                        .shader_dir = r->shader_dir, .defines = r->defines.list};
    return lr_blend_create(&bd, &r->blend, e);
}
static void blend_free(lr_renderer *r)
{
    lr_blend_destroy(r->blend);
    r->blend = NULL;
}
static bool blend_on(const lr_renderer *r) { return !r->images_only; }
/* The per-light images weighted by intensity x colour x flicker (PIPELINE.md "Blend"). */
static int blend_run(lr_renderer *r, unsigned dirty, lr_err *e)
{
    (void)dirty;
    lr_pass_ctx c = pass_ctx(r);
    lr_blend_input in = {.images = r->img.images, .n = r->img.n,
                         .exposure = (float)r->rs.exposure, .tonemap_op = LR_RENDER_TONEMAP};
    for (int l = 0; l < r->img.n && l < LR_BLEND_MAX_IMAGES && l < LR_MAX_LIGHTS; l++)
        for (int b = 0; b < 3; b++)
            in.w[l][b] = c.I[l][b] / r->img.scale[l]; /* the images hold scale[l] L_l */
    return lr_blend_run(r->blend, &in, e);
}

/* What each scene change makes due (docs/ARCHITECTURE.md "Data flow"; render/schedule.c says why). */
enum {
    D_TRANSPORT = LR_DIRTY_LIGHT_GEOMETRY | LR_DIRTY_GEOMETRY | LR_DIRTY_SETTINGS,
    D_MAPS = D_TRANSPORT | LR_DIRTY_MATERIAL,
    D_GRIDS = D_MAPS | LR_DIRTY_RECEIVERS,
    D_VIEW = D_GRIDS | LR_DIRTY_CAMERA,
    D_OUTPUT = D_VIEW | LR_DIRTY_INTENSITY | LR_DIRTY_DISPLAY,
};

/* The passes in the order they run. */
static const lr_pass_desc pass_table[LR_PASS_COUNT] = {
    {"gbuffer", LR_PASS_GBUFFER, D_TRANSPORT, 0, false, gbuffer_alloc, gbuffer_free, gbuffer_due,
     gbuffer_run, NULL},
    {"lpv", LR_PASS_LPV, D_GRIDS, LR_PASS_COMPOSE, false, NULL, lpv_free, lpv_due, lpv_run,
     lpv_on},
    {"radiosity", LR_PASS_RADIOSITY, D_MAPS, LR_PASS_VPL | LR_PASS_SURFACE | LR_PASS_COMPOSE,
     false, radiosity_alloc, radiosity_free, radiosity_due, radiosity_run, NULL},
    {"vpl", LR_PASS_VPL, D_MAPS, LR_PASS_IRRADIANCE, true, vpl_alloc, vpl_free, NULL, vpl_run, NULL},
    {"irradiance", LR_PASS_IRRADIANCE, D_GRIDS, LR_PASS_COMPOSE, true, NULL, irradiance_free,
     irradiance_due, irradiance_run, irradiance_on},
    {"surface", LR_PASS_SURFACE, D_MAPS, LR_PASS_COMPOSE, false, NULL, surface_free,
     surface_due, surface_run, cache_now},
    {"compose", LR_PASS_COMPOSE, D_VIEW, LR_PASS_BLEND, false, compose_alloc, compose_free,
     compose_due, compose_run, NULL},
    {"blend", LR_PASS_BLEND, D_OUTPUT, 0, false, blend_alloc, blend_free, NULL, blend_run,
     blend_on},
};

const lr_pass_desc *lr_pass_table(void)
{
    return pass_table;
}

static int program(lr_renderer *r, const char *vert, const char *frag, lr_program **out, lr_err *e)
{
    lr_program_desc d = {.vertex = vert, .fragment = frag, .dir = r->shader_dir,
                         .defines = r->defines.list};
    return lr_program_create(&d, out, e);
}

/* The shader directory (render/base/paths.h: $LAMPRIG_SHADERS, the source tree's or the
 * installed prefix's). */
static int find_shaders(lr_renderer *r, lr_err *e)
{
    if (lr_shaders_dir(r->shader_dir, sizeof r->shader_dir) != 0)
        return lr_err_set(e, LR_EINVAL, "shader directory path too long (configs: %s)",
                          lr_configs_dir());
    return LR_OK;
}

static void free_resources(lr_renderer *r)
{
    for (int i = 0; i < LR_PASS_COUNT; i++)
        if (pass_table[i].free)
            pass_table[i].free(r);
    r->allocated = false;
}

static int settings_check(const lr_renderer *r, const lr_render_settings *rs, lr_err *e)
{
    int maxs = r->caps->max_texture_size;
    if (rs->K < 1 || rs->K > LR_MAX_K)
        return lr_err_set(e, LR_EUNSUPPORTED, "render.K = %d: the renderer takes 1..%d maps", rs->K,
                          LR_MAX_K);
    if (rs->map_size < 1 || rs->map_size > maxs || rs->gbuffer_size < 1 ||
        rs->gbuffer_size > r->caps->max_cube_map_size || rs->vpl_map_size < 1 ||
        rs->vpl_map_size > r->caps->max_cube_map_size)
        return lr_err_set(e, LR_EUNSUPPORTED, "render: map sizes %d/%d/%d beyond the driver's %d",
                          rs->map_size, rs->gbuffer_size, rs->vpl_map_size, maxs);
    if (rs->N < 1 || rs->frames < 1)
        return lr_err_set(e, LR_EINVAL, "render: N = %d, frames = %d: must be >= 1", rs->N, rs->frames);
    return LR_OK;
}

/* The renderer's GPU memory now, against the budget: a board's GPU shares its RAM, so settings
 * that would take more than the rig allows are refused with what they need. */
static int check_memory(lr_renderer *r, lr_err *e)
{
    size_t now;
    lr_gl_memory(r->gl, &now, NULL);
    r->gpu_bytes = now > r->gpu_base ? now - r->gpu_base : 0;
    if (!r->gpu_budget || r->gpu_bytes <= r->gpu_budget)
        return LR_OK;
    return lr_err_set(e, LR_ENOMEM, "renderer: the settings need %.1f MB of GPU memory (render.K "
                      "%d maps of %d^2 per light, G-buffers %d^2, VPL maps %d^2, %d lights, "
                      "%dx%d output), over the budget of %.1f MB (gpu_memory_mb)",
                      r->gpu_bytes / 1048576.0, r->rs.K, r->rs.map_size, r->rs.gbuffer_size,
                      r->rs.vpl_map_size, r->n_lights, r->width, r->height,
                      r->gpu_budget / 1048576.0);
}

static int alloc_resources(lr_renderer *r, lr_err *e)
{
    free_resources(r);
    r->rs = *lr_scene_render(r->scene);
    int rc = settings_check(r, &r->rs, e);
    int nl = lr_scene_light_count(r->scene);
    if (!rc && nl > LR_MAX_LIGHTS)
        rc = lr_err_set(e, LR_EUNSUPPORTED, "renderer: %d lights; at most %d", nl, LR_MAX_LIGHTS);
    if (!rc)
        rc = lr_area_direct_check(r->scene, e);
    if (!rc)
        r->n_lights = nl;
    for (int i = 0; i < LR_PASS_COUNT && !rc; i++)
        if (pass_table[i].alloc)
            rc = pass_table[i].alloc(r, e);
    if (!rc)
        rc = check_memory(r, e);
    if (rc) {
        free_resources(r);
        return rc;
    }
    r->allocated = true;
    return LR_OK;
}

int lr_renderer_create(const lr_renderer_desc *desc, lr_renderer **out, lr_err *e)
{
    *out = NULL;
    if (!desc || !desc->gl || !desc->scene)
        return lr_err_set(e, LR_EINVAL, "renderer: a GL context and a scene are required");
    int w = desc->width ? desc->width : 640, h = desc->height ? desc->height : 480;
    const lr_gl_caps *caps = lr_gl_caps_get(desc->gl);
    if (w < 1 || h < 1 || w > caps->max_texture_size || h > caps->max_texture_size)
        return lr_err_set(e, LR_EINVAL, "renderer: image size %d x %d: must be 1..%d", w, h,
                          caps->max_texture_size);
    if (lr_scene_light_count(desc->scene) < 1 || lr_scene_object_count(desc->scene) < 1)
        return lr_err_set(e, LR_EINVAL, "renderer: scene %s needs a light and an object",
                          lr_scene_name(desc->scene));
    /* Area lights: the passes sample them frame by frame (render/area/frames.h); their
     * direct light is accumulated on plane receivers only (render/passes/area_direct.h). */
    int rc = lr_area_direct_check(desc->scene, e);
    if (rc)
        return rc;
    rc = lr_gl_caps_require(caps, LR_GL_NEED_FLOAT_RT, e);
    if (rc)
        return lr_err_prefix(e, "renderer (positions, normals and the HDR output are RGBA32F)");
    lr_renderer *r = calloc(1, sizeof *r);
    if (!r)
        return lr_err_set(e, LR_ENOMEM, "renderer: out of memory");
    r->gl = desc->gl;
    r->scene = desc->scene;
    r->width = w;
    r->height = h;
    r->no_vpl = desc->no_vpl;
    r->images_only = desc->images_only;
    lr_gl_memory(desc->gl, &r->gpu_base, NULL);
    r->gpu_budget = (size_t)(desc->gpu_budget_mb * 1048576.0);
    r->vpl_visibility = desc->vpl_visibility;
    r->seed = desc->seed ? desc->seed : 1;
    r->caps = caps;
    const char *maps = "RGBA32F maps";
    r->map_format = LR_TEX_RGBA32F;
    if (desc->half_maps) {
        r->map_format = LR_TEX_RGBA16F;
        maps = "RGBA16F maps (asked for; accumulation capped at " STR(LR_HALF_MAX_FRAMES) " frames)";
    } else if (!caps->float_blend) {
        /* Accumulation blends into the maps: without EXT_float_blend, half floats. */
        r->map_format = LR_TEX_RGBA16F;
        maps = "RGBA16F maps (EXT_float_blend missing; accumulation capped at " STR(
            LR_HALF_MAX_FRAMES) " frames)";
    }
    lr_passes_defines(&r->defines);
    if ((rc = find_shaders(r, e)))
        goto fail;
    if ((rc = lr_timer_create(r->gl, NULL, &r->timer, e)) || (rc = lr_slicer_create(&r->slicer, e)))
        goto fail;
    snprintf(r->info, sizeof r->info, "%s; %s; %s timers", caps->renderer, maps,
             lr_timer_is_gpu(r->timer) ? "GPU" : "CPU+glFinish");
    lr_pass_programs *pr = &r->prog;
    if (desc->programs_of) {
        *pr = desc->programs_of->prog;
        r->borrowed_programs = true;
    } else if ((rc = program(r, "mesh.vert", "surface.frag", &pr->surface, e)) ||
        (rc = program(r, "mesh.vert", "depth.frag", &pr->depth, e)) ||
        (rc = program(r, "radiosity.vert", "radiosity.frag", &pr->radiosity, e)) ||
        (rc = program(r, "fullscreen.vert", "vpl.frag", &pr->vpl, e)) ||
        (rc = program(r, "compose_object.vert", "compose_object.frag", &pr->obj, e)) ||
        (rc = program(r, "fullscreen.vert", "irradiance.frag", &pr->irr, e)) ||
        (rc = program(r, "fullscreen.vert", "area_direct.frag", &pr->area, e)) ||
        (rc = program(r, "fullscreen.vert", "surface_cache.frag", &pr->cache, e)))
        goto fail;
    if (!r->borrowed_programs) {
        /* Composition from the surface cache and of the receivers, one program per light count
         * (LR_CACHE_LIGHTS, LR_RECV_LIGHTS): llvmpipe runs a loop's body for every light up to
         * the bound whatever u_n_lights says (a camera move's receivers cost 1.8x for one light
         * with the bound at 4, tools/bench/README.md "Camera move, profiled"). */
        for (int n = 1; n <= LR_MAX_LIGHTS; n++) {
            lr_shader_defines d;
            lr_shader_defines_copy(&d, &r->defines);
            if (!lr_shader_defines_add(&d, "LR_CACHE_LIGHTS", n) ||
                !lr_shader_defines_add(&d, "LR_RECV_LIGHTS", n)) {
                rc = lr_err_set(e, LR_EINVAL, "renderer: too many shader defines");
                goto fail;
            }
            lr_program_desc pd = {.vertex = "compose_cached.vert",
                                  .fragment = "compose_cached.frag", .dir = r->shader_dir,
                                  .defines = d.list};
            lr_program_desc pr_d = {.vertex = "mesh.vert", .fragment = "compose_receiver.frag",
                                    .dir = r->shader_dir, .defines = d.list};
            if ((rc = lr_program_create(&pd, &pr->obj_cached[n - 1], e)) ||
                (rc = lr_program_create(&pr_d, &pr->recv[n - 1], e)))
                goto fail;
        }
    }
    if ((rc = alloc_resources(r, e)) || (rc = lr_pass_objects_upload(&r->objs, r->scene, e)))
        goto fail;
    /* Warm-up section: llvmpipe's first time-elapsed query reports time since the context
     * was made (seconds), not the section; one throw-away query absorbs that. */
    if (!lr_timer_begin(r->timer, "warmup", NULL)) {
        lr_fb_bind(lr_blend_ldr_fb(r->blend));
        glClear(GL_COLOR_BUFFER_BIT);
        lr_timer_end(r->timer, NULL);
        lr_timer_collect(r->timer, NULL);
        lr_timer_reset(r->timer);
    }
    r->dirty = LR_DIRTY_SETTINGS; /* everything */
    *out = r;
    return LR_OK;
fail:
    lr_renderer_destroy(r);
    return rc;
}

void lr_renderer_destroy(lr_renderer *r)
{
    if (!r)
        return;
    free_resources(r);
    lr_radiosity_free(&r->rad);
    lr_irradiance_free(&r->irr);
    lr_pass_objects_free(&r->objs);
    const lr_pass_programs *pr = &r->prog;
    lr_program *ps[] = {pr->surface,       pr->depth,         pr->radiosity,     pr->vpl,
                        pr->obj,           pr->recv[0],       pr->irr,
                        pr->cache,         pr->obj_cached[0], pr->obj_cached[1],
                        pr->obj_cached[2], pr->obj_cached[3], pr->area,
                        pr->recv[1],       pr->recv[2],       pr->recv[3]};
    for (size_t i = 0; i < sizeof ps / sizeof ps[0] && !r->borrowed_programs; i++)
        lr_program_destroy(ps[i]);
    lr_timer_destroy(r->timer);
    lr_slicer_destroy(r->slicer);
    free(r);
}

/* Whether light l's intensity changes with time. */
void lr_renderer_set_time(lr_renderer *r, double t_seconds)
{
    if (!isfinite(t_seconds) || (r->clock_set && t_seconds == r->time_s))
        return;
    for (int l = 0; l < lr_scene_light_count(r->scene); l++)
        if (lr_light_flickers(lr_scene_light_at(r->scene, l)))
            r->dirty |= LR_DIRTY_INTENSITY; /* the blend alone (transport is linear) */
    r->clock_set = true;
    r->time_s = t_seconds;
}

double lr_renderer_flicker(const lr_renderer *r, int l)
{
    if (!r->clock_set || l < 0 || l >= lr_scene_light_count(r->scene))
        return 1.0;
    const lr_light *light = lr_scene_light_at(r->scene, l);
    if (!(light->flicker.amplitude > 0.0))
        return 1.0;
    double f;
    lr_light_flicker_at(light, r->time_s, &f, NULL);
    return f;
}

void lr_renderer_invalidate(lr_renderer *r, unsigned dirty)
{
    r->dirty |= dirty;
}

/* Whether the accumulated maps are deterministic: made (since their last restart) without a
 * per-frame sample. The frame-seeded estimator (lr_radiosity.sampled) and an area light's
 * point p_f (render/area/frames.h: the G-buffer, the maps and the receivers' direct grid
 * move with it) are the only inputs that change from one accumulation frame to the next;
 * the VPLs (fixed directions), the receivers' grids, the bounce, the openings' light and
 * composition are functions of the maps. */
static bool maps_deterministic(const lr_renderer *r)
{
    return r->rad.F > 0 && !r->rad.sampled && !lr_area_direct_needed(r->scene);
}

/* Frames to accumulate: render.frames, capped for half-float maps (LR_HALF_MAX_FRAMES); 1
 * for deterministic maps, whose every further frame would redraw the same values (issue 33:
 * the grid, translucent radiosity and SH redrew one image render.frames times). */
static int frames_target(const lr_renderer *r)
{
    int f = lr_scene_render(r->scene)->frames;
    if (maps_deterministic(r))
        return 1;
    return r->map_format == LR_TEX_RGBA16F && f > LR_HALF_MAX_FRAMES ? LR_HALF_MAX_FRAMES : f;
}

bool lr_renderer_needs_frame(const lr_renderer *r)
{
    /* images_only: what only the blend reads (D_OUTPUT over D_VIEW) is the caller's. */
    unsigned d = r->images_only ? r->dirty & ~(unsigned)(D_OUTPUT & ~D_VIEW) : r->dirty;
    return d != 0 || r->rad.F < frames_target(r) || r->coarse;
}

static bool resources_stale(const lr_renderer *r)
{
    const lr_render_settings *s = lr_scene_render(r->scene);
    return !r->allocated || s->K != r->rs.K || s->map_size != r->rs.map_size ||
           s->gbuffer_size != r->rs.gbuffer_size || s->vpl_map_size != r->rs.vpl_map_size ||
           s->N_vpl != r->rs.N_vpl;
}

int lr_renderer_frame(lr_renderer *r, lr_frame_stats *stats, lr_err *e)
{
    int rc;
    unsigned dirty = r->dirty;
    if (dirty & (LR_DIRTY_RECEIVERS | LR_DIRTY_LIGHT_GEOMETRY | LR_DIRTY_SETTINGS)) {
        if ((rc = lr_area_direct_check(r->scene, e)))
            return rc;
        /* The area lights' direct grid is a running mean over the map frames: new receivers
         * accumulate it again from the first frame, with the maps. */
        if ((dirty & LR_DIRTY_RECEIVERS) && lr_area_direct_pass_needed(r->scene)) {
            dirty |= LR_DIRTY_LIGHT_GEOMETRY;
            lr_area_direct_free(&r->area);
        }
    }
    unsigned passes = lr_dirty_passes(dirty);
    bool restart = (passes & LR_PASS_RADIOSITY) != 0;
    if (dirty & LR_DIRTY_SETTINGS) {
        if (resources_stale(r)) {
            if ((rc = alloc_resources(r, e)))
                return rc;
        } else {
            r->rs = *lr_scene_render(r->scene);
            if ((rc = settings_check(r, &r->rs, e)))
                return rc;
        }
    }
    r->rs.exposure = lr_scene_render(r->scene)->exposure;
    r->rs.frames = frames_target(r);
    r->rs.N = lr_scene_render(r->scene)->N;
    /* Turning render.surface_cache off is a view-class change too, but not a move. */
    bool was_cached = r->rs.surface_cache;
    r->rs.surface_cache = lr_scene_render(r->scene)->surface_cache;
    r->rs.surface_cache_moves = lr_scene_render(r->scene)->surface_cache_moves;
    /* A camera move on converged maps (nothing that restarts them, nothing left to
     * accumulate) composes from the surface cache (render/README.md "Camera moves"). */
    r->move_frame = r->rs.surface_cache_moves && !r->rs.surface_cache && !was_cached &&
                    (dirty & LR_DIRTY_CAMERA) && !(passes & LR_PASS_RADIOSITY) &&
                    !radiosity_due(r);
    /* The refined meshes depend on the geometry, sigma_tr and the map size (surface.h). */
    if (dirty & (LR_DIRTY_GEOMETRY | LR_DIRTY_SETTINGS | LR_DIRTY_MATERIAL))
        lr_surface_invalidate_geometry(&r->surf);
    if (dirty & (LR_DIRTY_GEOMETRY | LR_DIRTY_SETTINGS | LR_DIRTY_RECEIVERS | LR_DIRTY_MATERIAL)) {
        if ((rc = lr_pass_objects_upload(&r->objs, r->scene, e)))
            return rc;
        /* Receivers may have changed kind: grids laid out again (the bounce's and the
         * openings' own state stays: keyed, it rebuilds only what changed). */
        lr_irradiance_free_grids(&r->irr);
    }
    lr_pass_objects_update_coeffs(&r->objs, r->scene);
    /* The cavity gain depends on the light, the geometry and the material: measured (a few
     * ms on the CPU) whenever the maps restart. */
    if (restart && (rc = lr_pass_objects_update_cavity(&r->objs, r->scene, e)))
        return rc;
    /* Accumulation frames update the maps, then what reads them (the table's due and
     * feeds). */
    passes = lr_schedule_close(r, passes, r->no_vpl);

    lr_frame_stats st = {0};
    lr_timer_reset(r->timer);
    for (int i = 0; i < LR_PASS_COUNT; i++) {
        const lr_pass_desc *p = &pass_table[i];
        if (!(passes & p->bit))
            continue;
        /* A frame cut short keeps r->dirty as it came in: the next frame redoes every pass
         * this one would have run (the passes' own caches keep what was complete). */
        if ((rc = lr_cancel_check(r->cancel, "renderer: frame", e)))
            return rc;
        if ((rc = lr_timer_begin(r->timer, p->name, e)))
            return rc;
        rc = p->run(r, dirty, e);
        if (!rc)
            rc = check_programs(r, e);
        int rc2 = lr_timer_end(r->timer, e);
        if (rc || (rc = rc2))
            return rc;
    }
    /* A disjoint GPU clock only spoils this frame's times (NaN); the frame itself is fine. */
    int trc = lr_timer_collect(r->timer, NULL);
    for (int s = 0; s < lr_timer_count(r->timer); s++)
        for (int i = 0; i < LR_PASS_COUNT; i++)
            if (!strcmp(lr_timer_name(r->timer, s), lr_pass_name(i))) {
                st.ms[i] = trc ? NAN : lr_timer_ms(r->timer, s);
                st.total_ms += st.ms[i];
            }
    r->dirty = 0;
    /* A restart this frame may have found the maps deterministic: the target after it. */
    r->rs.frames = frames_target(r);
    /* Passes that make their textures at their first run (grids, LPV) count too. */
    if ((rc = check_memory(r, e)))
        return rc;
    st.gpu_bytes = r->gpu_bytes;
    st.index = r->frame_index++;
    st.passes = passes;
    st.samples = r->rad.F;
    st.converged = r->rad.F >= r->rs.frames;
    st.deterministic = maps_deterministic(r);
    st.time_s = r->clock_set ? r->time_s : 0.0;
    if (stats)
        *stats = st;
    return LR_OK;
}

int lr_renderer_read_hdr(lr_renderer *r, float *rgb, lr_err *e)
{
    if (r->images_only)
        return lr_err_set(e, LR_EINVAL, "renderer: made images_only (the caller blends "
                          "lr_renderer_images): no output image of its own");
    if (!r->blend)
        return lr_err_set(e, LR_EINVAL, "renderer: no image (resources failed to allocate)");
    return lr_blend_read_hdr(r->blend, rgb, e);
}

int lr_renderer_read_rgba8(lr_renderer *r, unsigned char *out, lr_err *e)
{
    if (r->images_only)
        return lr_err_set(e, LR_EINVAL, "renderer: made images_only (the caller blends "
                          "lr_renderer_images): no output image of its own");
    if (!r->blend)
        return lr_err_set(e, LR_EINVAL, "renderer: no image (resources failed to allocate)");
    return lr_blend_read_rgba8(r->blend, out, e);
}

int lr_renderer_present(lr_renderer *r, lr_err *e)
{
    if (r->images_only)
        return lr_err_set(e, LR_EINVAL, "renderer: made images_only (the caller blends "
                          "lr_renderer_images): no output image of its own");
    if (!r->blend)
        return lr_err_set(e, LR_EINVAL, "renderer: no image (resources failed to allocate)");
    return lr_blend_present(r->blend, e);
}

size_t lr_renderer_gpu_bytes(const lr_renderer *r) { return r->gpu_bytes; }

const lr_tex *lr_renderer_images(const lr_renderer *r, int *n, float *scale)
{
    if (!r->img.valid || !r->img.images) {
        *n = 0;
        return NULL;
    }
    *n = r->img.n;
    for (int l = 0; l < r->img.n && l < LR_MAX_LIGHTS; l++)
        scale[l] = r->img.scale[l];
    return r->img.images;
}

void lr_renderer_set_cancel(lr_renderer *r, const lr_cancel *cancel)
{
    r->cancel = cancel;
    lr_slicer_set_cancel(r->slicer, cancel);
}

void lr_renderer_set_slice_ms(lr_renderer *r, double ms) { lr_slicer_set_budget(r->slicer, ms); }

const char *lr_renderer_info(const lr_renderer *r)
{
    return r->info;
}

void lr_renderer_size(const lr_renderer *r, int *width, int *height)
{
    if (width)
        *width = r->width;
    if (height)
        *height = r->height;
}

void lr_renderer_tonemap(const lr_renderer *r, lr_tonemap *tm)
{
    tm->op = LR_RENDER_TONEMAP;
    tm->exposure = (float)lr_scene_render(r->scene)->exposure;
}

void lr_renderer_parts_get(const lr_renderer *r, lr_renderer_parts *out)
{
    *out = (lr_renderer_parts){.gl = r->gl, .timer = r->timer, .slicer = r->slicer,
                               .shader_dir = r->shader_dir,
                               .defines = r->defines.list,
                               .width = r->width, .height = r->height, .seed = r->seed,
                               .rs = &r->rs, .objs = &r->objs, .gbuffer = &r->gbuffer,
                               .radiosity = &r->rad, .vpl = &r->vpl, .compose = &r->img,
                               .surface = &r->surf, .irradiance = &r->irr, .blend = r->blend};
}
