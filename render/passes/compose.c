/* Pass 3 — composition (render/passes/PIPELINE.md): the camera's view of the objects
 * (Algorithm 1 over the K maps, L_o = I F_t B / pi) and of the receivers (direct light
 * shadowed through the light G-buffer, plus the VPLs), into a linear RGBA32F target; then
 * exposure, tone curve and sRGB into an RGBA8 target. The lights' intensities I_l (and the
 * cavity gains per light and object, PIPELINE.md "Energy") enter here and only here (each
 * light's maps and VPL row hold its unit-intensity transport, summed with weights I_l), so a
 * dimmer change re-runs this pass alone. */
#include <math.h>

#include "render/base/mat4.h"
#include "render/passes/passes.h"

int lr_compose_alloc(lr_renderer *r, lr_err *e)
{
    int rc;
    lr_tex_desc hdr = {.format = LR_TEX_RGBA32F, .width = r->width, .height = r->height,
                       .label = "HDR output"};
    lr_tex_desc ldr = {.format = LR_TEX_RGBA8, .width = r->width, .height = r->height,
                       .linear = true, .label = "tone-mapped output"};
    if ((rc = lr_tex_create(r->gl, &hdr, &r->hdr, e)) || (rc = lr_tex_create(r->gl, &ldr, &r->ldr, e)))
        return rc;
    lr_fb_desc fh = {.color = {{r->hdr, 0}}, .depth_buffer = true, .label = "HDR output"};
    lr_fb_desc fl = {.color = {{r->ldr, 0}}, .label = "tone-mapped output"};
    if ((rc = lr_fb_create(r->gl, &fh, &r->fb_hdr, e)) || (rc = lr_fb_create(r->gl, &fl, &r->fb_ldr, e)))
        return rc;
    return LR_OK;
}

void lr_compose_free(lr_renderer *r)
{
    lr_fb_destroy(r->fb_hdr);
    lr_fb_destroy(r->fb_ldr);
    lr_tex_destroy(r->hdr);
    lr_tex_destroy(r->ldr);
    r->fb_hdr = r->fb_ldr = NULL;
    r->hdr = r->ldr = NULL;
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
    const lr_camera *cam = lr_scene_camera(r->scene);
    double view[16], proj[16], vp[16];
    lr_camera_view(cam, view);
    lr_camera_projection(cam, (double)r->width / r->height, proj);
    lr_mat4_mul(proj, view, vp);
    lr_vec3 fwd = lr_v3_normalize(lr_v3_sub(cam->target, cam->position));

    lr_fb_bind(r->fb_hdr);
    glClearBufferfv(GL_COLOR, 0, zero);
    glClearDepthf(1.0f);
    glDepthMask(GL_TRUE);
    glClear(GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);

    const lr_program *p = r->p_obj;
    glUseProgram(lr_program_id(p));
    lr_passes_set_coeffs(r, p);
    double I[LR_MAX_LIGHTS][3];
    intensities(r, I);
    lr_passes_bind_gather(r, p, I);
    lr_passes_uniform_mat4(p, "u_vp", vp);
    lr_passes_uniform_v3(p, "u_eye", cam->position);
    lr_passes_uniform_v3(p, "u_view_dir", fwd);
    lr_passes_uniform_i(p, "u_ortho", cam->orthographic);
    for (int i = 0; i < r->n_objects; i++) {
        /* Object i's emission for light l times its cavity gain for l (PIPELINE.md "Energy"):
         * folded into the gather's per-light weights. */
        double w[LR_MAX_LIGHTS][3];
        for (int l = 0; l < LR_MAX_LIGHTS; l++)
            for (int c = 0; c < 3; c++)
                w[l][c] = I[l][c] * r->cavity_gain[3 * (l * LR_MAX_OBJECTS + i) + c];
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
    bool use_vpl = !r->no_vpl && r->vpl.fb;
    lr_passes_uniform_i(p, "u_use_vpl", use_vpl);
    lr_passes_uniform_i(p, "u_n_vpl", r->vpl.n);
    lr_passes_bind_tex(p, "u_vpl_pos", 7, use_vpl ? r->vpl.pos : NULL);
    lr_passes_bind_tex(p, "u_vpl_nrm", 8, use_vpl ? r->vpl.nrm : NULL);
    lr_passes_bind_tex(p, "u_vpl_B", 9, use_vpl ? r->vpl.B : NULL);
    lr_passes_uniform_i(p, "u_vpl_vis", use_vpl && r->vpl_visibility);
    lr_passes_bind_tex(p, "u_outer_pos", 10, use_vpl ? r->vpl.outer_pos : NULL);
    lr_passes_uniform_v3(p, "u_center", r->vpl.center);
    lr_passes_uniform_f(p, "u_vis_eps", (float)(2.0 * r->rad.radius / (r->vpl.size > 0 ? r->vpl.size : 1)));
    for (int i = 0; i < r->n_receivers; i++) {
        const lr_receiver *rc = lr_scene_receiver_at(r->scene, i);
        GLint loc = lr_program_uniform(p, "u_albedo");
        if (loc >= 0)
            glUniform3f(loc, (float)rc->albedo[0], (float)rc->albedo[1], (float)rc->albedo[2]);
        lr_passes_draw(&r->recv[i]);
    }

    /* Tone mapping. */
    glDisable(GL_DEPTH_TEST);
    lr_fb_bind(r->fb_ldr);
    p = r->p_tonemap;
    glUseProgram(lr_program_id(p));
    lr_passes_bind_tex(p, "u_hdr", 0, r->hdr);
    lr_passes_uniform_f(p, "u_exposure", (float)r->rs.exposure);
    lr_passes_uniform_i(p, "u_op", LR_RENDER_TONEMAP);
    lr_gl_draw_fullscreen(r->gl);
    return lr_gl_check("compose pass", e);
}
