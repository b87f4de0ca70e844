/* Pass 2 — scattered-radiosity maps (render/passes/PIPELINE.md): K orthographic views along
 * d_k = lr_halton_sphere(k + 1) of the objects' bounding sphere. Each frame adds one N-sample
 * estimate per texel and colour band; the maps keep the running mean through the constant
 * blend colour 1/F (GL_CONSTANT_ALPHA), so values stay O(B) over any number of frames.
 * A depth-only prepass at restart fixes each texel's visible surface (seed 003 Sec. 3.2);
 * the depth stays for composition's visibility test.
 *
 * Several lights: each light l has its own K maps of B for unit intensity (layers l K + k of
 * one 2D array texture; x_o, n_o and depth are shared), so that a dimmer change still
 * re-weights them at composition only (transport is linear in each light's intensity). Memory:
 * K map_size^2 RGBA32F texels per light (16 MB at K = 16, 256^2). The per-texel seeds do not
 * depend on the light's index: light l's maps are the same whether or not the other lights
 * exist, so a two-light render is the sum of the two one-light renders. */
#include <math.h>
#include <stdlib.h>

#include "render/base/mat4.h"
#include "render/diffusion/dscene.h"
#include "render/models/twin/radiosity.h"
#include "render/optics/optics.h"
#include "render/passes/radiosity.h"

/* Texture unit of the diffusion grid's field: above the G-buffer's (0-3), the gather's (4-10)
 * and the lights' arrays (11-14), within the 16 units GLES 3.1 guarantees. */
#define LR_DGRID_TEX_UNIT 15

int lr_radiosity_alloc(lr_radiosity *rad, const lr_pass_ctx *c, lr_err *e)
{
    int K = c->rs->K, n = c->rs->map_size, rc;
    if (K > LR_MAX_K)
        return lr_err_set(e, LR_EUNSUPPORTED, "render.K = %d: at most %d maps", K, LR_MAX_K);
    rad->K = K;
    rad->size = n;
    int L = c->n_lights;
    rad->n_lights = L;
    lr_tex_desc d = {.type = LR_TEX_2D_ARRAY, .format = c->map_format, .width = n, .height = n,
                     .layers = K * L, .label = "radiosity maps"};
    if ((rc = lr_tex_create(c->gl, &d, &rad->B, e)))
        return rc;
    d.format = LR_TEX_RGBA32F;
    d.label = "radiosity map positions";
    if ((rc = lr_tex_create(c->gl, &d, &rad->pos, e)))
        return rc;
    d.label = "radiosity map normals";
    if ((rc = lr_tex_create(c->gl, &d, &rad->nrm, e)))
        return rc;
    d.format = LR_TEX_DEPTH32F;
    d.label = "radiosity map depth";
    if ((rc = lr_tex_create(c->gl, &d, &rad->depth, e)))
        return rc;
    for (int l = 0; l < L; l++)
        for (int k = 0; k < K; k++) {
            lr_fb_desc fd = {.color = {{rad->B, l * K + k}, {rad->pos, k}, {rad->nrm, k}},
                             .depth = {rad->depth, k}, .label = "radiosity map"};
            if ((rc = lr_fb_create(c->gl, &fd, &rad->fb[l * K + k], e)))
                return rc;
            lr_fb_desc ad = {.color = {{rad->B, l * K + k}}, .depth = {rad->depth, k},
                             .label = "radiosity map accumulation"};
            if ((rc = lr_fb_create(c->gl, &ad, &rad->acc[l * K + k], e)))
                return rc;
        }
    rad->F = 0;
    return LR_OK;
}

void lr_radiosity_release(lr_radiosity *rad)
{
    for (int k = 0; k < LR_MAX_LIGHTS * LR_MAX_K; k++) {
        lr_fb_destroy(rad->fb[k]);
        lr_fb_destroy(rad->acc[k]);
        rad->fb[k] = rad->acc[k] = NULL;
    }
    for (int i = 0; i < LR_MAX_OBJECTS; i++) {
        lr_tex_destroy(rad->trB[i]);
        rad->trB[i] = NULL;
        lr_tex_destroy(rad->dg_tex[i]);
        rad->dg_tex[i] = NULL;
    }
    lr_tex_destroy(rad->B);
    lr_tex_destroy(rad->pos);
    lr_tex_destroy(rad->nrm);
    lr_tex_destroy(rad->depth);
    rad->B = rad->pos = rad->nrm = rad->depth = NULL;
    rad->F = 0;
}

