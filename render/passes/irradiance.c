/* The receiver irradiance pass (issue 11; render/passes/PIPELINE.md "Receiver irradiance
 * cache"; the grid is render/core/recv_grid.h's, shared with the CPU twin): E_vpl per light at
 * unit intensity over every plane receiver, view-independent, redrawn only when the VPLs'
 * radiosity or the receivers change. Composition reads it with four fetches per receiver
 * pixel, so a camera or projector move costs no VPL sum.
 *
 * Owns its state (lr_irradiance); its inputs are the VPL targets, the receivers and the
 * material and cavity uniforms. */
#include "render/passes/irradiance.h"

#include <stdlib.h>

#include "render/bounce/objlight.h"
#include "render/bounce/rbounce.h"
#include "render/core/recv_grid.h"
#include "render/openings/openings.h"
#include "render/passes/radiosity.h"

/* Uploads the translucent-radiosity extra of every plane receiver and light (tr_scene.h) into
 * tr_E, or frees it when no object uses the model. */
static int tr_upload(lr_irradiance *irr, const lr_pass_ctx *c, const lr_radiosity *rad,
                     lr_err *e)
{
    lr_tex_destroy(irr->tr_E);
    irr->tr_E = NULL;
    if (!rad->tr || !irr->grid)
        return LR_OK;
    int w, h, layers, rc;
    lr_tex_size(irr->grid, &w, &h, &layers);
    lr_tex_desc td = {.type = LR_TEX_2D_ARRAY, .format = LR_TEX_RGBA32F, .width = w, .height = h,
                      .layers = layers, .label = "translucent radiosity receiver irradiance"};
    if ((rc = lr_tex_create(c->gl, &td, &irr->tr_E, e)))
        return rc;
    size_t n = (size_t)LR_RECV_GRID * LR_RECV_GRID;
    float *data = malloc(4 * n * sizeof *data);
    if (!data)
        return lr_err_set(e, LR_ENOMEM, "irradiance pass: out of memory");
    for (int i = 0; i < irr->n_receivers && !rc; i++) {
        if (irr->layer[i] < 0)
            continue;
        for (int l = 0; l < irr->n_lights && !rc; l++) {
            const float *E = lr_tr_scene_recv_E(rad->tr, i, l);
            for (size_t k = 0; k < n; k++)
                for (int b = 0; b < 4; b++)
                    data[4 * k + (size_t)b] = E && b < 3 ? E[3 * k + (size_t)b] : 0.0f;
            rc = lr_tex_upload(irr->tr_E, irr->layer[i] + l, data, e);
        }
    }
    free(data);
    return rc;
}

static void rl_free(lr_irradiance *irr)
{
    for (int i = 0; i < LR_MAX_OBJECTS; i++) {
        lr_tex_destroy(irr->rl[i]);
        lr_tex_destroy(irr->rlu[i]);
        irr->rl[i] = irr->rlu[i] = NULL;
        irr->rl_rows[i] = irr->rlu_rows[i] = 0;
    }
}

/* One texture of n entries (vertex k's values at entry k, or corner 3 t + c's from vertex
 * idx[3 t + c] when idx is given) for every light and side. */
static int rl_texture(const lr_pass_ctx *c, const lr_objlight *ol, int i, const uint32_t *idx,
                      size_t n, lr_tex **out, int *rows_out, lr_err *e)
{
    int L = c->n_lights, rows = (int)((n + LR_RL_TEX_WIDTH - 1) / LR_RL_TEX_WIDTH);
    rows = rows < 1 ? 1 : rows;
    size_t W = LR_RL_TEX_WIDTH, blk = (size_t)rows * W;
    float *data = calloc(blk * 2 * (size_t)L * 4, sizeof *data);
    if (!data)
        return lr_err_set(e, LR_ENOMEM, "irradiance pass: out of memory (objects' receiver light)");
    for (int l = 0; l < L; l++) {
        const float *E = lr_objlight_E(ol, i, l);
        for (size_t k = 0; E && k < n; k++) {
            size_t v = idx ? idx[k] : k;
            for (int s = 0; s < 2; s++)
                for (int b = 0; b < 3; b++)
                    data[4 * ((size_t)(2 * l + s) * blk + k) + (size_t)b] =
                        E[6 * v + 3 * (size_t)s + (size_t)b];
        }
    }
    lr_tex_desc d = {.type = LR_TEX_2D, .format = LR_TEX_RGBA32F, .width = LR_RL_TEX_WIDTH,
                     .height = rows * 2 * L, .label = "objects' receiver light"};
    int rc = lr_tex_create(c->gl, &d, out, e);
    if (!rc)
        rc = lr_tex_upload(*out, 0, data, e);
    free(data);
    *rows_out = rows;
    return rc;
}

