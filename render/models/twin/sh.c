/* CPU twin of the sh_translucency model; see sh.h. */
#include "render/models/twin/sh.h"

#include <math.h>
#include <stdlib.h>

#include "render/base/parallel.h"
#include "render/models/twin/radiosity.h"
#include "render/optics/near_light.h"

/* The G-buffer's first surface along (org, dir), as render/models/radiosity.c's gbuffer_texel:
 * false when obj is missed or another object is nearer. */
static bool first_own(const lr_scene_object *obj, lr_vec3 org, lr_vec3 dir,
                      const lr_scene_object *const *others, int n_others, lr_vec3 *xi,
                      lr_vec3 *ni, bool *blocked)
{
    *blocked = false;
    double tmin = 1e-7 * obj->radius;
    if (!lr_first_surface(obj, org, dir, tmin, xi, ni))
        return false;
    if (!obj->closed && lr_v3_dot(*ni, dir) > 0.0)
        *ni = lr_v3_scale(*ni, -1.0);
    double t = lr_v3_len(lr_v3_sub(*xi, org));
    for (int i = 0; i < n_others; i++)
        if (others[i] != obj && lr_bvh_occluded(others[i]->bvh, org, dir, tmin, t)) {
            *blocked = true;
            return false;
        }
    return true;
}

typedef struct env_ctx {
    const lr_scene_object *obj;
    const lr_light *light;
    const lr_gb_camera *cam;
    int size;
    const lr_scene_object *const *others;
    int n_others;
    lr_sh_env *part; /* one per view row */
} env_ctx;

/* Row `item` (view * size + j) of texels into its own partial sum (fixed order: the result
 * does not depend on the threads). */
static void env_row(void *p, long item)
{
    env_ctx *c = p;
    int view = (int)(item / c->size), j = (int)(item % c->size);
    bool ortho = c->cam->mode == LR_GB_ORTHO;
    lr_sh_env *acc = &c->part[item];
    lr_sh_env_clear(acc);
    for (int i = 0; i < c->size; i++) {
        lr_vec3 org, dir, xi, ni;
        double w;
        bool blocked;
        if (!lr_sh_texel_ray(c->cam->vp[view], ortho, c->size, i, j, &org, &dir, &w))
            continue;
        if (!ortho)
            org = c->light->position;
        if (!first_own(c->obj, org, dir, c->others, c->n_others, &xi, &ni, &blocked))
            continue;
        double cos_i = -lr_v3_dot(dir, ni);
        if (!(cos_i > LR_SH_MIN_COS))
            continue;
        double flux = w * (ortho ? 1.0 : lr_light_shape(c->light, dir));
        double t = lr_v3_len(lr_v3_sub(xi, org));
        double area = ortho ? w / cos_i : w * t * t / cos_i;
        lr_sh_env_add(acc, dir, ni, flux, area, c->obj->coeffs.eta);
    }
}

void lr_cpu_sh_env(const lr_scene_object *obj, const lr_light *light, const lr_gb_camera *cam,
                   int size, const lr_scene_object *const *others, int n_others, int threads,
                   lr_sh_env *out)
{
    lr_sh_env_clear(out);
    long rows = (long)cam->views * size;
    lr_sh_env *part = malloc((size_t)rows * sizeof *part);
    if (!part)
        return; /* out of memory: an empty environment (B = 0) */
    env_ctx c = {obj, light, cam, size, others, n_others, part};
    lr_parallel_for(rows, threads, env_row, &c);
    for (long r = 0; r < rows; r++) {
        for (int k = 0; k < 9; k++)
            out->E[k] += part[r].E[k];
        out->power += part[r].power;
        out->area += part[r].area;
    }
    free(part);
    lr_sh_env_finish(out);
}