void lr_radiosity_free(lr_radiosity *rad)
{
    lr_radiosity_release(rad);
    lr_tr_scene_destroy(rad->tr);
    rad->tr = NULL;
    lr_dscene_destroy(rad->dscene);
    rad->dscene = NULL;
}

/* Map cameras from the current geometry: orthographic, looking at the bounding sphere's
 * centre from d_k, frustum around the sphere (depth range [R, 3R] from an eye at 2R). */
static void place_maps(lr_radiosity *rad, const lr_pass_ctx *ctx, const lr_gbuffer *gb)
{
    lr_vec3 c;
    double R;
    lr_scene_bounds(ctx->scene, &c, &R);
    R = fmax(R, 1e-3);
    rad->center = c;
    rad->radius = R;
    rad->r_max = 20.0 * R;
    double S[16] = {0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 0.5, 0, 0.5, 0.5, 0.5, 1};
    for (int k = 0; k < rad->K; k++) {
        lr_vec3 d = lr_halton_sphere((unsigned)k + 1);
        rad->d[k] = d;
        double view[16], proj[16];
        lr_vec3 up = fabs(d.z) > 0.99 ? lr_v3(0.0, 1.0, 0.0) : lr_v3(0.0, 0.0, 1.0);
        lr_mat4_look_at(lr_v3_add(c, lr_v3_scale(d, 2.0 * R)), c, up, view);
        lr_mat4_ortho(-R, R, -R, R, R, 3.0 * R, proj);
        lr_mat4_mul(proj, view, rad->vp[k]);
        lr_mat4_mul(S, rad->vp[k], rad->P[k]);
        lr_mat4_to_float(rad->P[k], rad->Pf + 16 * k);
        rad->df[3 * k] = (float)d.x;
        rad->df[3 * k + 1] = (float)d.y;
        rad->df[3 * k + 2] = (float)d.z;
    }
    /* Maps hold B for a unit light: ~1/d^2 W/mm^2 for a point light at d mm, 1e-4..1e-6 in
     * the shipped scenes, below half floats' normal range (6e-5) and flushed to zero by some
     * drivers. They store B R^2 instead (O(1) at the bounding radius); directional lights
     * (unit radiance, B ~ 1) store B. */
    for (int l = 0; l < rad->n_lights; l++)
        rad->scale[l] = gb->light[l].type == LR_LIGHT_DIRECTIONAL ? 1.0f : (float)(R * R);
    double texel = 2.0 * R / rad->size;
    rad->eps_comb = (float)texel;
    rad->eps_bias = (float)(2.0 * texel / (2.0 * R)); /* two texels, in depth units */
}

/* Seed 001: solve the diffusion_grid objects for every light (warm-started, dscene.h) and
 * upload their fields. Runs when the maps restart: a light, material or geometry change. */
static int dgrid_update(lr_radiosity *rad, const lr_pass_ctx *c, lr_err *e)
{
    bool any = false;
    int n = lr_scene_object_count(c->scene), rc;
    for (int i = 0; i < n && i < LR_MAX_OBJECTS; i++)
        any |= lr_sss_model_props_of(lr_scene_object_at(c->scene, i)->sss_model)->grid_field;
    if (!any && !rad->dscene)
        return LR_OK;
    if (!rad->dscene && (rc = lr_dscene_create(&rad->dscene, e)))
        return rc;
    lr_dscene_set_cancel(rad->dscene, c->cancel);
    if ((rc = lr_dscene_update(rad->dscene, c->scene, e)))
        return rc;
    for (int i = 0; i < LR_MAX_OBJECTS; i++) {
        lr_dfield_view v;
        if (!lr_dscene_field(rad->dscene, i, 0, &v)) {
            lr_tex_destroy(rad->dg_tex[i]);
            rad->dg_tex[i] = NULL;
            continue;
        }
        int L = rad->n_lights;
        if (!rad->dg_tex[i] || rad->dg_dims[i][0] != v.n[0] || rad->dg_dims[i][1] != v.n[1] ||
            rad->dg_dims[i][2] != v.n[2] || rad->dg_lights[i] != L) {
            lr_tex_destroy(rad->dg_tex[i]);
            rad->dg_tex[i] = NULL;
            lr_tex_desc d = {.type = LR_TEX_2D_ARRAY, .format = LR_TEX_RGBA32F, .width = v.n[0],
                             .height = v.n[1], .layers = v.n[2] * L,
                             .label = "diffusion grid field"};
            if ((rc = lr_tex_create(c->gl, &d, &rad->dg_tex[i], e)))
                return lr_err_prefix(e, "objects[%d]: diffusion_grid (%d x %d x %d nodes, %d lights)",
                                     i, v.n[0], v.n[1], v.n[2], L);
            for (int a = 0; a < 3; a++)
                rad->dg_dims[i][a] = v.n[a];
            rad->dg_lights[i] = L;
        }
        for (int l = 0; l < L; l++) {
            if (!lr_dscene_field(rad->dscene, i, l, &v))
                continue;
            for (int z = 0; z < v.n[2]; z++)
                if ((rc = lr_tex_upload(rad->dg_tex[i], l * v.n[2] + z,
                                        v.data + (size_t)4 * v.n[0] * v.n[1] * z, e)))
                    return rc;
        }
    }
    return LR_OK;
}

