/* Object and receiver pixels by ray casting (eval.h): the same camera rays as the CPU twin, so
 * the masks do not depend on what either renderer produced. */
#include "render/eval/eval.h"

#include <math.h>
#include <stdlib.h>

#include "render/cpu/frame.h"
#include "render/mesh/bvh.h"

/* Distance along the ray (o, unit d) to area light l's surface, INFINITY when missed: a quad
 * position + s edge_u + t edge_v (s, t in [-1, 1]), a disk of its radius about position
 * across its normal. Either side: the physical reference makes an area light a surface (its
 * emitter seen from the front, an absorber from the back), which the real-time renderer does
 * not draw; a pixel that sees it compares the emitter with the receiver behind it. */
static double emitter_t(const lr_light *l, lr_vec3 o, lr_vec3 d)
{
    lr_vec3 n = lr_light_area_normal(l);
    double dn = lr_v3_dot(d, n);
    if (fabs(dn) < 1e-12)
        return INFINITY;
    double t = lr_v3_dot(lr_v3_sub(l->position, o), n) / dn;
    if (!(t > 0.0))
        return INFINITY;
    lr_vec3 q = lr_v3_sub(lr_v3_add(o, lr_v3_scale(d, t)), l->position);
    if (l->type == LR_LIGHT_DISK)
        return lr_v3_dot(q, q) <= l->radius * l->radius ? t : INFINITY;
    /* q = s u + t v in the quad's plane: solve the 2x2 Gram system */
    lr_vec3 u = l->edge_u, v = l->edge_v;
    double uu = lr_v3_dot(u, u), uv = lr_v3_dot(u, v), vv = lr_v3_dot(v, v);
    double qu = lr_v3_dot(q, u), qv = lr_v3_dot(q, v), det = uu * vv - uv * uv;
    if (!(det > 0.0))
        return INFINITY;
    double a = (qu * vv - qv * uv) / det, b = (qv * uu - qu * uv) / det;
    return fabs(a) <= 1.0 && fabs(b) <= 1.0 ? t : INFINITY;
}

/* Nearest object or receiver along the ray, INFINITY when none. */
static double surface_t(const lr_scene *s, lr_vec3 o, lr_vec3 d)
{
    double best = INFINITY;
    lr_hit h;
    for (int k = 0; k < lr_scene_object_count(s); k++)
        if (lr_bvh_intersect(lr_scene_object_at(s, k)->bvh, o, d, 0.0, best, &h) && h.t < best)
            best = h.t;
    for (int k = 0; k < lr_scene_receiver_count(s); k++)
        if (lr_bvh_intersect(lr_scene_receiver_at(s, k)->bvh, o, d, 0.0, best, &h) && h.t < best)
            best = h.t;
    return best;
}

/* Whether an area light covers any of EMITTER_SUB^2 sub-pixel rays of pixel (x, y) before the
 * surface behind: the reference averages random points over the whole pixel, so an LED strip
 * narrower than a pixel still lights part of it (the pixel centre alone misses it). */
#define EMITTER_SUB 4
bool lr_eval_emitter_in_pixel(const lr_scene *s, int width, int height, int x, int y)
{
    for (int j = 0; j < EMITTER_SUB; j++)
        for (int i = 0; i < EMITTER_SUB; i++) {
            lr_vec3 o, d;
            lr_cpu_camera_ray(s, width * EMITTER_SUB, height * EMITTER_SUB, x * EMITTER_SUB + i,
                              y * EMITTER_SUB + j, &o, &d);
            double ts = surface_t(s, o, d);
            for (int k = 0; k < lr_scene_light_count(s); k++) {
                const lr_light *l = lr_scene_light_at(s, k);
                if (lr_light_is_area(l) && emitter_t(l, o, d) < ts)
                    return true;
            }
        }
    return false;
}

int lr_eval_masks_create(const lr_scene *s, int width, int height, lr_eval_masks *out, lr_err *e)
{
    *out = (lr_eval_masks){.width = width, .height = height};
    if (width < 1 || height < 1)
        return lr_err_set(e, LR_EINVAL, "masks: bad size %dx%d", width, height);
    size_t n = (size_t)width * (size_t)height;
    out->object = calloc(n, 1);
    out->receivers = calloc(n, 1);
    if (!out->object || !out->receivers) {
        lr_eval_masks_free(out);
        return lr_err_set(e, LR_ENOMEM, "masks: out of memory");
    }
    bool area = false;
    for (int k = 0; k < lr_scene_light_count(s); k++)
        area |= lr_light_is_area(lr_scene_light_at(s, k));
    for (int y = 0; y < height; y++)
        for (int x = 0; x < width; x++) {
            lr_vec3 o, d;
            lr_cpu_camera_ray(s, width, height, x, y, &o, &d);
            double best = INFINITY;
            int kind = 0; /* 0 none, 1 object, 2 receiver */
            lr_hit h;
            for (int k = 0; k < lr_scene_object_count(s); k++)
                if (lr_bvh_intersect(lr_scene_object_at(s, k)->bvh, o, d, 0.0, best, &h) &&
                    h.t < best)
                    best = h.t, kind = 1;
            for (int k = 0; k < lr_scene_receiver_count(s); k++)
                if (lr_bvh_intersect(lr_scene_receiver_at(s, k)->bvh, o, d, 0.0, best, &h) &&
                    h.t < best)
                    best = h.t, kind = 2;
            if (kind && area && lr_eval_emitter_in_pixel(s, width, height, x, y))
                kind = 0; /* an area light in front: in neither mask */
            size_t i = (size_t)y * width + x;
            if (kind == 1)
                out->object[i] = 1, out->object_px++;
            else if (kind == 2)
                out->receivers[i] = 1, out->receiver_px++;
        }
    return LR_OK;
}

void lr_eval_masks_free(lr_eval_masks *m)
{
    free(m->object);
    free(m->receivers);
    *m = (lr_eval_masks){0};
}
