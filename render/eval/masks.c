/* Object and receiver pixels by ray casting (eval.h): the same camera rays as the CPU twin, so
 * the masks do not depend on what either renderer produced. */
#include "render/eval/eval.h"

#include <math.h>
#include <stdlib.h>

#include "render/cpu/frame.h"
#include "render/mesh/bvh.h"

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