/* The running mean's weight for frame F: 1/F. For RGBA16F maps the GPU may evaluate the blend
 * factors in half precision, where 1 - 1/F is not representable (fp16 has 11 bits below 1):
 * rounded the same way every frame, it would scale the mean by up to (1 +- 2^-12) per frame,
 * a drift of tens of percent over a thousand frames. There the weight is rounded to a
 * multiple of 2^-11, so that both it and 1 - it are exact; the estimate stays a weighted mean
 * whose weights sum to 1 (unbiased), and from F = 2048 on it is an exponential average over
 * ~2048 frames. */
float lr_radiosity_blend_weight(lr_tex_format format, int F)
{
    if (format != LR_TEX_RGBA16F)
        return (float)(1.0 / F);
    double k = floor(2048.0 / F + 0.5);
    return (float)((k < 1.0 ? 1.0 : k) / 2048.0);
}

/* Translucent radiosity: solve (the solver is rebuilt only when geometry or materials
 * changed) and upload each such object's per-vertex B, light l's block at rows l tr_rows. */
static int tr_refresh(lr_radiosity *rad, const lr_pass_ctx *c, lr_err *e)
{
    int rc = lr_tr_scene_update(&rad->tr, c->scene, c->cancel, e);
    for (int i = 0; i < LR_MAX_OBJECTS; i++) {
        lr_tex_destroy(rad->trB[i]);
        rad->trB[i] = NULL;
    }
    if (rc || !rad->tr)
        return rc;
    for (int i = 0; i < c->objs->n_objects && i < LR_MAX_OBJECTS; i++) {
        if (!lr_tr_scene_vertex_B(rad->tr, i, 0))
            continue;
        const lr_mesh *m = lr_scene_object_at(c->scene, i)->mesh;
        int nv = (int)lr_mesh_vertex_count(m), rows = (nv + LR_TR_TEX_WIDTH - 1) / LR_TR_TEX_WIDTH;
        int L = rad->n_lights;
        float *data = calloc((size_t)LR_TR_TEX_WIDTH * (size_t)rows * (size_t)L * 4, sizeof *data);
        if (!data)
            return lr_err_set(e, LR_ENOMEM, "radiosity pass: out of memory (vertex B)");
        for (int l = 0; l < L; l++) {
            const float *vB = lr_tr_scene_vertex_B(rad->tr, i, l);
            for (int v = 0; vB && v < nv; v++)
                for (int b = 0; b < 3; b++)
                    data[4 * ((size_t)l * rows * LR_TR_TEX_WIDTH + (size_t)v) + (size_t)b] =
                        vB[3 * (size_t)v + (size_t)b];
        }
        lr_tex_desc d = {.type = LR_TEX_2D, .format = LR_TEX_RGBA32F, .width = LR_TR_TEX_WIDTH,
                         .height = rows * L, .label = "translucent radiosity vertex B"};
        rc = lr_tex_create(c->gl, &d, &rad->trB[i], e);
        if (!rc)
            rc = lr_tex_upload(rad->trB[i], 0, data, e);
        free(data);
        if (rc)
            return rc;
        rad->tr_rows[i] = rows;
    }
    return LR_OK;
}

/* What the maps draw of object i: its surface as built, except where its B comes per vertex
 * of the refined copy (translucent radiosity's u_tr_B by gl_VertexID) or the scene did not
 * refine it (lr_pass_objects.built). The depth prepass and the gather draw the same, so
 * their depths agree. */
static const lr_gpu_mesh *radiosity_mesh(const lr_pass_ctx *c, const lr_radiosity *rad, int i)
{
    bool per_vertex = i < LR_MAX_OBJECTS && rad->trB[i];
    return !per_vertex && c->objs->built[i].vao ? &c->objs->built[i] : &c->objs->obj[i];
}

