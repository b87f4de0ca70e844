/* Pass 1 — the light G-buffer (render/passes/PIPELINE.md): the first surface of the
 * translucent objects seen from the light (world position + material id, world normal).
 * An enclosed point light (or one inside the objects' bounding sphere) gets a cube map drawn
 * face by face (GLES 3.1 has no geometry shaders); a point light outside a perspective 2D
 * map whose frustum holds the bounding sphere; a spot light a perspective map along its axis;
 * a directional light an orthographic map over the bounding sphere. */
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
    r->gb.size = n;
    lr_tex_desc cube = {.type = LR_TEX_CUBE, .format = LR_TEX_RGBA32F, .width = n,
                        .label = "light G-buffer cube"};
    lr_tex_desc flat = {.type = LR_TEX_2D, .format = LR_TEX_RGBA32F, .width = n, .height = n,
                        .label = "light G-buffer 2D"};
    if ((rc = lr_tex_create(r->gl, &cube, &r->gb.pos_cube, e)) ||
        (rc = lr_tex_create(r->gl, &cube, &r->gb.nrm_cube, e)) ||
        (rc = lr_tex_create(r->gl, &flat, &r->gb.pos_2d, e)) ||
        (rc = lr_tex_create(r->gl, &flat, &r->gb.nrm_2d, e)))
        return rc;
    for (int f = 0; f < 6; f++)
        if ((rc = make_fb(r, r->gb.pos_cube, r->gb.nrm_cube, f, &r->gb.fb[f], e)))
            return rc;
    return make_fb(r, r->gb.pos_2d, r->gb.nrm_2d, 0, &r->gb.fb_2d, e);
}

void lr_gbuffer_free(lr_renderer *r)
{
    for (int f = 0; f < 6; f++) {
        lr_fb_destroy(r->gb.fb[f]);
        r->gb.fb[f] = NULL;
    }
    lr_fb_destroy(r->gb.fb_2d);
    lr_tex_destroy(r->gb.pos_cube);
    lr_tex_destroy(r->gb.nrm_cube);
    lr_tex_destroy(r->gb.pos_2d);
    lr_tex_destroy(r->gb.nrm_2d);
    r->gb.fb_2d = NULL;
    r->gb.pos_cube = r->gb.nrm_cube = r->gb.pos_2d = r->gb.nrm_2d = NULL;
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

int lr_pass_gbuffer(lr_renderer *r, lr_err *e)
{
    const lr_light *l = lr_passes_light(r);
    lr_vec3 c;
    double R;
    lr_scene_bounds(r->scene, &c, &R);
    R = fmax(R, 1e-3);
    r->gb.type = l->type == LR_LIGHT_POINT ? 0 : l->type == LR_LIGHT_SPOT ? 1 : 2;
    r->gb.pos = l->position;
    r->gb.dir = lr_v3_normalize(l->direction);
    r->gb.spot_cos[0] = (float)cos(l->outer_deg * M_PI / 180.0);
    r->gb.spot_cos[1] = (float)cos(l->inner_deg * M_PI / 180.0);

    double dist = lr_v3_len(lr_v3_sub(c, l->position));
    enum lr_enclosure enc = lr_scene_light_enclosure(r->scene, 0, NULL);
    if (l->type == LR_LIGHT_DIRECTIONAL)
        r->gb.mode = LR_GB_ORTHO;
    else if (l->type == LR_LIGHT_POINT && (enc != LR_ENCLOSURE_NONE || dist < 1.05 * R))
        r->gb.mode = LR_GB_CUBE;
    else
        r->gb.mode = LR_GB_PERSPECTIVE;

    glUseProgram(lr_program_id(r->p_surface));
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    if (r->gb.mode == LR_GB_CUBE) {
        double znear = fmax(1e-4 * R, 1e-3), zfar = dist + 3.0 * R;
        for (int f = 0; f < 6; f++) {
            lr_fb_bind(r->gb.fb[f]);
            clear_surface();
            lr_passes_cube_face_vp(l->position, f, znear, zfar, r->gb.face_vp[f]);
            draw_objects(r, r->gb.face_vp[f]);
        }
        lr_mat4_identity(r->gb.vp_d);
    } else {
        double view[16], proj[16];
        if (r->gb.mode == LR_GB_ORTHO) {
            lr_vec3 eye = lr_v3_sub(c, lr_v3_scale(r->gb.dir, 2.0 * R));
            lr_mat4_look_at(eye, c, up_for(r->gb.dir), view);
            lr_mat4_ortho(-R, R, -R, R, 0.5 * R, 3.5 * R, proj);
        } else if (l->type == LR_LIGHT_SPOT) {
            lr_mat4_look_at(l->position, lr_v3_add(l->position, r->gb.dir), up_for(r->gb.dir), view);
            double fov = fmin(2.0 * l->outer_deg * M_PI / 180.0 * 1.02, 170.0 * M_PI / 180.0);
            lr_mat4_perspective(fov, 1.0, fmax(1e-3 * R, 1e-3), dist + 3.0 * R, proj);
        } else {
            lr_vec3 axis = lr_v3_normalize(lr_v3_sub(c, l->position));
            lr_mat4_look_at(l->position, c, up_for(axis), view);
            double fov = 2.0 * asin(fmin(R / dist, 1.0)) * 1.05;
            lr_mat4_perspective(fmin(fov, 170.0 * M_PI / 180.0), 1.0, fmax(0.5 * (dist - R), 1e-3),
                                dist + 2.0 * R, proj);
        }
        lr_mat4_mul(proj, view, r->gb.vp_d);
        lr_fb_bind(r->gb.fb_2d);
        clear_surface();
        draw_objects(r, r->gb.vp_d);
    }
    lr_mat4_to_float(r->gb.vp_d, r->gb.vp);
    return lr_gl_check("gbuffer pass", e);
}
