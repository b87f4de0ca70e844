/* Pass 4 — emergent light (render/passes/PIPELINE.md): N_vpl virtual point lights at stable
 * positions on the outermost surface. The objects are drawn into a cube map around the
 * bounding-box centre keeping the *farthest* depth (cleared to 0, GL_GREATER); VPL v is that
 * cube map's surface in the fixed direction u_v = lr_halton_sphere(v + 1). Each frame the VPLs
 * re-read B through Algorithm 1 (the maps keep converging); the cube map is redrawn only when
 * the geometry changed. With several lights the VPLs carry B per light for unit intensity
 * (row l of the B target, N_vpl x n_lights), drawn one row per light, so that composition
 * weights them by the lights' current intensities. */
#include <math.h>
#include <stdlib.h>

#include "render/core/gbuffer_camera.h"
#include "render/optics/optics.h"
#include "render/passes/vpl.h"

int lr_vpl_alloc(lr_vpl *v, const lr_pass_ctx *c, lr_err *e)
{
    int n = c->rs->N_vpl, s = c->rs->vpl_map_size, rc;
    if (n > LR_MAX_VPL || n > c->caps->max_texture_size)
        return lr_err_set(e, LR_EUNSUPPORTED, "render.N_vpl = %d: at most %d", n, LR_MAX_VPL);
    v->n = n;
    v->size = s;
    lr_tex_desc cube = {.type = LR_TEX_CUBE, .format = LR_TEX_RGBA32F, .width = s,
                        .label = "VPL outer-surface cube"};
    if ((rc = lr_tex_create(c->gl, &cube, &v->outer_pos, e)) ||
        (rc = lr_tex_create(c->gl, &cube, &v->outer_nrm, e)))
        return rc;
    for (int f = 0; f < 6; f++) {
        lr_fb_desc d = {.color = {{v->outer_pos, f}, {v->outer_nrm, f}},
                        .depth_buffer = true, .label = "VPL outer-surface cube"};
        if ((rc = lr_fb_create(c->gl, &d, &v->outer_fb[f], e)))
            return rc;
    }
    lr_tex_desc line = {.format = LR_TEX_RGBA32F, .width = n, .height = 1, .label = "VPLs"};
    lr_tex_desc rows = line;
    rows.height = c->n_lights;
    v->n_lights = c->n_lights;
    if ((rc = lr_tex_create(c->gl, &line, &v->dirs, e)) ||
        (rc = lr_tex_create(c->gl, &rows, &v->pos, e)) ||
        (rc = lr_tex_create(c->gl, &rows, &v->nrm, e)) ||
        (rc = lr_tex_create(c->gl, &rows, &v->B, e)))
        return rc;
    float *dirs = malloc((size_t)n * 4 * sizeof *dirs);
    if (!dirs)
        return lr_err_set(e, LR_ENOMEM, "VPL directions: out of memory");
    for (int i = 0; i < n; i++) {
        lr_vec3 u = lr_halton_sphere((unsigned)i + 1);
        dirs[4 * i] = (float)u.x;
        dirs[4 * i + 1] = (float)u.y;
        dirs[4 * i + 2] = (float)u.z;
        dirs[4 * i + 3] = 0.0f;
    }
    rc = lr_tex_upload(v->dirs, 0, dirs, e);
    free(dirs);
    if (rc)
        return rc;
    lr_fb_desc d = {.color = {{v->pos, 0}, {v->nrm, 0}, {v->B, 0}}, .label = "VPLs"};
    v->outer_valid = false;
    return lr_fb_create(c->gl, &d, &v->fb, e);
}

void lr_vpl_free(lr_vpl *v)
{
    for (int f = 0; f < 6; f++) {
        lr_fb_destroy(v->outer_fb[f]);
        v->outer_fb[f] = NULL;
    }
    lr_fb_destroy(v->fb);
    v->fb = NULL;
    lr_tex **t[] = {&v->outer_pos, &v->outer_nrm, &v->dirs, &v->pos, &v->nrm,
                    &v->B};
    for (size_t i = 0; i < sizeof t / sizeof t[0]; i++) {
        lr_tex_destroy(*t[i]);
        *t[i] = NULL;
    }
    v->outer_valid = false;
}