/* The objects into light l's map, with the program's per-map uniforms already set. */
static void draw_objects(const lr_radiosity *rad, const lr_pass_ctx *c, lr_program *p, int l)
{
    for (int i = 0; i < c->objs->n_objects; i++) {
        if (rad->dg_tex[i]) {
            lr_dfield_view v;
            lr_dscene_field(rad->dscene, i, l, &v);
            lr_passes_bind_tex(p, "u_dg_field", LR_DGRID_TEX_UNIT, rad->dg_tex[i]);
            lr_passes_uniform_v3(p, "u_dg_origin", v.origin);
            lr_passes_uniform_f(p, "u_dg_h", (float)v.h);
            glUniform3i(lr_program_uniform(p, "u_dg_dims"), v.n[0], v.n[1], v.n[2]);
            lr_passes_uniform_i(p, "u_dg_layer0", l * v.n[2]);
        }
        lr_passes_uniform_i(p, "u_object", i);
        lr_passes_uniform_i(p, "u_two_sided", c->objs->two_sided[i]);
        bool tr = i < LR_MAX_OBJECTS && rad->trB[i];
        lr_passes_uniform_i(p, "u_tr_on", tr);
        lr_passes_bind_tex(p, "u_tr_B", 10, tr ? rad->trB[i] : NULL);
        lr_passes_uniform_i(p, "u_tr_row0", tr ? l * rad->tr_rows[i] : 0);
        lr_passes_draw(radiosity_mesh(c, rad, i));
    }
}

int lr_radiosity_run(lr_radiosity *rad, const lr_pass_ctx *c, const lr_gbuffer *gb, bool restart,
                     lr_err *e)
{
    static const GLenum all[3] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2};
    static const float zero[4] = {0, 0, 0, 0};
    if (restart || rad->F == 0) {
        place_maps(rad, c, gb);
        rad->F = 0;
        int rc = tr_refresh(rad, c, e);
        if (!rc)
            rc = dgrid_update(rad, c, e);
        if (!rc)
            rc = lr_radiosity_sh_project(rad, c, gb, e);
        if (rc)
            return rc;
        /* radiosity.frag's branches: per-vertex B (u_tr_on) and the models without a profile
         * (the grid's field, SH) are drawn without a sample; every other object is sampled
         * afresh at each frame (u_frame). */
        rad->sampled = false;
        for (int i = 0; i < c->objs->n_objects; i++) {
            bool per_vertex = i < LR_MAX_OBJECTS && rad->trB[i];
            enum lr_sss_model m = lr_scene_object_at(c->scene, i)->sss_model;
            if (!per_vertex && !lr_sss_model_props_of(m)->no_profile)
                rad->sampled = true;
        }
    }
    int F = rad->F + 1;
    int K = rad->K, cut = LR_OK;
    glDisable(GL_CULL_FACE);
    glEnable(GL_DEPTH_TEST);
    for (int k = 0; k < K; k++)
        for (int l = 0; l < rad->n_lights; l++) {
            if (F == 1 && l == 0) {
                lr_fb_bind(rad->fb[l * K + k]);
                glDrawBuffers(3, all);
                glClearBufferfv(GL_COLOR, 0, zero);
                glClearBufferfv(GL_COLOR, 1, zero);
                glClearBufferfv(GL_COLOR, 2, zero);
                glDepthMask(GL_TRUE);
                glClearDepthf(1.0f);
                glClear(GL_DEPTH_BUFFER_BIT);
                /* Depth-only prepass. */
                glUseProgram(lr_program_id(c->prog->depth));
                glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
                glDepthFunc(GL_LESS);
                lr_passes_uniform_mat4(c->prog->depth, "u_vp", rad->vp[k]);
                for (int i = 0; i < c->objs->n_objects; i++)
                    lr_passes_draw(radiosity_mesh(c, rad, i));
                glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
                glDisable(GL_BLEND);
            } else if (F == 1) {
                /* Further lights: x_o, n_o and depth are light 0's. */
                lr_fb_bind(rad->acc[l * K + k]);
                glClearBufferfv(GL_COLOR, 0, zero);
                glDisable(GL_BLEND);
            } else {
                lr_fb_bind(rad->acc[l * K + k]);
                glEnable(GL_BLEND);
                glBlendEquation(GL_FUNC_ADD);
                glBlendColor(0.0f, 0.0f, 0.0f, lr_radiosity_blend_weight(c->map_format, F));
                glBlendFunc(GL_CONSTANT_ALPHA, GL_ONE_MINUS_CONSTANT_ALPHA);
            }
            glDepthMask(GL_FALSE);
            glDepthFunc(GL_LEQUAL);
            lr_program *p = c->prog->radiosity;
            glUseProgram(lr_program_id(p));
            lr_passes_set_coeffs(c->objs, p);
            lr_passes_uniform_v3_array(p, "u_sd_norm", c->objs->sd_norm, LR_MAX_OBJECTS);
            lr_radiosity_sh_uniforms(rad, p, l);
            lr_gbuffer_bind(gb, p, l);
            lr_passes_uniform_mat4(p, "u_vp", rad->vp[k]);
            lr_passes_uniform_i(p, "u_N", c->rs->N);
            lr_passes_uniform_f(p, "u_r_max", (float)rad->r_max);
            lr_passes_uniform_f(p, "u_r_max_dist", 20.0f);
            lr_passes_uniform_f(p, "u_near_mix", (float)LR_PASS_NEAR_MIX);
            /* Its own unit even without a diffusion_grid object: the default 0 is the
             * G-buffer's cube, and two sampler types on one unit fail the draw. */
            lr_passes_uniform_i(p, "u_dg_field", LR_DGRID_TEX_UNIT);
            lr_passes_uniform_i(p, "u_map_size", rad->size);
            lr_passes_uniform_f(p, "u_map_scale", rad->scale[l]);
            /* Half floats: stay below 65504 (a light on the surface has B -> Inf at x_o -> x_l). */
            lr_passes_uniform_f(p, "u_map_max", c->map_format == LR_TEX_RGBA16F ? 6.0e4f : 3.0e38f);
            glUniform1ui(lr_program_uniform(p, "u_seed"), c->seed);
            glUniform1ui(lr_program_uniform(p, "u_map"), (GLuint)k);
            glUniform1ui(lr_program_uniform(p, "u_frame"), (GLuint)F);
            /* In bands of the map's rows (slice.h): each texel is drawn once a frame whatever
             * the bands. A cut here leaves some maps one sample ahead of the others, so the
             * maps restart at the next frame (frame count 0), as the change that cuts at
             * this level makes them do anyway. */
            glEnable(GL_SCISSOR_TEST);
            for (int y = 0, rows; y < rad->size && !cut; y += rows) {
                rows = lr_slice_band(c->slicer, LR_SLICE_RADIOSITY, y, rad->size);
                glScissor(0, y, rad->size, rows);
                draw_objects(rad, c, p, l);
                cut = lr_slice_end(c->slicer, LR_CANCEL_RESTART, "radiosity pass", e);
            }
            glDisable(GL_SCISSOR_TEST);
            if (cut)
                goto done;
        }
