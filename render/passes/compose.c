/* Pass 3 — composition (render/passes/PIPELINE.md): the camera's view of the objects
 * (Algorithm 1 over the K maps, L_o = F_t B / pi) and of the receivers (direct light
 * shadowed through the light G-buffer, plus the VPLs), one linear RGBA32F image per light for
 * unit intensity (multiple render targets: one draw per mesh fills every light's image). The
 * cavity gains per light and object (PIPELINE.md "Energy") are in the images; with
 * render.surface_cache the objects' B comes from the surface pass (surface.h) instead of a
 * per-pixel gather; the lights'
 * intensity x colour x flicker enter only in the blend pass (blend.h), so a dimmer change runs
 * that fullscreen pass alone (issue 11). */
#include <math.h>

#include "render/base/mat4.h"
#include "render/passes/compose.h"

void lr_compose_free(lr_compose *img)
{
    lr_fb_destroy(img->fb);
    lr_tex_destroy(img->images);
    img->fb = NULL;
    img->images = NULL;
    img->n = 0;
    img->valid = false;
}

/* Images for n lights (a 2D array, one colour attachment per layer, one depth buffer). */
static int images_alloc(lr_compose *img, const lr_pass_ctx *c, int n, lr_err *e)
{
    lr_compose_free(img);
    if (n < 1 || n > LR_MAX_LIGHTS || n > c->caps->max_draw_buffers)
        return lr_err_set(e, LR_EUNSUPPORTED,
                          "compose: %d lights; takes 1..%d (and the driver %d draw buffers)", n,
                          LR_MAX_LIGHTS, c->caps->max_draw_buffers);
    /* RGBA32F: half floats (half the bytes for the blend) were tried and measured no faster
     * on llvmpipe, which truncates on the store (-2e-4 relative, beyond the 1e-4 of
     * test_render_emergent). The images hold S_l L_l (lr_compose.scale), which would put them
     * in fp16's normal range (PIPELINE.md "Blend"). */
    lr_tex_desc td = {.type = LR_TEX_2D_ARRAY, .format = LR_TEX_RGBA32F, .width = c->width,
                      .height = c->height, .layers = n, .label = "per-light images"};
    int rc = lr_tex_create(c->gl, &td, &img->images, e);
    if (rc)
        return rc;
    lr_fb_desc fd = {.depth_buffer = true, .label = "per-light images"};
    for (int l = 0; l < n; l++)
        fd.color[l] = (lr_fb_attachment){img->images, l};
    if ((rc = lr_fb_create(c->gl, &fd, &img->fb, e)))
        return rc;
    img->n = n;
    for (int l = 0; l < LR_MAX_LIGHTS; l++)
        img->scale[l] = 1.0f;
    return LR_OK;
}

int lr_compose_alloc(lr_compose *img, const lr_pass_ctx *c, lr_err *e)
{
    return images_alloc(img, c, lr_scene_light_count(c->scene), e);
}

/* Object i's emission for light l times its cavity gain for l (PIPELINE.md "Energy") and the
 * image's scale S_l. */
static void cavity_w(const lr_compose *img, const lr_pass_objects *o, int i,
                     double w[LR_MAX_LIGHTS][3])
{
    for (int l = 0; l < LR_MAX_LIGHTS; l++)
        for (int b = 0; b < 3; b++)
            w[l][b] = o->cavity_gain[3 * (l * LR_MAX_OBJECTS + i) + b] * img->scale[l];
}

/* Algorithm 1 per pixel (compose_object.frag): the cavity gains are the gather's per-light
 * weights. */
static void draw_objects_gather(const lr_compose *img, const lr_radiosity *rad,
                                const lr_lpv_pass *lpv, const lr_irradiance *irr,
                                const lr_pass_ctx *c, lr_program *p)
{
    const lr_pass_objects *o = c->objs;
    double unit[LR_MAX_LIGHTS][3];
    for (int l = 0; l < LR_MAX_LIGHTS; l++)
        for (int b = 0; b < 3; b++)
            unit[l][b] = 1.0;
    lr_radiosity_bind_gather(rad, p, unit);
    for (int i = 0; i < o->n_objects; i++) {
        double w[LR_MAX_LIGHTS][3];
        cavity_w(img, o, i, w);
        lr_radiosity_set_light_w(rad, p, w);
        lr_lpv_pass_bind_objects(lpv, c, p, i, img->scale);
        lr_irradiance_bind_objects(irr, c, p, i, false, img->scale);
        lr_passes_uniform_i(p, "u_object", i);
        lr_passes_uniform_i(p, "u_two_sided", o->two_sided[i]);
        lr_passes_draw(&o->obj[i]);
    }
}

/* B from the surface cache, looked up per pixel in the lattice of the pixel's triangle
 * (compose_cached.vert/.frag, render/mesh/lattice.h): no gather, and no refined mesh to
 * rasterise. */
