/* The receiver irradiance pass (issue 11; render/passes/PIPELINE.md "Receiver irradiance
 * cache"; the grid is render/cpu/recv_grid.h's, shared with the CPU twin): E_vpl per light at
 * unit intensity over every plane receiver, view-independent, redrawn only when the VPLs'
 * radiosity or the receivers change. Composition reads it with four fetches per receiver
 * pixel, so a camera or projector move costs no VPL sum.
 *
 * Owns its state (r->irr: the grid array and one framebuffer per plane receiver, allocated on
 * first use and again when the number of receivers or lights changes), in the shape issue 15
 * asks of passes; its inputs are the VPL targets, the receivers and the material and cavity
 * uniforms. */
#include "render/cpu/recv_grid.h"
#include "render/passes/passes.h"

void lr_irradiance_free(lr_renderer *r)
{
    for (int i = 0; i < LR_MAX_RECEIVERS; i++) {
        lr_fb_destroy(r->irr.fb[i]);
        r->irr.fb[i] = NULL;
        r->irr.layer[i] = -1;
    }
    lr_tex_destroy(r->irr.grid);
    r->irr.grid = NULL;
    r->irr.n_receivers = r->irr.n_lights = 0;
    r->irr.valid = false;
}

static int alloc(lr_renderer *r, lr_err *e)
{
    lr_irradiance_free(r);
    int nl = r->n_lights, planes = 0, rc;
    for (int i = 0; i < r->n_receivers; i++) {
        lr_recv_grid_frame f;
        r->irr.layer[i] = lr_recv_grid_frame_of(lr_scene_receiver_at(r->scene, i), &f)
                              ? nl * planes++ : -1;
    }
    r->irr.n_receivers = r->n_receivers;
    r->irr.n_lights = nl;
    if (!planes || nl < 1)
        return LR_OK;
    lr_tex_desc td = {.type = LR_TEX_2D_ARRAY, .format = LR_TEX_RGBA32F, .width = LR_RECV_GRID,
                      .height = LR_RECV_GRID, .layers = planes * nl,
                      .label = "receiver irradiance grids"};
    if ((rc = lr_tex_create(r->gl, &td, &r->irr.grid, e)))
        return rc;
    for (int i = 0; i < r->n_receivers; i++) {
        if (r->irr.layer[i] < 0)
            continue;
        lr_fb_desc fd = {.label = "receiver irradiance grid"};
        for (int l = 0; l < nl; l++)
            fd.color[l] = (lr_fb_attachment){r->irr.grid, r->irr.layer[i] + l};
        if ((rc = lr_fb_create(r->gl, &fd, &r->irr.fb[i], e)))
            return rc;
    }
    return LR_OK;
}

/* The VPL inputs of lib/vpl_irradiance.glsl (units 7..10), shared with composition. */
void lr_passes_bind_vpls(lr_renderer *r, const lr_program *p)
{
    bool use_vpl = !r->no_vpl && r->vpl.fb;
    lr_passes_uniform_i(p, "u_use_vpl", use_vpl);
    lr_passes_uniform_i(p, "u_n_vpl", r->vpl.n);
    lr_passes_bind_tex(p, "u_vpl_pos", 7, use_vpl ? r->vpl.pos : NULL);
    lr_passes_bind_tex(p, "u_vpl_nrm", 8, use_vpl ? r->vpl.nrm : NULL);
    lr_passes_bind_tex(p, "u_vpl_B", 9, use_vpl ? r->vpl.B : NULL);
    lr_passes_uniform_i(p, "u_vpl_vis", use_vpl && r->vpl_visibility);
    lr_passes_bind_tex(p, "u_outer_pos", 10, use_vpl ? r->vpl.outer_pos : NULL);
    lr_passes_uniform_v3(p, "u_center", r->vpl.center);
    lr_passes_uniform_f(p, "u_vis_eps",
                        (float)(2.0 * r->rad.radius / (r->vpl.size > 0 ? r->vpl.size : 1)));
}

int lr_pass_irradiance(lr_renderer *r, lr_err *e)
{
    int rc;
    if ((r->irr.n_receivers != r->n_receivers || r->irr.n_lights != r->n_lights) &&
        (rc = alloc(r, e)))
        return rc;
    /* Nothing to cache (no plane receiver, no VPLs): up to date as it is. */
    r->irr.valid = !r->irr.grid || r->no_vpl || !r->vpl.fb;
    if (r->irr.valid)
        return LR_OK;
    const lr_program *p = r->p_irr;
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glUseProgram(lr_program_id(p));
    lr_passes_set_coeffs(r, p);
    lr_passes_uniform_i(p, "u_n_lights", r->n_lights);
    lr_passes_bind_vpls(r, p);
    lr_passes_uniform_i(p, "u_grid_size", LR_RECV_GRID);
    for (int i = 0; i < r->n_receivers; i++) {
        lr_recv_grid_frame f;
        if (r->irr.layer[i] < 0 || !lr_recv_grid_frame_of(lr_scene_receiver_at(r->scene, i), &f))
            continue;
        lr_fb_bind(r->irr.fb[i]);
        lr_passes_uniform_v3(p, "u_grid_c", f.c);
        lr_passes_uniform_v3(p, "u_grid_wa", lr_v3_scale(f.a, f.w));
        lr_passes_uniform_v3(p, "u_grid_hb", lr_v3_scale(f.b, f.h));
        lr_passes_uniform_v3(p, "u_grid_n", lr_scene_receiver_at(r->scene, i)->normal);
        lr_gl_draw_fullscreen(r->gl);
    }
    if ((rc = lr_gl_check("receiver irradiance pass", e)))
        return rc;
    r->irr.valid = true;
    return LR_OK;
}

void lr_passes_bind_irradiance(lr_renderer *r, const lr_program *p, int receiver)
{
    lr_recv_grid_frame f;
    bool cached = r->irr.valid && r->irr.grid && receiver < r->irr.n_receivers &&
                  r->irr.layer[receiver] >= 0 &&
                  lr_recv_grid_frame_of(lr_scene_receiver_at(r->scene, receiver), &f);
    lr_passes_uniform_i(p, "u_cached", cached);
    lr_passes_bind_tex(p, "u_irr", 15, cached ? r->irr.grid : NULL);
    if (!cached)
        return;
    lr_passes_uniform_i(p, "u_irr_layer", r->irr.layer[receiver]);
    lr_passes_uniform_v3(p, "u_grid_c", f.c);
    lr_passes_uniform_v3(p, "u_grid_a", lr_v3_scale(f.a, 1.0 / f.w));
    lr_passes_uniform_v3(p, "u_grid_b", lr_v3_scale(f.b, 1.0 / f.h));
}
