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

#include "render/optics/optics.h"
#include "render/passes/passes.h"

int lr_vpl_alloc(lr_renderer *r, lr_err *e)
{
    int n = r->rs.N_vpl, s = r->rs.vpl_map_size, rc;
    if (n > LR_MAX_VPL || n > r->caps->max_texture_size)
        return lr_err_set(e, LR_EUNSUPPORTED, "render.N_vpl = %d: at most %d", n, LR_MAX_VPL);
    r->vpl.n = n;
    r->vpl.size = s;
    lr_tex_desc cube = {.type = LR_TEX_CUBE, .format = LR_TEX_RGBA32F, .width = s,
                        .label = "VPL outer-surface cube"};
    if ((rc = lr_tex_create(r->gl, &cube, &r->vpl.outer_pos, e)) ||
        (rc = lr_tex_create(r->gl, &cube, &r->vpl.outer_nrm, e)))
        return rc;
    for (int f = 0; f < 6; f++) {
        lr_fb_desc d = {.color = {{r->vpl.outer_pos, f}, {r->vpl.outer_nrm, f}},
                        .depth_buffer = true, .label = "VPL outer-surface cube"};
        if ((rc = lr_fb_create(r->gl, &d, &r->vpl.outer_fb[f], e)))
            return rc;
    }
    lr_tex_desc line = {.format = LR_TEX_RGBA32F, .width = n, .height = 1, .label = "VPLs"};
    lr_tex_desc rows = line;
    rows.height = r->n_lights;
    if ((rc = lr_tex_create(r->gl, &line, &r->vpl.dirs, e)) ||
        (rc = lr_tex_create(r->gl, &rows, &r->vpl.pos, e)) ||
        (rc = lr_tex_create(r->gl, &rows, &r->vpl.nrm, e)) ||
        (rc = lr_tex_create(r->gl, &rows, &r->vpl.B, e)))
        return rc;
    float *dirs = malloc((size_t)n * 4 * sizeof *dirs);
    if (!dirs)
        return lr_err_set(e, LR_ENOMEM, "VPL directions: out of memory");
    for (int v = 0; v < n; v++) {
        lr_vec3 u = lr_halton_sphere((unsigned)v + 1);
        dirs[4 * v] = (float)u.x;
        dirs[4 * v + 1] = (float)u.y;
        dirs[4 * v + 2] = (float)u.z;
        dirs[4 * v + 3] = 0.0f;
    }
    rc = lr_tex_upload(r->vpl.dirs, 0, dirs, e);
    free(dirs);
    if (rc)
        return rc;
    lr_fb_desc d = {.color = {{r->vpl.pos, 0}, {r->vpl.nrm, 0}, {r->vpl.B, 0}}, .label = "VPLs"};
    r->vpl.outer_valid = false;
    return lr_fb_create(r->gl, &d, &r->vpl.fb, e);
}

void lr_vpl_free(lr_renderer *r)
{
    for (int f = 0; f < 6; f++) {
        lr_fb_destroy(r->vpl.outer_fb[f]);
        r->vpl.outer_fb[f] = NULL;
    }
    lr_fb_destroy(r->vpl.fb);
    r->vpl.fb = NULL;
    lr_tex **t[] = {&r->vpl.outer_pos, &r->vpl.outer_nrm, &r->vpl.dirs, &r->vpl.pos, &r->vpl.nrm,
                    &r->vpl.B};
    for (size_t i = 0; i < sizeof t / sizeof t[0]; i++) {
        lr_tex_destroy(*t[i]);
        *t[i] = NULL;
    }
    r->vpl.outer_valid = false;
}

static void draw_outer(lr_renderer *r)
{
    static const float zero[4] = {0, 0, 0, 0};
    lr_vec3 c;
    double R;
    lr_scene_bounds(r->scene, &c, &R);
    R = fmax(R, 1e-3);
    r->vpl.center = c;
    const lr_program *p = r->p_surface;
    glUseProgram(lr_program_id(p));
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_GREATER); /* the outermost surface: farthest from c */
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    for (int f = 0; f < 6; f++) {
        double vp[16];
        lr_fb_bind(r->vpl.outer_fb[f]);
        glClearBufferfv(GL_COLOR, 0, zero);
        glClearBufferfv(GL_COLOR, 1, zero);
        glClearDepthf(0.0f);
        glClear(GL_DEPTH_BUFFER_BIT);
        lr_passes_cube_face_vp(c, f, 1e-3 * R, 3.0 * R, vp);
        lr_passes_uniform_mat4(p, "u_vp", vp);
        for (int i = 0; i < r->n_objects; i++) {
            lr_passes_uniform_i(p, "u_object", i);
            /* Normals as the mesh has them: the outer surface faces out. */
            lr_passes_uniform_i(p, "u_two_sided", 0);
            lr_passes_draw(&r->obj[i]);
        }
    }
    glClearDepthf(1.0f);
    glDepthFunc(GL_LESS);
    r->vpl.outer_valid = true;
}

int lr_pass_vpl(lr_renderer *r, bool geometry_changed, lr_err *e)
{
    if (geometry_changed || !r->vpl.outer_valid)
        draw_outer(r);
    const lr_program *p = r->p_vpl;
    lr_fb_bind(r->vpl.fb);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glUseProgram(lr_program_id(p));
    lr_passes_set_coeffs(r, p);
    lr_passes_bind_tex(p, "u_outer_pos", 0, r->vpl.outer_pos);
    lr_passes_bind_tex(p, "u_outer_nrm", 1, r->vpl.outer_nrm);
    lr_passes_bind_tex(p, "u_vpl_dirs", 2, r->vpl.dirs);
    lr_passes_uniform_v3(p, "u_center", r->vpl.center);
    lr_passes_uniform_i(p, "u_n_vpl", r->vpl.n);
    for (int l = 0; l < r->n_lights; l++) {
        /* Row l: Algorithm 1 over light l's maps alone, unit intensity. */
        double w[LR_MAX_LIGHTS][3] = {{0}};
        w[l][0] = w[l][1] = w[l][2] = 1.0;
        lr_passes_bind_gather(r, p, w);
        glViewport(0, l, r->vpl.n, 1);
        lr_gl_draw_fullscreen(r->gl);
    }
    return lr_gl_check("vpl pass", e);
}