static void draw_objects_cached(const lr_compose *img, const lr_surface *sc,
                                const lr_lpv_pass *lpv, const lr_irradiance *irr,
                                const lr_pass_ctx *c, lr_program *p)
{
    const lr_pass_objects *o = c->objs;
    lr_surface_bind(sc, p);
    for (int i = 0; i < o->n_objects && i < sc->n_objects; i++) {
        double w[LR_MAX_LIGHTS][3];
        float g[3 * LR_MAX_LIGHTS];
        cavity_w(img, o, i, w);
        for (int l = 0; l < LR_MAX_LIGHTS; l++)
            for (int b = 0; b < 3; b++)
                g[3 * l + b] = (float)w[l][b];
        lr_passes_uniform_v3_array(p, "u_gain", g, LR_MAX_LIGHTS);
        lr_lpv_pass_bind_objects(lpv, c, p, i, img->scale);
        lr_irradiance_bind_objects(irr, c, p, i, true, img->scale);
        lr_passes_uniform_i(p, "u_object", i);
        lr_passes_uniform_i(p, "u_two_sided", o->two_sided[i]);
        lr_passes_uniform_i(p, "u_nv", sc->nv[i]);
        lr_surface_draw(sc, i);
    }
}

int lr_compose_run(lr_compose *img, const lr_pass_ctx *c, const lr_compose_inputs *in,
                   lr_err *e)
{
    /* Alpha 1 everywhere but on object fragments no map sees (compose_object.frag writes 0
     * there): lr_renderer_debug_uncovered counts them. */
    static const float zero[4] = {0, 0, 0, 1};
    int rc;
    if (img->n != c->n_lights && (rc = images_alloc(img, c, c->n_lights, e)))
        return rc;
    const lr_pass_objects *o = c->objs;
    const lr_camera *cam = lr_scene_camera(c->scene);
    double view[16], proj[16], vp[16];
    lr_camera_view(cam, view);
    lr_camera_projection(cam, (double)c->width / c->height, proj);
    lr_mat4_mul(proj, view, vp);
    lr_vec3 fwd = lr_v3_normalize(lr_v3_sub(cam->target, cam->position));

    /* The maps' own scale per light (B R^2 for point and spot lights; radiosity.h). */
    for (int l = 0; l < LR_MAX_LIGHTS; l++)
        img->scale[l] = l < in->radiosity->n_lights && in->radiosity->scale[l] > 0.0f
                            ? in->radiosity->scale[l]
                            : 1.0f;
    lr_fb_bind(img->fb);
    for (int l = 0; l < img->n; l++)
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
    lr_program *p = in->surface ? c->prog->obj_cached[in->surface->n_lights - 1] : c->prog->obj;
    glUseProgram(lr_program_id(p));
    lr_passes_set_coeffs(o, p);
    lr_passes_uniform_mat4(p, "u_vp", vp);
    lr_passes_uniform_v3(p, "u_eye", cam->position);
    lr_passes_uniform_v3(p, "u_view_dir", fwd);
    lr_passes_uniform_i(p, "u_ortho", cam->orthographic);
    img->gathered = !in->surface;
    if (in->surface)
        draw_objects_cached(img, in->surface, in->lpv, in->irradiance, c, p);
    else
        draw_objects_gather(img, in->radiosity, in->lpv, in->irradiance, c, p);

    p = c->prog->recv[img->n - 1];
    glUseProgram(lr_program_id(p));
    lr_passes_set_coeffs(o, p);
    lr_gbuffer_bind_lights(in->gbuffer, c, p);
    lr_passes_uniform_mat4(p, "u_vp", vp);
    lr_passes_uniform_i(p, "u_use_vpl", lr_vpl_bind(in->vpl, c, in->radiosity, p));
    GLint sl = lr_program_uniform(p, "u_image_scale");
    if (sl < 0)
        sl = lr_program_uniform(p, "u_image_scale[0]");
    if (sl >= 0)
        glUniform1fv(sl, LR_MAX_LIGHTS, img->scale);
    for (int i = 0; i < o->n_receivers; i++) {
        lr_irradiance_bind(in->irradiance, c, p, i);
        lr_area_direct_bind(in->area, c, p, i);
        const lr_receiver *rcv = lr_scene_receiver_at(c->scene, i);
        GLint loc = lr_program_uniform(p, "u_albedo");
        if (loc >= 0)
            glUniform3f(loc, (float)rcv->albedo[0], (float)rcv->albedo[1], (float)rcv->albedo[2]);
        lr_passes_draw(&o->recv[i]);
    }
    glDisable(GL_DEPTH_TEST);
    if ((rc = lr_gl_check("compose pass", e)))
        return rc;
    img->valid = true;
    return LR_OK;
}
