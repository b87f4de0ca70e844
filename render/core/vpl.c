/* VPL placement and receiver lighting; see vpl.h. */
#include "render/core/vpl.h"

#include <math.h>
#include <string.h>

#include "render/core/ray.h"

void lr_vpl_place(const lr_scene_object *obj, int count, lr_vpl_point *out)
{
    lr_vec3 c = obj->center;
    double far = 2.0 * obj->radius + 1.0;
    for (int v = 0; v < count; v++) {
        lr_vpl_point *p = &out[v];
        memset(p, 0, sizeof *p);
        lr_vec3 u = lr_halton_sphere((unsigned)v + 1);
        p->u = u;
        lr_vec3 x, n;
        /* From outside inwards: the first hit is the outermost surface along the line. */
        if (!lr_first_surface(obj, lr_v3_add(c, lr_v3_scale(u, far)), lr_v3_scale(u, -1.0),
                                  0.0, &x, &n))
            continue;
        if (lr_v3_dot(lr_v3_sub(x, c), u) < 0.0)
            continue; /* the line passes the centre before meeting the surface: no outer hit */
        p->valid = true;
        p->x = x;
        p->n = n;
        lr_vec3 cx = lr_v3_sub(x, c);
        double cosv = fabs(lr_v3_dot(n, u));
        if (cosv < LR_CPU_VPL_COS_FLOOR)
            cosv = LR_CPU_VPL_COS_FLOOR;
        p->area = lr_v3_dot(cx, cx) * (4.0 * M_PI / count) / cosv; /* PIPELINE.md pass 4 */
    }
}

void lr_vpl_point_irradiance(const lr_vpl_point *v, int count, double eta, lr_vec3 x, lr_vec3 n,
                           double E[3], double var[3])
{
    lr_vpl_point_irradiance_vis(NULL, v, count, eta, x, n, E, var);
}

/* Whether any object of s blocks the segment from VPL p to x (dist = |x - x_v|, w its unit
 * direction). The VPL lies on its object's surface and the segment leaves it outward
 * (cos_v > 0): tmin 1e-6 of each object's radius, as the direct light's shadow rays. */
static bool vpl_hidden(const lr_scene *s, const lr_vpl_point *p, lr_vec3 w, double dist)
{
    for (int i = 0; i < lr_scene_object_count(s); i++) {
        const lr_scene_object *o = lr_scene_object_at(s, i);
        if (lr_bvh_occluded(o->bvh, p->x, w, 1e-6 * o->radius, dist * (1.0 - 1e-9)))
            return true;
    }
    return false;
}

void lr_vpl_point_irradiance_vis(const lr_scene *s, const lr_vpl_point *v, int count, double eta,
                               lr_vec3 x, lr_vec3 n, double E[3], double var[3])
{
    for (int i = 0; i < count; i++) {
        const lr_vpl_point *p = &v[i];
        if (!p->valid)
            continue;
        lr_vec3 w = lr_v3_sub(x, p->x);
        double d2 = lr_v3_dot(w, w);
        if (!(d2 > 0.0))
            continue;
        lr_vec3 wh = lr_v3_scale(w, 1.0 / sqrt(d2));
        double cv = lr_v3_dot(p->n, wh), cx = -lr_v3_dot(n, wh);
        if (!(cv > 0.0) || !(cx > 0.0))
            continue;
        if (s && vpl_hidden(s, p, wh, sqrt(d2)))
            continue;
        double g = lr_fresnel_transmittance(cv, eta) / M_PI * p->area * cv * cx /
                   (d2 > p->area ? d2 : p->area); /* bounded geometry term */
        for (int c = 0; c < 3; c++) {
            E[c] += g * p->B[c];
            if (var)
                var[c] += g * g * p->var[c];
        }
    }
}

double lr_direct_irradiance(const lr_scene *s, const lr_light *l, lr_vec3 x, lr_vec3 n)
{
    lr_vec3 dir;
    double dist, e;
    if (l->type == LR_LIGHT_DIRECTIONAL) {
        dir = lr_v3_scale(l->direction, -1.0);
        dist = INFINITY;
        double cs = lr_v3_dot(n, dir);
        if (!(cs > 0.0))
            return 0.0;
        e = cs;
    } else {
        lr_vec3 to = lr_v3_sub(l->position, x);
        dist = lr_v3_len(to);
        if (!(dist > 0.0))
            return 0.0;
        dir = lr_v3_scale(to, 1.0 / dist);
        double cs = lr_v3_dot(n, dir);
        if (!(cs > 0.0))
            return 0.0;
        e = cs / (dist * dist) * lr_light_shape(l, lr_v3_scale(dir, -1.0));
        if (!(e > 0.0))
            return 0.0;
    }
    for (int i = 0; i < lr_scene_object_count(s); i++) {
        const lr_scene_object *o = lr_scene_object_at(s, i);
        double tmin = 1e-6 * o->radius;
        if (lr_bvh_occluded(o->bvh, x, dir, tmin, dist < INFINITY ? dist * (1.0 - 1e-9) : dist))
            return 0.0;
    }
    return e;
}