bool lr_cpu_sh_thickness(const lr_scene_object *obj, const lr_light *light, lr_vec3 xo,
                         const lr_cpu_radiosity_desc *d, double *thickness, lr_vec3 *ni_out)
{
    const lr_scene_object *const *others = d ? d->others : NULL;
    int n_others = d ? d->n_others : 0;
    lr_vec3 (*snap)(void *, lr_vec3) = d ? d->snap : NULL;
    lr_vec3 org, dir, xi, ni;
    bool blocked;
    double reach;
    if (light->type == LR_LIGHT_DIRECTIONAL) {
        dir = lr_v3_normalize(light->direction);
        lr_vec3 at = snap ? snap(d->snap_ctx, xo) : xo; /* the texel's plane point */
        double back = lr_v3_dot(lr_v3_sub(at, obj->center), dir) + 1.01 * obj->radius + 1.0;
        org = lr_v3_sub(at, lr_v3_scale(dir, back));
        /* the depth difference along the light: x_o's depth from the same plane */
        reach = lr_v3_dot(lr_v3_sub(xo, org), dir);
    } else {
        lr_vec3 h = lr_v3_sub(xo, light->position);
        reach = lr_v3_len(h);
        org = light->position;
        dir = reach > 0.0 ? lr_v3_scale(h, 1.0 / reach) : lr_v3(0, 0, 1);
        if (snap)
            dir = lr_v3_normalize(snap(d->snap_ctx, dir));
    }
    *thickness = 0.0;
    if (ni_out)
        *ni_out = lr_v3(0, 0, 0);
    if (!first_own(obj, org, dir, others, n_others, &xi, &ni, &blocked))
        return !blocked;
    *thickness = fmax(0.0, reach - lr_v3_len(lr_v3_sub(xi, org)));
    if (ni_out)
        *ni_out = ni;
    return true;
}

void lr_cpu_sh_B(const lr_scene_object *obj, const lr_light *light, const lr_sh_env *env,
                 lr_vec3 xo, lr_vec3 no, const lr_cpu_radiosity_desc *rd, double out[3])
{
    double d, s[3];
    lr_vec3 ni;
    out[0] = out[1] = out[2] = 0.0;
    if (!lr_cpu_sh_thickness(obj, light, xo, rd, &d, &ni))
        return;
    lr_sh_object_scale(&obj->coeffs, obj->material.sh_scale, s);
    lr_sh_translucency_B(&obj->coeffs, s, env, no, d, out);
    if (!lr_sh_lit(&obj->coeffs, obj->radius, d, lr_v3_dot(ni, no)))
        return;
    /* The direct term: irradiance of the unit light at x_o (PIPELINE.md pass 4's receivers).
     * A point light's is the mean over the square of side mfp about x_o (near_light.h), not
     * the point sample cos / r^2, which diverges as the light nears the wall (1e-3 mm off the
     * candle's pool: 524 times the light's power): what leaves x_o entered within the
     * diffuse reflectance's spread around it, at least a mean free path (the mean of the
     * bands', as lr_sh_lit's), so the light a point sample stands for is that patch's.
     * lr_sh_direct takes cos_i times F_t(cos_i): here F_t at the patch's mean cosine times
     * the patch's mean irradiance. */
    double direct[3];
    if (light->type == LR_LIGHT_DIRECTIONAL) {
        lr_sh_direct(&obj->coeffs, -lr_v3_dot(no, lr_v3_normalize(light->direction)), direct);
        for (int b = 0; b < 3; b++)
            out[b] += direct[b];
        return;
    }
    lr_vec3 h = lr_v3_sub(light->position, xo);
    double r2 = lr_v3_dot(h, h);
    if (!(r2 > 0.0))
        return;
    lr_vec3 u = lr_v3_scale(h, 1.0 / sqrt(r2));
    if (!(lr_v3_dot(no, u) > 0.0))
        return;
    double side = (obj->coeffs.mfp[0] + obj->coeffs.mfp[1] + obj->coeffs.mfp[2]) / 3.0;
    double mu = 0.0;
    double E = lr_patch_irradiance_far(light->position, xo, no, side, &mu) *
        lr_light_shape(light, lr_v3_scale(u, -1.0));
    if (!(mu > 0.0))
        return;
    /* lr_sh_direct(mu) = rho F_t(mu) mu: divided by mu, rho F_t(mu). */
    lr_sh_direct(&obj->coeffs, mu, direct);
    for (int b = 0; b < 3; b++)
        out[b] += direct[b] / mu * E;
}
