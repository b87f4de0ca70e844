/* The area lights' direct light on the plane receivers (area_direct.h): frame F adds the
 * direct irradiance from each area light's sample p_F (render/area/frames.h) at the receiver
 * grid's texel centres (render/core/recv_grid.h), shadowed through the G-buffer drawn at p_F,
 * with blend weight 1/F, so the grid keeps the running mean
 *     E(x) = (1/F) sum_f L-less A cos(theta_e,f) cos(theta_x,f) / d_f^2 V_f,
 * the twin's direct_at (render/cpu/frame.c) over the same samples. A shadow cast per pixel
 * at composition would see only the last frame's G-buffer, one sample of the emitter. The
 * grid has the format of the maps (RGBA32F, RGBA16F without float blending) and their
 * weights. */
#include "render/passes/area_direct.h"

#include <stdlib.h>

#include "render/core/recv_grid.h"
#include "render/passes/radiosity.h"

bool lr_area_direct_needed(const lr_scene *s)
{
    for (int l = 0; l < lr_scene_light_count(s); l++)
        if (lr_light_is_area(lr_scene_light_at(s, l)))
            return true;
    return false;
}

bool lr_area_direct_pass_needed(const lr_scene *s)
{
    if (lr_area_direct_needed(s))
        return true;
    if (lr_scene_render(s)->lpv <= 0)
        return false;
    bool lit = false, plane = false;
    for (int l = 0; l < lr_scene_light_count(s); l++) {
        enum lr_light_type t = lr_scene_light_at(s, l)->type;
        lit |= t == LR_LIGHT_POINT || t == LR_LIGHT_SPOT;
    }
    for (int i = 0; i < lr_scene_receiver_count(s); i++) {
        lr_recv_grid_frame f;
        plane |= lr_recv_grid_frame_of(lr_scene_receiver_at(s, i), &f);
    }
    return lit && plane;
}

int lr_area_direct_check(const lr_scene *s, lr_err *e)
{
    if (!lr_area_direct_needed(s))
        return LR_OK;
    for (int i = 0; i < lr_scene_receiver_count(s); i++) {
        lr_recv_grid_frame f;
        if (!lr_recv_grid_frame_of(lr_scene_receiver_at(s, i), &f))
            return lr_err_set(e, LR_EUNSUPPORTED,
                              "renderer: scene %s: receiver '%s' is not a plane, and the GLES "
                              "renderer accumulates an area light's direct light on plane "
                              "receivers only; use lamprig-cpuref --twin",
                              lr_scene_name(s), lr_scene_receiver_at(s, i)->name);
    }
    return LR_OK;
}

void lr_area_direct_free(lr_area_direct *a)
{
    for (int i = 0; i < LR_MAX_RECEIVERS; i++) {
        lr_fb_destroy(a->fb[i]);
        a->fb[i] = NULL;
        a->layer[i] = -1;
    }
    lr_tex_destroy(a->grid);
    a->grid = NULL;
    a->n_receivers = a->n_lights = 0;
    a->F = 0;
}

static int alloc(lr_area_direct *a, const lr_pass_ctx *c, lr_err *e)
{
    lr_area_direct_free(a);
    int nl = c->n_lights, nr = c->objs->n_receivers, planes = 0, rc;
    for (int i = 0; i < nr; i++) {
        lr_recv_grid_frame f;
        a->layer[i] = lr_recv_grid_frame_of(lr_scene_receiver_at(c->scene, i), &f)
                          ? nl * planes++ : -1;
    }
    a->n_receivers = nr;
    a->n_lights = nl;
    if (!planes || nl < 1)
        return LR_OK;
    lr_tex_desc td = {.type = LR_TEX_2D_ARRAY, .format = c->map_format, .width = LR_RECV_GRID,
                      .height = LR_RECV_GRID, .layers = planes * nl,
                      .label = "area lights' direct grids"};
    if ((rc = lr_tex_create(c->gl, &td, &a->grid, e)))
        return rc;
    for (int i = 0; i < nr; i++) {
        if (a->layer[i] < 0)
            continue;
        lr_fb_desc fd = {.label = "area lights' direct grid"};
        for (int l = 0; l < nl; l++)
            fd.color[l] = (lr_fb_attachment){a->grid, a->layer[i] + l};
        if ((rc = lr_fb_create(c->gl, &fd, &a->fb[i], e)))
            return rc;
    }
    return LR_OK;
}

int lr_area_direct_run(lr_area_direct *a, const lr_pass_ctx *c, const lr_gbuffer *gb, int F,
                       const lr_tex *lpv, lr_err *e)
{
    int rc;
    if ((!a->grid || a->n_receivers != c->objs->n_receivers || a->n_lights != c->n_lights) &&
        (rc = alloc(a, c, e)))
        return rc;
    if (!a->grid)
        return LR_OK;
    lr_program *p = c->prog->area;
    glDisable(GL_DEPTH_TEST);
    glUseProgram(lr_program_id(p));
    lr_gbuffer_bind_lights(gb, c, p);
    lr_passes_uniform_i(p, "u_grid_size", LR_RECV_GRID);
    lr_passes_uniform_i(p, "u_lpv_on", lpv != NULL);
    lr_passes_bind_tex(p, "u_lpv", 17, lpv);
    if (F <= 1) {
        glDisable(GL_BLEND);
    } else {
        glEnable(GL_BLEND);
        glBlendEquation(GL_FUNC_ADD);
        glBlendColor(0.0f, 0.0f, 0.0f, lr_radiosity_blend_weight(c->map_format, F));
        glBlendFunc(GL_CONSTANT_ALPHA, GL_ONE_MINUS_CONSTANT_ALPHA);
    }
    for (int i = 0; i < c->objs->n_receivers; i++) {
        lr_recv_grid_frame f;
        if (a->layer[i] < 0 || !lr_recv_grid_frame_of(lr_scene_receiver_at(c->scene, i), &f))
            continue;
        lr_fb_bind(a->fb[i]);
        lr_passes_uniform_v3(p, "u_grid_c", f.c);
        lr_passes_uniform_v3(p, "u_grid_wa", lr_v3_scale(f.a, f.w));
        lr_passes_uniform_v3(p, "u_grid_hb", lr_v3_scale(f.b, f.h));
        lr_passes_uniform_v3(p, "u_grid_n", lr_scene_receiver_at(c->scene, i)->normal);
        lr_passes_uniform_i(p, "u_lpv_layer", a->layer[i]);
        lr_gl_draw_fullscreen(c->gl);
    }
    glDisable(GL_BLEND);
    if ((rc = lr_gl_check("area lights' direct grid", e)))
        return rc;
    a->F = F;
    return LR_OK;
}

void lr_area_direct_bind(const lr_area_direct *a, const lr_pass_ctx *c, lr_program *p,
                         int receiver)
{
    lr_recv_grid_frame f;
    bool cached = a->grid && a->F > 0 && receiver < a->n_receivers && a->layer[receiver] >= 0 &&
                  lr_recv_grid_frame_of(lr_scene_receiver_at(c->scene, receiver), &f);
    lr_passes_uniform_i(p, "u_area_cached", cached);
    lr_passes_bind_tex(p, "u_area_grid", 16, cached ? a->grid : NULL);
    if (!cached)
        return;
    lr_passes_uniform_i(p, "u_area_layer", a->layer[receiver]);
    lr_passes_uniform_v3(p, "u_area_c", f.c);
    lr_passes_uniform_v3(p, "u_area_a", lr_v3_scale(f.a, 1.0 / f.w));
    lr_passes_uniform_v3(p, "u_area_b", lr_v3_scale(f.b, 1.0 / f.h));
}
