/* Seed 002's accumulation step on the GPU path (render/optics/sh_translucency.h): the light's
 * own G-buffer (pass 1: first surface seen from the light, cube map for an enclosed flame or
 * bulb) is read back and every texel of an sh_translucency object is projected on the 9 SH
 * (Eq. 6) with its solid angle (or area) from the G-buffer camera (lr_sh_texel_ray). The
 * evaluation (Eq. 10-12) runs per map texel in render/shaders/radiosity.frag. Only when the
 * maps restart (light, material or geometry change): 2 x 6 x gbuffer_size^2 texels per light. */
#include <math.h>
#include <stdlib.h>

#include "render/optics/sh_translucency.h"
#include "render/passes/radiosity.h"

/* Adds view `view` of light l's G-buffer (pos and nrm read back) into env[object]. */
static void project_view(const lr_gb_camera *cam, int view, int n, const lr_light *light,
                         const lr_scene *s, const float *pos, const float *nrm, lr_sh_env *env)
{
    bool ortho = cam->mode == LR_GB_ORTHO;
    int nobj = lr_scene_object_count(s);
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            const float *p = pos + 4 * ((size_t)j * n + i), *q = nrm + 4 * ((size_t)j * n + i);
            if (!(p[3] > 0.5f))
                continue; /* empty texel */
            int id = (int)(p[3] + 0.5f) - 1;
            if (id < 0 || id >= nobj || id >= LR_MAX_OBJECTS)
                continue;
            const lr_scene_object *o = lr_scene_object_at(s, id);
            if (!lr_sss_model_props_of(o->sss_model)->light_env)
                continue;
            lr_vec3 org, dir;
            double w;
            if (!lr_sh_texel_ray(cam->vp[view], ortho, n, i, j, &org, &dir, &w))
                continue;
            lr_vec3 xi = lr_v3(p[0], p[1], p[2]), ni = lr_v3(q[0], q[1], q[2]);
            double len = lr_v3_len(ni);
            if (!(len > 0.0))
                continue;
            ni = lr_v3_scale(ni, 1.0 / len);
            double cos_i = -lr_v3_dot(dir, ni);
            if (!(cos_i > LR_SH_MIN_COS))
                continue;
            double flux = w, area = w / cos_i;
            if (!ortho) {
                double t = lr_v3_len(lr_v3_sub(xi, light->position));
                flux *= lr_light_shape(light, dir);
                area *= t * t;
            }
            lr_sh_env_add(&env[id], dir, ni, flux, area, o->coeffs.eta);
        }
}

int lr_radiosity_sh_project(lr_radiosity *rad, const lr_pass_ctx *c, const lr_gbuffer *gb,
                            lr_err *e)
{
    const lr_scene *s = c->scene;
    int nobj = lr_scene_object_count(s);
    rad->has_sh = false;
    for (int o = 0; o < nobj && o < LR_MAX_OBJECTS; o++) {
        const lr_scene_object *ob = lr_scene_object_at(s, o);
        double sc[3] = {0, 0, 0}, rho[3] = {0, 0, 0}, lit = -1.0;
        if (lr_sss_model_props_of(ob->sss_model)->light_env) {
            rad->has_sh = true;
            lr_sh_object_scale(&ob->coeffs, ob->material.sh_scale, sc);
            lr_dipole_rd_total(&ob->coeffs, rho);
            /* lr_sh_lit's threshold: LR_SH_LIT_RADII radius + mean free path */
            lit = LR_SH_LIT_RADII * ob->radius +
                  (ob->coeffs.mfp[0] + ob->coeffs.mfp[1] + ob->coeffs.mfp[2]) / 3.0;
        }
        for (int b = 0; b < 3; b++) {
            rad->sh_scale[3 * o + b] = (float)sc[b];
            rad->sh_rho[4 * o + b] = (float)rho[b];
        }
        rad->sh_rho[4 * o + 3] = (float)lit;
    }
    if (!rad->has_sh)
        return LR_OK;
    int n = c->rs->gbuffer_size, rc = LR_OK;
    float *pos = malloc((size_t)n * n * 4 * sizeof *pos);
    float *nrm = malloc((size_t)n * n * 4 * sizeof *nrm);
    if (!pos || !nrm) {
        free(pos);
        free(nrm);
        return lr_err_set(e, LR_ENOMEM, "sh_translucency: out of memory reading back the "
                                        "%d^2 light G-buffer", n);
    }
    for (int l = 0; l < gb->n_lights && !rc; l++) {
        lr_sh_env env[LR_MAX_OBJECTS];
        for (int o = 0; o < LR_MAX_OBJECTS; o++)
            lr_sh_env_clear(&env[o]);
        lr_gb_camera cam;
        lr_gb_camera_scene(s, l, &cam);
        const lr_light_gbuffer *g = &gb->light[l];
        for (int v = 0; v < cam.views && !rc; v++) {
            lr_fb *fb = cam.mode == LR_GB_CUBE ? g->fb[v] : g->fb_2d;
            if ((rc = lr_fb_read(fb, 0, 0, 0, n, n, pos, e)) ||
                (rc = lr_fb_read(fb, 1, 0, 0, n, n, nrm, e)))
                break;
            project_view(&cam, v, n, lr_scene_light_at(s, l), s, pos, nrm, env);
        }
        for (int o = 0; o < LR_MAX_OBJECTS; o++) {
            lr_sh_env_finish(&env[o]);
            for (int k = 0; k < 9; k++)
                rad->sh_E[l][9 * o + k] = (float)env[o].E[k];
        }
    }
    free(pos);
    free(nrm);
    return rc;
}

void lr_radiosity_sh_uniforms(const lr_radiosity *rad, lr_program *p, int l)
{
    if (!rad->has_sh)
        return; /* the shader's defaults (0) are never read: no object has the model */
    lr_passes_uniform_v3_array(p, "u_sh_E", rad->sh_E[l], 3 * LR_MAX_OBJECTS);
    lr_passes_uniform_v3_array(p, "u_sh_scale", rad->sh_scale, LR_MAX_OBJECTS);
    GLint loc = lr_program_uniform(p, "u_sh_rho");
    if (loc < 0)
        loc = lr_program_uniform(p, "u_sh_rho[0]");
    if (loc >= 0)
        glUniform4fv(loc, LR_MAX_OBJECTS, rad->sh_rho);
}