/* The receivers' light on the objects of every solved slot, uploaded per object. */
static int rl_upload(lr_irradiance *irr, const lr_pass_ctx *c, lr_err *e)
{
    rl_free(irr);
    const lr_objlight *ol = lr_rbounce_objects(irr->rb);
    if (!ol || c->n_lights > LR_TR_MAX_SLOTS)
        return LR_OK;
    int rc = LR_OK;
    for (int i = 0; i < lr_objlight_count(ol) && i < LR_MAX_OBJECTS && !rc; i++) {
        const lr_mesh *m = lr_scene_object_at(c->scene, i)->mesh;
        rc = rl_texture(c, ol, i, NULL, lr_objlight_vertex_count(ol, i), &irr->rl[i],
                        &irr->rl_rows[i], e);
        if (!rc)
            rc = rl_texture(c, ol, i, lr_mesh_indices(m), 3 * lr_mesh_triangle_count(m),
                            &irr->rlu[i], &irr->rlu_rows[i], e);
    }
    return rc;
}

void lr_irradiance_bind_objects(const lr_irradiance *irr, const lr_pass_ctx *c, lr_program *p,
                                int object, bool unindexed, const float scale[LR_MAX_LIGHTS])
{
    const lr_tex *t = NULL;
    int rows = 0;
    if (irr && irr->valid && object >= 0 && object < LR_MAX_OBJECTS &&
        object < lr_scene_object_count(c->scene)) {
        t = unindexed ? irr->rlu[object] : irr->rl[object];
        rows = unindexed ? irr->rlu_rows[object] : irr->rl_rows[object];
    }
    lr_passes_uniform_i(p, "u_rl_on", t != NULL);
    lr_passes_bind_tex(p, "u_rl", 19, t);
    if (!t)
        return;
    lr_passes_uniform_i(p, "u_rl_rows", rows);
    double kR[3], kT[3];
    lr_objlight_factors(lr_scene_object_at(c->scene, object), kR, kT);
    float r[3 * LR_MAX_LIGHTS], tt[3 * LR_MAX_LIGHTS];
    for (int l = 0; l < LR_MAX_LIGHTS; l++)
        for (int b = 0; b < 3; b++) {
            r[3 * l + b] = (float)(kR[b] * scale[l]);
            tt[3 * l + b] = (float)(kT[b] * scale[l]);
        }
    lr_passes_uniform_v3_array(p, "u_rl_r", r, LR_MAX_LIGHTS);
    lr_passes_uniform_v3_array(p, "u_rl_t", tt, LR_MAX_LIGHTS);
}

/* Receiver inter-reflection (render/bounce/rbounce.h): each light's drawn grids (E_vpl at unit
 * intensity) read back, the receivers' radiosity solved with E = E_dir,l + E_vpl,l (slot l),
 * and the bounce E_b added to the grids in place; composition then reads it like E_vpl. */