static void draw_outer(lr_vpl *v, const lr_pass_ctx *ctx)
{
    static const float zero[4] = {0, 0, 0, 0};
    lr_vec3 c;
    double R;
    lr_scene_bounds(ctx->scene, &c, &R);
    R = fmax(R, 1e-3);
    v->center = c;
    v->radius = R;
    lr_program *p = ctx->prog->surface;
    glUseProgram(lr_program_id(p));
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_GREATER); /* the outermost surface: farthest from c */
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    for (int f = 0; f < 6; f++) {
        double vp[16];
        lr_fb_bind(v->outer_fb[f]);
        glClearBufferfv(GL_COLOR, 0, zero);
        glClearBufferfv(GL_COLOR, 1, zero);
        glClearDepthf(0.0f);
        glClear(GL_DEPTH_BUFFER_BIT);
        lr_cube_face_vp(c, f, 1e-3 * R, 3.0 * R, vp);
        lr_passes_uniform_mat4(p, "u_vp", vp);
        for (int i = 0; i < ctx->objs->n_objects; i++) {
            lr_passes_uniform_i(p, "u_object", i);
            /* Normals as the mesh has them: the outer surface faces out. */
            lr_passes_uniform_i(p, "u_two_sided", 0);
            lr_passes_draw(&ctx->objs->obj[i]);
        }
    }
    glClearDepthf(1.0f);
    glDepthFunc(GL_LESS);
    v->outer_valid = true;
}

int lr_vpl_run(lr_vpl *v, const lr_pass_ctx *c, const lr_radiosity *rad, bool geometry_changed,
               lr_err *e)
{
    if (geometry_changed || !v->outer_valid)
        draw_outer(v, c);
    lr_program *p = c->prog->vpl;
    lr_fb_bind(v->fb);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glUseProgram(lr_program_id(p));
    lr_passes_set_coeffs(c->objs, p);
    lr_passes_bind_tex(p, "u_outer_pos", 0, v->outer_pos);
    lr_passes_bind_tex(p, "u_outer_nrm", 1, v->outer_nrm);
    lr_passes_bind_tex(p, "u_vpl_dirs", 2, v->dirs);
    lr_passes_uniform_v3(p, "u_center", v->center);
    lr_passes_uniform_i(p, "u_n_vpl", v->n);
    for (int l = 0; l < v->n_lights; l++) {
        /* Row l: Algorithm 1 over light l's maps alone, unit intensity. */
        double w[LR_MAX_LIGHTS][3] = {{0}};
        w[l][0] = w[l][1] = w[l][2] = 1.0;
        lr_radiosity_bind_gather(rad, p, w);
        glViewport(0, l, v->n, 1);
        lr_gl_draw_fullscreen(c->gl);
    }
    return lr_gl_check("vpl pass", e);
}

bool lr_vpl_bind(const lr_vpl *v, const lr_pass_ctx *c, const lr_radiosity *rad,
                 lr_program *p)
{
    bool use_vpl = !c->no_vpl && v->fb;
    lr_passes_uniform_v3_array(p, "u_cavity_gain", c->objs->cavity_gain,
                               LR_MAX_LIGHTS * LR_MAX_OBJECTS);
    lr_passes_uniform_i(p, "u_n_vpl", v->n);
    lr_passes_bind_tex(p, "u_vpl_pos", 7, use_vpl ? v->pos : NULL);
    lr_passes_bind_tex(p, "u_vpl_nrm", 8, use_vpl ? v->nrm : NULL);
    lr_passes_bind_tex(p, "u_vpl_B", 9, use_vpl ? v->B : NULL);
    lr_passes_uniform_i(p, "u_vpl_vis", use_vpl && c->vpl_visibility);
    lr_passes_bind_tex(p, "u_outer_pos", 10, use_vpl ? v->outer_pos : NULL);
    lr_passes_uniform_v3(p, "u_center", v->center);
    lr_passes_uniform_f(p, "u_outer_r", (float)(v->radius * 1.001));
    lr_passes_uniform_f(p, "u_vis_eps", (float)(2.0 * rad->radius / (v->size > 0 ? v->size : 1)));
    return use_vpl;
}
