/* Pass 1 — the light G-buffer (render/passes/PIPELINE.md): the first surface of the
 * translucent objects seen from the light (world position + material id, world normal).
 * An enclosed point light (or one inside the objects' bounding sphere) gets a cube map drawn
 * face by face (GLES 3.1 has no geometry shaders); a point light outside a perspective 2D
 * map whose frustum holds the bounding sphere; a spot light a perspective map along its axis;
 * a directional light an orthographic map over the bounding sphere. One G-buffer per light
 * (g->light[l]); the memory per light is 2 x 6 x gbuffer_size^2 RGBA32F texels for the cube
 * plus 2 x gbuffer_size^2 for the 2D map (14.7 MB at 256^2). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/area/frames.h"
#include "render/base/mat4.h"
#include "render/passes/gbuffer.h"

static int make_fb(lr_gl *gl, lr_tex *pos, lr_tex *nrm, int layer, lr_fb **out, lr_err *e)
{
    lr_fb_desc d = {.color = {{pos, layer}, {nrm, layer}}, .depth_buffer = true,
                    .label = "light G-buffer"};
    return lr_fb_create(gl, &d, out, e);
}

int lr_gbuffer_alloc(lr_gbuffer *gb, const lr_pass_ctx *c, lr_err *e)
{
    int n = c->rs->gbuffer_size, rc;
    int nl = c->n_lights;
    gb->n_lights = nl;
    lr_tex_desc cube = {.type = LR_TEX_CUBE, .format = LR_TEX_RGBA32F, .width = n,
                        .label = "light G-buffer cube"};
    lr_tex_desc flat = {.type = LR_TEX_2D, .format = LR_TEX_RGBA32F, .width = n, .height = n,
                        .label = "light G-buffer 2D"};
    lr_tex_desc prof = {.type = LR_TEX_2D, .format = LR_TEX_R32F, .width = LR_PROFILE_NG,
                        .height = LR_PROFILE_NC * LR_MAX_LIGHTS, .label = "light profiles"};
    if ((rc = lr_tex_create(c->gl, &prof, &gb->profiles, e)))
        return rc;
    gb->profiles_valid = false;
    for (int l = 0; l < nl; l++) {
        lr_light_gbuffer *g = &gb->light[l];
        g->size = n;
        if ((rc = lr_tex_create(c->gl, &cube, &g->pos_cube, e)) ||
            (rc = lr_tex_create(c->gl, &cube, &g->nrm_cube, e)) ||
            (rc = lr_tex_create(c->gl, &flat, &g->pos_2d, e)) ||
            (rc = lr_tex_create(c->gl, &flat, &g->nrm_2d, e)))
            return rc;
        for (int f = 0; f < 6; f++)
            if ((rc = make_fb(c->gl, g->pos_cube, g->nrm_cube, f, &g->fb[f], e)))
                return rc;
        if ((rc = make_fb(c->gl, g->pos_2d, g->nrm_2d, 0, &g->fb_2d, e)))
            return rc;
    }
    return LR_OK;
}

void lr_gbuffer_free(lr_gbuffer *gb)
{
    lr_tex_destroy(gb->profiles);
    gb->profiles = NULL;
    gb->profiles_valid = false;
    for (int l = 0; l < LR_MAX_LIGHTS; l++) {
        lr_light_gbuffer *g = &gb->light[l];
        for (int f = 0; f < 6; f++) {
            lr_fb_destroy(g->fb[f]);
            g->fb[f] = NULL;
        }
        lr_fb_destroy(g->fb_2d);
        lr_tex_destroy(g->pos_cube);
        lr_tex_destroy(g->nrm_cube);
        lr_tex_destroy(g->pos_2d);
        lr_tex_destroy(g->nrm_2d);
        g->fb_2d = NULL;
        g->pos_cube = g->nrm_cube = g->pos_2d = g->nrm_2d = NULL;
    }
}

/* Draws every object into the bound framebuffer with world -> clip `vp`. */
static void draw_objects(const lr_pass_ctx *c, const double vp[16])
{
    lr_program *p = c->prog->surface;
    lr_passes_uniform_mat4(p, "u_vp", vp);
    for (int i = 0; i < c->objs->n_objects; i++) {
        lr_passes_uniform_i(p, "u_object", i);
        lr_passes_uniform_i(p, "u_two_sided", c->objs->two_sided[i]);
        lr_passes_draw(&c->objs->obj[i]);
    }
}

static void clear_surface(void)
{
    static const float zero[4] = {0, 0, 0, 0};
    glClearBufferfv(GL_COLOR, 0, zero);
    glClearBufferfv(GL_COLOR, 1, zero);
    glClearDepthf(1.0f);
    glClear(GL_DEPTH_BUFFER_BIT);
}

/* The lights' profile tables into the texture when one changed (a scene's tables are fixed
 * at load, so this runs once per scene). Rows without a profile stay 0: never read. */
