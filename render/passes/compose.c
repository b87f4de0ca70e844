/* Pass 3 — composition (render/passes/PIPELINE.md): the camera's view of the objects
 * (Algorithm 1 over the K maps, L_o = F_t B / pi) and of the receivers (direct light
 * shadowed through the light G-buffer, plus the VPLs), one linear RGBA32F image per light for
 * unit intensity (multiple render targets: one draw per mesh fills every light's image). The
 * cavity gains per light and object (PIPELINE.md "Energy") are in the images; the lights'
 * intensity x colour x flicker enter only in the blend pass (lr_pass_blend, below), so a
 * dimmer change runs that fullscreen pass alone (issue 11). */
#include <math.h>

#include "render/base/mat4.h"
#include "render/passes/passes.h"

static void images_free(lr_renderer *r)
{
    lr_fb_destroy(r->img.fb);
    lr_tex_destroy(r->img.images);
    r->img.fb = NULL;
    r->img.images = NULL;
    r->img.n = 0;
    r->img.valid = false;
}

/* Images for n lights (a 2D array, one colour attachment per layer, one depth buffer). */
static int images_alloc(lr_renderer *r, int n, lr_err *e)
{
    images_free(r);
    if (n < 1 || n > LR_MAX_LIGHTS || n > r->caps->max_draw_buffers)
        return lr_err_set(e, LR_EUNSUPPORTED,
                          "compose: %d lights; takes 1..%d (and the driver %d draw buffers)", n,
                          LR_MAX_LIGHTS, r->caps->max_draw_buffers);
    lr_tex_desc td = {.type = LR_TEX_2D_ARRAY, .format = LR_TEX_RGBA32F, .width = r->width,
                      .height = r->height, .layers = n, .label = "per-light images"};
    int rc = lr_tex_create(r->gl, &td, &r->img.images, e);
    if (rc)
        return rc;
    lr_fb_desc fd = {.depth_buffer = true, .label = "per-light images"};
    for (int l = 0; l < n; l++)
        fd.color[l] = (lr_fb_attachment){r->img.images, l};
    if ((rc = lr_fb_create(r->gl, &fd, &r->img.fb, e)))
        return rc;
    r->img.n = n;
    return LR_OK;
}

int lr_compose_alloc(lr_renderer *r, lr_err *e)
{
    int rc = images_alloc(r, lr_scene_light_count(r->scene), e);
    if (rc)
        return rc;
    lr_blend_desc bd = {.gl = r->gl, .width = r->width, .height = r->height,
                        .shader_dir = r->shader_dir, .defines = lr_passes_defines()};
    return lr_blend_create(&bd, &r->blend, e);
}

void lr_compose_free(lr_renderer *r)
{
    images_free(r);
    lr_blend_destroy(r->blend);
    r->blend = NULL;
}

/* Per light and band: intensity * color (the gather's weights for the objects). */
static void intensities(const lr_renderer *r, double I[LR_MAX_LIGHTS][3])
{
    for (int l = 0; l < LR_MAX_LIGHTS; l++)
        for (int c = 0; c < 3; c++)
            I[l][c] = 0.0;
    for (int l = 0; l < r->n_lights; l++)
        lr_passes_light_rgb(r, l, I[l]);
}

int lr_pass_compose(lr_renderer *r, lr_err *e)
{
    /* Alpha 1 everywhere but on object fragments no map sees (compose_object.frag writes 0
     * there): lr_renderer_debug_uncovered counts them. */
    static const float zero[4] = {0, 0, 0, 1};
    int rc;
    if (r->img.n != r->n_lights && (rc = images_alloc(r, r->n_lights, e)))
        return rc;
    const lr_camera *cam = lr_scene_camera(r->scene);
    double view[16], proj[16], vp[16];
    lr_camera_view(cam, view);
    lr_camera_projection(cam, (double)r->width / r->height, proj);
    lr_mat4_mul(proj, view, vp);
    lr_vec3 fwd = lr_v3_normalize(lr_v3_sub(cam->target, cam->position));

    lr_fb_bind(r->img.fb);
    for (int l = 0; l < r->img.n; l++)
        glClearBufferfv(GL_COLOR, l, zero);
    glClearDepthf(1.0f);
    glDepthMask(GL_TRUE);
    glClear(GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);

    /* Unit intensity: the images hold each light's transport alone; the blend pass weights
     * them with intensity x colour x flicker (PIPELINE.md "Linearity"). */
    const lr_program *p = r->p_obj;
    glUseProgram(lr_program_id(p));
    lr_passes_set_coeffs(r, p);
    double unit[LR_MAX_LIGHTS][3];
    for (int l = 0; l < LR_MAX_LIGHTS; l++)
        for (int c = 0; c < 3; c++)
            unit[l][c] = 1.0;
    lr_passes_bind_gather(r, p, unit);
    lr_passes_uniform_mat4(p, "u_vp", vp);
    lr_passes_uniform_v3(p, "u_eye", cam->position);
    lr_passes_uniform_v3(p, "u_view_dir", fwd);
    lr_passes_uniform_i(p, "u_ortho", cam->orthographic);
    for (int i = 0; i < r->n_objects; i++) {
        /* Object i's emission for light l times its cavity gain for l (PIPELINE.md "Energy"):
         * the gather's per-light weights. */
        double w[LR_MAX_LIGHTS][3];
        for (int l = 0; l < LR_MAX_LIGHTS; l++)
            for (int c = 0; c < 3; c++)
                w[l][c] = r->cavity_gain[3 * (l * LR_MAX_OBJECTS + i) + c];
        lr_passes_set_light_w(r, p, w);
        lr_passes_uniform_i(p, "u_object", i);
        lr_passes_uniform_i(p, "u_two_sided", r->two_sided[i]);
        lr_passes_draw(&r->obj[i]);
    }

    p = r->p_recv;
    glUseProgram(lr_program_id(p));
    lr_passes_set_coeffs(r, p);
    lr_passes_bind_lights(r, p);
    lr_passes_uniform_mat4(p, "u_vp", vp);
    lr_passes_bind_vpls(r, p);
    for (int i = 0; i < r->n_receivers; i++) {
        lr_passes_bind_irradiance(r, p, i);
        const lr_receiver *rcv = lr_scene_receiver_at(r->scene, i);
        GLint loc = lr_program_uniform(p, "u_albedo");
        if (loc >= 0)
            glUniform3f(loc, (float)rcv->albedo[0], (float)rcv->albedo[1], (float)rcv->albedo[2]);
        lr_passes_draw(&r->recv[i]);
    }
    glDisable(GL_DEPTH_TEST);
    if ((rc = lr_gl_check("compose pass", e)))
        return rc;
    r->img.valid = true;
    return LR_OK;
}

int lr_pass_blend(lr_renderer *r, lr_err *e)
{
    lr_blend_input in = {.images = r->img.images, .n = r->img.n,
                         .exposure = (float)r->rs.exposure, .tonemap_op = LR_RENDER_TONEMAP};
    double I[LR_MAX_LIGHTS][3];
    intensities(r, I);
    for (int l = 0; l < r->img.n && l < LR_BLEND_MAX_IMAGES; l++)
        for (int c = 0; c < 3; c++)
            in.w[l][c] = I[l][c];
    return lr_blend_run(r->blend, &in, e);
}