static int bounce(lr_irradiance *irr, const lr_pass_ctx *c, const lr_radiosity *rad, lr_err *e)
{
    if (!lr_rbounce_needed(c->scene) && irr->rb) {
        lr_rbounce_destroy(irr->rb_parked);
        irr->rb_parked = irr->rb;
        irr->rb = NULL;
    } else if (lr_rbounce_needed(c->scene) && !irr->rb && irr->rb_parked) {
        irr->rb = irr->rb_parked; /* rebuilds only what changed since (keyed) */
        irr->rb_parked = NULL;
    }
    int rc = lr_rbounce_update(&irr->rb, c->scene, c->cancel, e);
    /* render.opening_light (render/openings/openings.h): rebuilt only when the geometry, a
     * light or a material changed; its grid joins E_vpl before the bounce reads it. */
    if (!rc)
        rc = lr_openings_update(&irr->op, c->scene, rad ? rad->dscene : NULL, 0, e);
    if (rc || !irr->rb)
        rl_free(irr); /* no bounce: no receiver light on the objects either */
    if (rc || (!irr->rb && !irr->op))
        return rc;
    const size_t n = (size_t)LR_RECV_GRID * LR_RECV_GRID;
    int nr = irr->n_receivers;
    float *buf = malloc((size_t)(nr ? nr : 1) * 4 * n * sizeof *buf);
    if (!buf)
        return lr_err_set(e, LR_ENOMEM, "irradiance pass: receiver bounce: out of memory");
    for (int l = 0; l < irr->n_lights && l < LR_TR_MAX_SLOTS && !rc; l++) {
        for (int i = 0; i < nr && !rc; i++) {
            if (irr->layer[i] < 0)
                continue;
            float *g = buf + (size_t)i * 4 * n;
            rc = lr_fb_read(irr->fb[i], l, 0, 0, LR_RECV_GRID, LR_RECV_GRID, g, e);
            const float *Eo = rc ? NULL : lr_openings_grid(irr->op, i, l);
            for (size_t k = 0; Eo && k < n; k++)
                for (int b = 0; b < 3; b++)
                    g[4 * k + (size_t)b] += Eo[3 * k + (size_t)b];
            if (irr->rb)
                lr_rbounce_vpl_f(irr->rb, i, rc ? NULL : g, 4);
        }
        double w[LR_MAX_LIGHTS][3] = {{0}};
        w[l][0] = w[l][1] = w[l][2] = 1.0; /* unit intensity: the dimmer stays blend-only */
        if (!rc && irr->rb)
            rc = lr_rbounce_solve(irr->rb, l, (const double(*)[3])w, e);
        for (int i = 0; i < nr && !rc; i++) {
            const float *Eb = irr->rb ? lr_rbounce_grid(irr->rb, i, l) : NULL;
            if (irr->layer[i] < 0 || (!Eb && !lr_openings_grid(irr->op, i, l)))
                continue;
            float *g = buf + (size_t)i * 4 * n;
            for (size_t k = 0; Eb && k < n; k++)
                for (int b = 0; b < 3; b++)
                    g[4 * k + (size_t)b] += Eb[3 * k + (size_t)b];
            rc = lr_tex_upload(irr->grid, irr->layer[i] + l, g, e);
        }
    }
    free(buf);
    /* The receivers' light on the objects (render/bounce/objlight.h), every slot solved. */
    if (!rc)
        rc = rl_upload(irr, c, e);
    return rc;
}

void lr_irradiance_free_grids(lr_irradiance *irr)
{
    rl_free(irr);
    for (int i = 0; i < LR_MAX_RECEIVERS; i++) {
        lr_fb_destroy(irr->fb[i]);
        irr->fb[i] = NULL;
        irr->layer[i] = -1;
    }
    lr_tex_destroy(irr->grid);
    irr->grid = NULL;
    lr_tex_destroy(irr->tr_E);
    irr->tr_E = NULL;
    irr->n_receivers = irr->n_lights = 0;
    irr->valid = false;
}

void lr_irradiance_free(lr_irradiance *irr)
{
    lr_irradiance_free_grids(irr);
    lr_rbounce_destroy(irr->rb);
    irr->rb = NULL;
    lr_rbounce_destroy(irr->rb_parked);
    irr->rb_parked = NULL;
    lr_openings_destroy(irr->op);
    irr->op = NULL;
}

static int alloc(lr_irradiance *irr, const lr_pass_ctx *c, lr_err *e)
{
    lr_irradiance_free_grids(irr); /* the bounce and the openings keep what still holds */
    int nl = c->n_lights, nr = c->objs->n_receivers, planes = 0, rc;
    for (int i = 0; i < nr; i++) {
        lr_recv_grid_frame f;
        irr->layer[i] = lr_recv_grid_frame_of(lr_scene_receiver_at(c->scene, i), &f)
                            ? nl * planes++ : -1;
    }
    irr->n_receivers = nr;
    irr->n_lights = nl;
    if (!planes || nl < 1)
        return LR_OK;
    lr_tex_desc td = {.type = LR_TEX_2D_ARRAY, .format = LR_TEX_RGBA32F, .width = LR_RECV_GRID,
                      .height = LR_RECV_GRID, .layers = planes * nl,
                      .label = "receiver irradiance grids"};
    if ((rc = lr_tex_create(c->gl, &td, &irr->grid, e)))
        return rc;
    for (int i = 0; i < nr; i++) {
        if (irr->layer[i] < 0)
            continue;
        lr_fb_desc fd = {.label = "receiver irradiance grid"};
        for (int l = 0; l < nl; l++)
            fd.color[l] = (lr_fb_attachment){irr->grid, irr->layer[i] + l};
        if ((rc = lr_fb_create(c->gl, &fd, &irr->fb[i], e)))
            return rc;
    }
    return LR_OK;
}