static int upload_profiles(lr_gbuffer *g, const lr_pass_ctx *c, lr_err *e)
{
    bool same = g->profiles_valid;
    uint64_t key[LR_MAX_LIGHTS] = {0};
    for (int l = 0; l < g->n_lights; l++) {
        const lr_light *light = lr_scene_light_at(c->scene, l);
        key[l] = light->profile.on ? light->profile.hash | 1u : 0;
        same = same && key[l] == g->profile_key[l];
    }
    if (same)
        return LR_OK;
    const size_t per = (size_t)LR_PROFILE_NG * LR_PROFILE_NC;
    float *t = calloc(per * LR_MAX_LIGHTS, sizeof *t);
    if (!t)
        return lr_err_set(e, LR_ENOMEM, "light profiles: out of memory");
    for (int l = 0; l < g->n_lights; l++) {
        const lr_light *light = lr_scene_light_at(c->scene, l);
        if (light->profile.on)
            memcpy(t + per * (size_t)l, light->profile.rel, per * sizeof *t);
    }
    int rc = lr_tex_upload(g->profiles, 0, t, e);
    free(t);
    if (rc)
        return rc;
    memcpy(g->profile_key, key, sizeof key);
    g->profiles_valid = true;
    return LR_OK;
}

/* Light l's G-buffer. */
static void draw_light(lr_light_gbuffer *g, const lr_pass_ctx *ctx, int l, long frame)
{
    /* An area light is a point light at the frame's sample p_f with the emitter's profile
     * A cos(theta_e) (render/area/frames.h; the twin's lr_light_at_frame). */
    lr_light at;
    lr_light_at_frame(lr_scene_light_at(ctx->scene, l), frame, &at);
    const lr_light *light = &at;
    bool area = lr_light_is_area(light);
    g->area_n = area ? lr_light_area_normal(light) : lr_v3(0.0, 0.0, 1.0);
    g->area = area ? (float)lr_light_area(light) : 0.0f;
    g->two_sided = area && light->two_sided;
    g->type = light->type;
    g->pos = light->position;
    g->dir = lr_v3_normalize(light->direction);
    g->spot_cos[0] = (float)cos(light->outer_deg * M_PI / 180.0);
    g->spot_cos[1] = (float)cos(light->inner_deg * M_PI / 180.0);
    g->profile_on = light->profile.on;
    if (g->profile_on)
        lr_light_profile_axes(light, &g->prof_x, &g->prof_y, &g->prof_z);

    lr_gb_camera cam;
    lr_gb_camera_scene_frame(ctx->scene, l, frame, &cam);
    g->mode = cam.mode;
    if (g->mode == LR_GB_CUBE) {
        for (int f = 0; f < 6; f++) {
            lr_fb_bind(g->fb[f]);
            clear_surface();
            memcpy(g->face_vp[f], cam.vp[f], sizeof cam.vp[f]);
            draw_objects(ctx, g->face_vp[f]);
        }
        lr_mat4_identity(g->vp_d);
    } else {
        memcpy(g->vp_d, cam.vp[0], sizeof cam.vp[0]);
        lr_fb_bind(g->fb_2d);
        clear_surface();
        draw_objects(ctx, g->vp_d);
    }
    lr_mat4_to_float(g->vp_d, g->vp);
}

int lr_gbuffer_run(lr_gbuffer *g, const lr_pass_ctx *c, long frame, lr_err *e)
{
    glUseProgram(lr_program_id(c->prog->surface));
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    for (int l = 0; l < g->n_lights; l++)
        draw_light(&g->light[l], c, l, frame);
    int rc = upload_profiles(g, c, e);
    if (rc)
        return rc;
    return lr_gl_check("gbuffer pass", e);
}

void lr_gbuffer_bind(const lr_gbuffer *gb, lr_program *p, int l)
{
    const lr_light_gbuffer *g = &gb->light[l];
    if (g->mode == LR_GB_CUBE) {
        lr_passes_bind_tex(p, "u_gb_cube_pos", 0, g->pos_cube);
        lr_passes_bind_tex(p, "u_gb_cube_nrm", 1, g->nrm_cube);
        /* Units of the unused sampler type must differ from the used ones. */
        lr_passes_uniform_i(p, "u_gb_pos", 2);
        lr_passes_uniform_i(p, "u_gb_nrm", 3);
    } else {
        lr_passes_uniform_i(p, "u_gb_cube_pos", 0);
        lr_passes_uniform_i(p, "u_gb_cube_nrm", 1);
        lr_passes_bind_tex(p, "u_gb_pos", 2, g->pos_2d);
        lr_passes_bind_tex(p, "u_gb_nrm", 3, g->nrm_2d);
    }
    lr_passes_uniform_i(p, "u_gb_mode", (int)g->mode);
    GLint loc = lr_program_uniform(p, "u_gb_vp");
    if (loc >= 0)
        glUniformMatrix4fv(loc, 1, GL_FALSE, g->vp);
    lr_passes_uniform_v3(p, "u_light_pos", g->pos);
    lr_passes_uniform_v3(p, "u_light_dir", g->dir);
    lr_passes_uniform_i(p, "u_light_type", (int)g->type);
    loc = lr_program_uniform(p, "u_spot_cos");
    if (loc >= 0)
        glUniform2f(loc, g->spot_cos[0], g->spot_cos[1]);
    /* The area light's profile (radiosity.frag light_shape); set only where declared. */
    if ((loc = lr_program_uniform(p, "u_area_n")) >= 0)
        glUniform3f(loc, (float)g->area_n.x, (float)g->area_n.y, (float)g->area_n.z);
    if ((loc = lr_program_uniform(p, "u_area")) >= 0)
        glUniform1f(loc, g->area);
    if ((loc = lr_program_uniform(p, "u_area_two_sided")) >= 0)
        glUniform1i(loc, g->two_sided);
    if (lr_program_uniform(p, "u_profiles") >= 0)
        lr_passes_bind_tex(p, "u_profiles", LR_PROFILE_TEX_UNIT, gb->profiles);
    lr_passes_uniform_i(p, "u_profile_on", g->profile_on);
    lr_passes_uniform_i(p, "u_profile_light", l);
    lr_passes_uniform_v3(p, "u_prof_x", g->prof_x);
    lr_passes_uniform_v3(p, "u_prof_y", g->prof_y);
    lr_passes_uniform_v3(p, "u_prof_z", g->prof_z);
}

