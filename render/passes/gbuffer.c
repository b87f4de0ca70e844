/* Pass 1 — the light G-buffer (render/passes/PIPELINE.md): the first surface of the
 * translucent objects seen from the light (world position + material id, world normal).
 * An enclosed point light (or one inside the objects' bounding sphere) gets a cube map drawn
 * face by face (GLES 3.1 has no geometry shaders); a point light outside a perspective 2D
 * map whose frustum holds the bounding sphere; a spot light a perspective map along its axis;
 * a directional light an orthographic map over the bounding sphere. One G-buffer per light
 * (r->gb[l]); the memory per light is 2 x 6 x gbuffer_size^2 RGBA32F texels for the cube
 * plus 2 x gbuffer_size^2 for the 2D map (14.7 MB at 256^2). */
#include <math.h>

#include "render/base/mat4.h"
#include "render/passes/passes.h"

static int make_fb(lr_renderer *r, lr_tex *pos, lr_tex *nrm, int layer, lr_fb **out, lr_err *e)
{
    lr_fb_desc d = {.color = {{pos, layer}, {nrm, layer}}, .depth_buffer = true,
                    .label = "light G-buffer"};
    return lr_fb_create(r->gl, &d, out, e);
}

int lr_gbuffer_alloc(lr_renderer *r, lr_err *e)
{
    int n = r->rs.gbuffer_size, rc;
    int nl = lr_scene_light_count(r->scene);
    if (nl > LR_MAX_LIGHTS)
        return lr_err_set(e, LR_EUNSUPPORTED, "renderer: %d lights; at most %d", nl,
                          LR_MAX_LIGHTS);
    r->n_lights = nl;
    lr_tex_desc cube = {.type = LR_TEX_CUBE, .format = LR_TEX_RGBA32F, .width = n,
                        .label = "light G-buffer cube"};
    lr_tex_desc flat = {.type = LR_TEX_2D, .format = LR_TEX_RGBA32F, .width = n, .height = n,
                        .label = "light G-buffer 2D"};
    for (int l = 0; l < nl; l++) {
        struct lr_light_gbuffer *g = &r->gb[l];
        g->size = n;
        if ((rc = lr_tex_create(r->gl, &cube, &g->pos_cube, e)) ||
            (rc = lr_tex_create(r->gl, &cube, &g->nrm_cube, e)) ||
            (rc = lr_tex_create(r->gl, &flat, &g->pos_2d, e)) ||
            (rc = lr_tex_create(r->gl, &flat, &g->nrm_2d, e)))
            return rc;
        for (int f = 0; f < 6; f++)
            if ((rc = make_fb(r, g->pos_cube, g->nrm_cube, f, &g->fb[f], e)))
                return rc;
        if ((rc = make_fb(r, g->pos_2d, g->nrm_2d, 0, &g->fb_2d, e)))
            return rc;
    }
    return LR_OK;
}

void lr_gbuffer_free(lr_renderer *r)
{
    for (int l = 0; l < LR_MAX_LIGHTS; l++) {
        struct lr_light_gbuffer *g = &r->gb[l];
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

static lr_vec3 up_for(lr_vec3 dir)
{
    return fabs(dir.z) > 0.99 ? lr_v3(0.0, 1.0, 0.0) : lr_v3(0.0, 0.0, 1.0);
}

/* Draws every object into the bound framebuffer with world -> clip `vp`. */
static void draw_objects(lr_renderer *r, const double vp[16])
{
    const lr_program *p = r->p_surface;
    lr_passes_uniform_mat4(p, "u_vp", vp);
    for (int i = 0; i < r->n_objects; i++) {
        lr_passes_uniform_i(p, "u_object", i);
        lr_passes_uniform_i(p, "u_two_sided", r->two_sided[i]);
        lr_passes_draw(&r->obj[i]);
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

/* Light l's G-buffer. */
static void draw_light(lr_renderer *r, int l)
{
    const lr_light *light = lr_passes_light(r, l);
    struct lr_light_gbuffer *g = &r->gb[l];
    lr_vec3 c;
    double R;
    lr_scene_bounds(r->scene, &c, &R);
    R = fmax(R, 1e-3);
    g->type = light->type == LR_LIGHT_POINT ? 0 : light->type == LR_LIGHT_SPOT ? 1 : 2;
    g->pos = light->position;
    g->dir = lr_v3_normalize(light->direction);
    g->spot_cos[0] = (float)cos(light->outer_deg * M_PI / 180.0);
    g->spot_cos[1] = (float)cos(light->inner_deg * M_PI / 180.0);

    double dist = lr_v3_len(lr_v3_sub(c, light->position));
    enum lr_enclosure enc = lr_scene_light_enclosure(r->scene, l, NULL);
    if (light->type == LR_LIGHT_DIRECTIONAL)
        g->mode = LR_GB_ORTHO;
    else if (light->type == LR_LIGHT_POINT && (enc != LR_ENCLOSURE_NONE || dist < 1.05 * R))
        g->mode = LR_GB_CUBE;
    else
        g->mode = LR_GB_PERSPECTIVE;

    if (g->mode == LR_GB_CUBE) {
        double znear = fmax(1e-4 * R, 1e-3), zfar = dist + 3.0 * R;
        for (int f = 0; f < 6; f++) {
            lr_fb_bind(g->fb[f]);
            clear_surface();
            lr_passes_cube_face_vp(light->position, f, znear, zfar, g->face_vp[f]);
            draw_objects(r, g->face_vp[f]);
        }
        lr_mat4_identity(g->vp_d);
    } else {
        double view[16], proj[16];
        if (g->mode == LR_GB_ORTHO) {
            lr_vec3 eye = lr_v3_sub(c, lr_v3_scale(g->dir, 2.0 * R));
            lr_mat4_look_at(eye, c, up_for(g->dir), view);
            lr_mat4_ortho(-R, R, -R, R, 0.5 * R, 3.5 * R, proj);
        } else if (light->type == LR_LIGHT_SPOT) {
            lr_mat4_look_at(light->position, lr_v3_add(light->position, g->dir), up_for(g->dir),
                            view);
            double fov = fmin(2.0 * light->outer_deg * M_PI / 180.0 * 1.02, 170.0 * M_PI / 180.0);
            lr_mat4_perspective(fov, 1.0, fmax(1e-3 * R, 1e-3), dist + 3.0 * R, proj);
        } else {
            lr_vec3 axis = lr_v3_normalize(lr_v3_sub(c, light->position));
            lr_mat4_look_at(light->position, c, up_for(axis), view);
            double fov = 2.0 * asin(fmin(R / dist, 1.0)) * 1.05;
            lr_mat4_perspective(fmin(fov, 170.0 * M_PI / 180.0), 1.0, fmax(0.5 * (dist - R), 1e-3),
                                dist + 2.0 * R, proj);
        }
        lr_mat4_mul(proj, view, g->vp_d);
        lr_fb_bind(g->fb_2d);
        clear_surface();
        draw_objects(r, g->vp_d);
    }
    lr_mat4_to_float(g->vp_d, g->vp);
}

int lr_pass_gbuffer(lr_renderer *r, lr_err *e)
{
    glUseProgram(lr_program_id(r->p_surface));
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    for (int l = 0; l < r->n_lights; l++)
        draw_light(r, l);
    return lr_gl_check("gbuffer pass", e);
}