int lr_irradiance_run(lr_irradiance *irr, const lr_pass_ctx *c, const lr_vpl *v,
                      const lr_radiosity *rad, lr_err *e)
{
    int rc;
    if ((irr->n_receivers != c->objs->n_receivers || irr->n_lights != c->n_lights) &&
        (rc = alloc(irr, c, e)))
        return rc;
    /* Nothing to cache (no plane receiver, no VPLs): up to date as it is. */
    irr->valid = !irr->grid || c->no_vpl || !v->fb;
    if (irr->valid) {
        rl_free(irr); /* no bounce solved: no receiver light on the objects either */
        return LR_OK;
    }
    if ((rc = tr_upload(irr, c, rad, e)))
        return rc;
    lr_program *p = c->prog->irr;
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glUseProgram(lr_program_id(p));
    lr_passes_set_coeffs(c->objs, p);
    lr_passes_uniform_i(p, "u_n_lights", c->n_lights);
    lr_vpl_bind(v, c, rad, p);
    lr_passes_uniform_i(p, "u_grid_size", LR_RECV_GRID);
    lr_passes_uniform_i(p, "u_tr_on", irr->tr_E != NULL);
    lr_passes_bind_tex(p, "u_tr_E", 13, irr->tr_E);
    for (int i = 0; i < c->objs->n_receivers; i++) {
        lr_recv_grid_frame f;
        if (irr->layer[i] < 0 || !lr_recv_grid_frame_of(lr_scene_receiver_at(c->scene, i), &f))
            continue;
        lr_fb_bind(irr->fb[i]);
        lr_passes_uniform_v3(p, "u_grid_c", f.c);
        lr_passes_uniform_v3(p, "u_grid_wa", lr_v3_scale(f.a, f.w));
        lr_passes_uniform_v3(p, "u_grid_hb", lr_v3_scale(f.b, f.h));
        lr_passes_uniform_v3(p, "u_grid_n", lr_scene_receiver_at(c->scene, i)->normal);
        lr_passes_uniform_i(p, "u_tr_layer", irr->layer[i]);
        /* In bands of rows (slice.h): a cut leaves the grids invalid, and the pass, still
         * due, draws them whole at the next frame. */
        glEnable(GL_SCISSOR_TEST);
        for (int y = 0, rows; y < LR_RECV_GRID && !rc; y += rows) {
            rows = lr_slice_band(c->slicer, LR_SLICE_IRRADIANCE, y, LR_RECV_GRID);
            glScissor(0, y, LR_RECV_GRID, rows);
            lr_gl_draw_fullscreen(c->gl);
            rc = lr_slice_end(c->slicer, LR_CANCEL_STALE, "receiver irradiance pass", e);
        }
        glDisable(GL_SCISSOR_TEST);
        if (rc)
            return rc;
    }
    if ((rc = lr_gl_check("receiver irradiance pass", e)) || (rc = bounce(irr, c, rad, e)) ||
        (rc = lr_gl_check("receiver irradiance pass (bounce)", e)))
        return rc;
    irr->valid = true;
    return LR_OK;
}

void lr_irradiance_bind(const lr_irradiance *irr, const lr_pass_ctx *c, lr_program *p,
                        int receiver)
{
    lr_recv_grid_frame f;
    bool cached = irr->valid && irr->grid && receiver < irr->n_receivers &&
                  irr->layer[receiver] >= 0 &&
                  lr_recv_grid_frame_of(lr_scene_receiver_at(c->scene, receiver), &f);
    lr_passes_uniform_i(p, "u_cached", cached);
    lr_passes_bind_tex(p, "u_irr", 15, cached ? irr->grid : NULL);
    if (!cached)
        return;
    lr_passes_uniform_i(p, "u_irr_layer", irr->layer[receiver]);
    lr_passes_uniform_v3(p, "u_grid_c", f.c);
    lr_passes_uniform_v3(p, "u_grid_a", lr_v3_scale(f.a, 1.0 / f.w));
    lr_passes_uniform_v3(p, "u_grid_b", lr_v3_scale(f.b, 1.0 / f.h));
}
