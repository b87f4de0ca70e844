/* The renderer: resources, scheduling by dirty flags (render/renderer.h), per-pass timing,
 * readback and presentation. The passes are in render/passes/. */
#include "render/renderer.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/paths.h"
#include "render/passes/passes.h"

#define STR_(x) #x
#define STR(x) STR_(x)

static const char *const pass_names[LR_PASS_COUNT] = {"gbuffer", "radiosity", "vpl", "compose",
                                                      "blend",   "irradiance"};
/* The order the passes run in (bit indices). */
static const int pass_order[LR_PASS_COUNT] = {0, 1, 2, 5, 3, 4};

const char *lr_pass_name(int index)
{
    return index >= 0 && index < LR_PASS_COUNT ? pass_names[index] : "?";
}

static int program(lr_renderer *r, const char *vert, const char *frag, lr_program **out, lr_err *e)
{
    lr_program_desc d = {.vertex = vert, .fragment = frag, .dir = r->shader_dir,
                         .defines = lr_passes_defines()};
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
    lr_gbuffer_free(r);
    lr_radiosity_free(r);
    lr_vpl_free(r);
    lr_compose_free(r);
    lr_irradiance_free(r);
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

static int alloc_resources(lr_renderer *r, lr_err *e)
{
    free_resources(r);
    r->rs = *lr_scene_render(r->scene);
    int rc = settings_check(r, &r->rs, e);
    if (rc || (rc = lr_gbuffer_alloc(r, e)) || (rc = lr_radiosity_alloc(r, e)) ||
        (!r->no_vpl && (rc = lr_vpl_alloc(r, e))) || (rc = lr_compose_alloc(r, e))) {
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
    int rc = lr_gl_caps_require(caps, LR_GL_NEED_FLOAT_RT, e);
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
    if ((rc = find_shaders(r, e)))
        goto fail;
    if ((rc = lr_timer_create(r->gl, NULL, &r->timer, e)))
        goto fail;
    snprintf(r->info, sizeof r->info, "%s; %s; %s timers", caps->renderer, maps,
             lr_timer_is_gpu(r->timer) ? "GPU" : "CPU+glFinish");
    if ((rc = program(r, "mesh.vert", "surface.frag", &r->p_surface, e)) ||
        (rc = program(r, "mesh.vert", "depth.frag", &r->p_depth, e)) ||
        (rc = program(r, "mesh.vert", "radiosity.frag", &r->p_radiosity, e)) ||
        (rc = program(r, "fullscreen.vert", "vpl.frag", &r->p_vpl, e)) ||
        (rc = program(r, "mesh.vert", "compose_object.frag", &r->p_obj, e)) ||
        (rc = program(r, "mesh.vert", "compose_receiver.frag", &r->p_recv, e)) ||
        (rc = program(r, "fullscreen.vert", "blit.frag", &r->p_blit, e)) ||
        (rc = program(r, "fullscreen.vert", "irradiance.frag", &r->p_irr, e)))
        goto fail;
    if ((rc = alloc_resources(r, e)) || (rc = lr_passes_upload_meshes(r, e)))
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
    lr_passes_free_meshes(r);
    lr_program *ps[] = {r->p_surface, r->p_depth, r->p_radiosity, r->p_vpl,
                        r->p_obj,     r->p_recv,  r->p_blit,      r->p_irr};
    for (size_t i = 0; i < sizeof ps / sizeof ps[0]; i++)
        lr_program_destroy(ps[i]);
    lr_timer_destroy(r->timer);
    free(r);
}

/* Whether light l's intensity changes with time. */
static bool flickers(const lr_light *l)
{
    return l->flicker.amplitude > 0.0 && l->intensity > 0.0;
}

void lr_renderer_set_time(lr_renderer *r, double t_seconds)
{
    if (!isfinite(t_seconds) || (r->clock_set && t_seconds == r->time_s))
        return;
    for (int l = 0; l < lr_scene_light_count(r->scene); l++)
        if (flickers(lr_scene_light_at(r->scene, l)))
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

/* Frames to accumulate: render.frames, capped for half-float maps (LR_HALF_MAX_FRAMES). */
static int frames_target(const lr_renderer *r)
{
    int f = lr_scene_render(r->scene)->frames;
    return r->map_format == LR_TEX_RGBA16F && f > LR_HALF_MAX_FRAMES ? LR_HALF_MAX_FRAMES : f;
}

bool lr_renderer_needs_frame(const lr_renderer *r)
{
    return r->dirty != 0 || r->rad.F < frames_target(r);
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
    unsigned passes = lr_dirty_passes(dirty);
    bool restart = (passes & LR_PASS_RADIOSITY) != 0;
    bool geometry = (dirty & (LR_DIRTY_GEOMETRY | LR_DIRTY_SETTINGS)) != 0;
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
    if (dirty & (LR_DIRTY_GEOMETRY | LR_DIRTY_SETTINGS | LR_DIRTY_RECEIVERS | LR_DIRTY_MATERIAL)) {
        if ((rc = lr_passes_upload_meshes(r, e)))
            return rc;
        lr_irradiance_free(r); /* receivers may have changed kind: grids laid out again */
    }
    lr_passes_update_coeffs(r);
    /* The cavity gain depends on the light, the geometry and the material: measured (a few
     * ms on the CPU) whenever the maps restart. */
    if (restart && (rc = lr_passes_update_cavity(r, e)))
        return rc;
    /* Accumulation frames update the per-light images with the new maps (then the blend). */
    if (!restart && r->rad.F < r->rs.frames)
        passes |= LR_PASS_RADIOSITY | LR_PASS_VPL | LR_PASS_COMPOSE;
    if (passes & LR_PASS_RADIOSITY)
        passes |= LR_PASS_VPL | LR_PASS_COMPOSE;
    /* New VPL radiosity: the receivers' grids again. */
    if (passes & LR_PASS_VPL)
        passes |= LR_PASS_IRRADIANCE;
    if (!r->irr.valid && !r->no_vpl)
        passes |= LR_PASS_IRRADIANCE;
    if (passes & LR_PASS_IRRADIANCE)
        passes |= LR_PASS_COMPOSE;
    /* The images are composed for as many lights as the scene has now. */
    if (!r->img.valid)
        passes |= LR_PASS_COMPOSE;
    if (passes & LR_PASS_COMPOSE)
        passes |= LR_PASS_BLEND;
    if (r->no_vpl)
        passes &= ~(unsigned)(LR_PASS_VPL | LR_PASS_IRRADIANCE);

    lr_frame_stats st = {0};
    lr_timer_reset(r->timer);
    for (int oi = 0; oi < LR_PASS_COUNT; oi++) {
        int i = pass_order[oi];
        if (!(passes & (1u << i)))
            continue;
        if ((rc = lr_timer_begin(r->timer, pass_names[i], e)))
            return rc;
        switch (1u << i) {
        case LR_PASS_GBUFFER: rc = lr_pass_gbuffer(r, e); break;
        case LR_PASS_RADIOSITY: rc = lr_pass_radiosity(r, restart, e); break;
        case LR_PASS_VPL: rc = lr_pass_vpl(r, geometry, e); break;
        case LR_PASS_IRRADIANCE: rc = lr_pass_irradiance(r, e); break;
        case LR_PASS_COMPOSE: rc = lr_pass_compose(r, e); break;
        default: rc = lr_pass_blend(r, e); break;
        }
        int rc2 = lr_timer_end(r->timer, e);
        if (rc || (rc = rc2))
            return rc;
    }
    /* A disjoint GPU clock only spoils this frame's times (NaN); the frame itself is fine. */
    int trc = lr_timer_collect(r->timer, NULL);
    for (int s = 0; s < lr_timer_count(r->timer); s++)
        for (int i = 0; i < LR_PASS_COUNT; i++)
            if (!strcmp(lr_timer_name(r->timer, s), pass_names[i])) {
                st.ms[i] = trc ? NAN : lr_timer_ms(r->timer, s);
                st.total_ms += st.ms[i];
            }
    r->dirty = 0;
    st.index = r->frame_index++;
    st.passes = passes;
    st.samples = r->rad.F;
    st.converged = r->rad.F >= r->rs.frames;
    st.time_s = r->clock_set ? r->time_s : 0.0;
    if (stats)
        *stats = st;
    return LR_OK;
}

int lr_renderer_read_hdr(lr_renderer *r, float *rgb, lr_err *e)
{
    if (!r->blend)
        return lr_err_set(e, LR_EINVAL, "renderer: no image (resources failed to allocate)");
    lr_fb *hdr;
    int rc = lr_blend_hdr(r->blend, &hdr, e);
    if (rc)
        return rc;
    size_t n = (size_t)r->width * (size_t)r->height;
    float *rgba = malloc(n * 4 * sizeof *rgba);
    if (!rgba)
        return lr_err_set(e, LR_ENOMEM, "renderer: HDR readback: out of memory");
    rc = lr_fb_read(hdr, 0, 0, 0, r->width, r->height, rgba, e);
    if (!rc)
        for (size_t i = 0; i < n; i++)
            memcpy(rgb + 3 * i, rgba + 4 * i, 3 * sizeof *rgb);
    free(rgba);
    return rc;
}

int lr_renderer_read_rgba8(lr_renderer *r, unsigned char *out, lr_err *e)
{
    if (!r->blend)
        return lr_err_set(e, LR_EINVAL, "renderer: no image (resources failed to allocate)");
    size_t n = (size_t)r->width * (size_t)r->height;
    float *rgba = malloc(n * 4 * sizeof *rgba);
    if (!rgba)
        return lr_err_set(e, LR_ENOMEM, "renderer: readback: out of memory");
    int rc = lr_fb_read(lr_blend_ldr_fb(r->blend), 0, 0, 0, r->width, r->height, rgba, e);
    if (!rc)
        for (int y = 0; y < r->height; y++) {
            const float *src = rgba + (size_t)(r->height - 1 - y) * r->width * 4;
            unsigned char *dst = out + (size_t)y * r->width * 4;
            for (int i = 0; i < r->width * 4; i++) {
                float v = src[i] * 255.0f + 0.5f;
                dst[i] = (unsigned char)(v < 0.0f ? 0.0f : v > 255.0f ? 255.0f : v);
            }
        }
    free(rgba);
    return rc;
}

int lr_renderer_present(lr_renderer *r, lr_err *e)
{
    int w, h;
    if (!r->blend)
        return lr_err_set(e, LR_EINVAL, "renderer: no image (resources failed to allocate)");
    lr_gl_size(r->gl, &w, &h);
    if (w > 0 && h > 0) {
        lr_gl_bind_default(r->gl);
        glDisable(GL_DEPTH_TEST);
        glDisable(GL_BLEND);
        glUseProgram(lr_program_id(r->p_blit));
        lr_passes_bind_tex(r->p_blit, "u_src", 0, lr_blend_ldr(r->blend));
        lr_gl_draw_fullscreen(r->gl);
    }
    return lr_gl_present(r->gl, e);
}

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