done:
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_LESS);
    if (cut) {
        rad->F = 0;
        rad->gen++;
        return cut;
    }
    rad->F = F;
    rad->gen++;
    return lr_gl_check("radiosity pass", e);
}

void lr_radiosity_bind_gather(const lr_radiosity *rad, lr_program *p, const double w[][3])
{
    lr_passes_bind_tex(p, "u_map_B", 4, rad->B);
    lr_passes_bind_tex(p, "u_map_nrm", 5, rad->nrm);
    lr_passes_bind_tex(p, "u_map_depth", 6, rad->depth);
    GLint loc = lr_program_uniform(p, "u_map_P");
    if (loc < 0)
        loc = lr_program_uniform(p, "u_map_P[0]");
    if (loc >= 0)
        glUniformMatrix4fv(loc, rad->K, GL_FALSE, rad->Pf);
    loc = lr_program_uniform(p, "u_map_d");
    if (loc < 0)
        loc = lr_program_uniform(p, "u_map_d[0]");
    if (loc >= 0)
        glUniform3fv(loc, rad->K, rad->df);
    lr_passes_uniform_i(p, "u_K", rad->K);
    lr_passes_uniform_f(p, "u_eps_bias", rad->eps_bias);
    lr_passes_uniform_f(p, "u_eps_comb", rad->eps_comb);
    lr_radiosity_set_light_w(rad, p, w);
}

void lr_radiosity_set_light_w(const lr_radiosity *rad, lr_program *p, const double w[][3])
{
    /* The maps store B * scale[l]: the weight divides it out. */
    GLint loc;
    float wf[3 * LR_MAX_LIGHTS] = {0};
    for (int l = 0; l < rad->n_lights; l++)
        for (int c = 0; c < 3; c++)
            wf[3 * l + c] = (float)(w[l][c] / rad->scale[l]);
    loc = lr_program_uniform(p, "u_light_w");
    if (loc < 0)
        loc = lr_program_uniform(p, "u_light_w[0]");
    if (loc >= 0)
        glUniform3fv(loc, LR_MAX_LIGHTS, wf);
    lr_passes_uniform_i(p, "u_n_lights", rad->n_lights);
}
