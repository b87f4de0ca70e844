/* What the camera ray through a pixel meets first (tests/support/pixel_hit.h). */
#include "tests/support/pixel_hit.h"

#include <math.h>

#include "render/cpu/frame.h"

int lr_test_pixel_hit(const lr_scene *s, int w, int h, int x, int y)
{
    lr_vec3 org, dir;
    lr_cpu_camera_ray(s, w, h, x, y, &org, &dir);
    lr_hit hit;
    double best = INFINITY;
    int who = -1;
    for (int i = 0; i < lr_scene_object_count(s); i++)
        if (lr_bvh_intersect(lr_scene_object_at(s, i)->bvh, org, dir, 0, best, &hit) &&
            hit.t < best) {
            best = hit.t;
            who = 0;
        }
    for (int i = 0; i < lr_scene_receiver_count(s); i++)
        if (lr_bvh_intersect(lr_scene_receiver_at(s, i)->bvh, org, dir, 0, best, &hit) &&
            hit.t < best) {
            best = hit.t;
            who = 1 + i;
        }
    return who;
}

int lr_test_pixel_receiver(const lr_scene *s, int w, int h, int x, int y)
{
    int k = lr_test_pixel_hit(s, w, h, x, y);
    return k >= 1 ? k - 1 : -1;
}