/* Element i of uniform array `name` ("u_x[2]"). */
static GLint array_loc(lr_program *p, const char *name, int i)
{
    char n[64];
    snprintf(n, sizeof n, "%s[%d]", name, i);
    return lr_program_uniform(p, n);
}

void lr_gbuffer_bind_lights(const lr_gbuffer *gb, const lr_pass_ctx *c, lr_program *p)
{
    /* Every array element gets its own unit, used or not: a cube and a 2D sampler must never
     * share one (units 4..10 belong to the gather and the VPLs). */
    for (int l = 0; l < LR_MAX_LIGHTS; l++) {
        const lr_light_gbuffer *g = &gb->light[l];
        bool on = l < gb->n_lights;
        glActiveTexture(GL_TEXTURE0 + (GLenum)l);
        glBindTexture(GL_TEXTURE_CUBE_MAP, on && g->mode == LR_GB_CUBE ? lr_tex_id(g->pos_cube) : 0);
        glActiveTexture(GL_TEXTURE11 + (GLenum)l);
        glBindTexture(GL_TEXTURE_2D, on && g->mode != LR_GB_CUBE ? lr_tex_id(g->pos_2d) : 0);
        GLint loc;
        if ((loc = array_loc(p, "u_lights_cube", l)) >= 0)
            glUniform1i(loc, l);
        if ((loc = array_loc(p, "u_lights_2d", l)) >= 0)
            glUniform1i(loc, 11 + l);
        if (!on)
            continue;
        if ((loc = array_loc(p, "u_lights_mode", l)) >= 0)
            glUniform1i(loc, (int)g->mode);
        if ((loc = array_loc(p, "u_lights_type", l)) >= 0)
            glUniform1i(loc, (int)g->type);
        if ((loc = array_loc(p, "u_lights_vp", l)) >= 0)
            glUniformMatrix4fv(loc, 1, GL_FALSE, g->vp);
        if ((loc = array_loc(p, "u_lights_pos", l)) >= 0)
            glUniform3f(loc, (float)g->pos.x, (float)g->pos.y, (float)g->pos.z);
        if ((loc = array_loc(p, "u_lights_dir", l)) >= 0)
            glUniform3f(loc, (float)g->dir.x, (float)g->dir.y, (float)g->dir.z);
        if ((loc = array_loc(p, "u_lights_spot_cos", l)) >= 0)
            glUniform2f(loc, g->spot_cos[0], g->spot_cos[1]);
        if ((loc = array_loc(p, "u_lights_area_n", l)) >= 0)
            glUniform3f(loc, (float)g->area_n.x, (float)g->area_n.y, (float)g->area_n.z);
        if ((loc = array_loc(p, "u_lights_area", l)) >= 0)
            glUniform1f(loc, g->area);
        if ((loc = array_loc(p, "u_lights_two_sided", l)) >= 0)
            glUniform1i(loc, g->two_sided);
        if ((loc = array_loc(p, "u_lights_profile", l)) >= 0)
            glUniform1i(loc, g->profile_on);
        const lr_vec3 *ax[3] = {&g->prof_x, &g->prof_y, &g->prof_z};
        static const char *const axn[3] = {"u_lights_prof_x", "u_lights_prof_y",
                                           "u_lights_prof_z"};
        for (int k = 0; k < 3; k++)
            if ((loc = array_loc(p, axn[k], l)) >= 0)
                glUniform3f(loc, (float)ax[k]->x, (float)ax[k]->y, (float)ax[k]->z);
        if ((loc = array_loc(p, "u_lights_I", l)) >= 0)
            glUniform3f(loc, (float)c->I[l][0], (float)c->I[l][1], (float)c->I[l][2]);
    }
    lr_passes_uniform_i(p, "u_n_lights", gb->n_lights);
    if (lr_program_uniform(p, "u_profiles") >= 0)
        lr_passes_bind_tex(p, "u_profiles", LR_PROFILE_TEX_UNIT, gb->profiles);
}
