/* What the camera ray through a pixel meets first (tests comparing images by region). */
#ifndef LR_TEST_PIXEL_HIT_H
#define LR_TEST_PIXEL_HIT_H

#include "render/scene/scene.h"

/* The ray through pixel (x, y) of a w x h image (rows top down, lr_cpu_camera_ray): 0 an
 * object, 1 + i receiver i, -1 nothing. */
int lr_test_pixel_hit(const lr_scene *s, int w, int h, int x, int y);
/* The receiver it meets first; -1 for an object or nothing. */
int lr_test_pixel_receiver(const lr_scene *s, int w, int h, int x, int y);

#endif
