/* lamprig — the first-surface ray cast that the light G-buffer stands for, shared by the CPU
 * twin, the light paths and the models: what the rasteriser would store in the texel along a
 * direction (position and interpolated normal), and an orthonormal frame at a normal. */
#ifndef LR_CORE_RAY_H
#define LR_CORE_RAY_H

#include <stdbool.h>

#include "render/base/vec3.h"
#include "render/scene/scene.h"

/* The light G-buffer's texel along unit direction dir from origin o: first surface of the
 * object with t > tmin; x_i and its interpolated unit normal. False when the ray misses. */
bool lr_first_surface(const lr_scene_object *obj, lr_vec3 o, lr_vec3 dir, double tmin,
                      lr_vec3 *xi, lr_vec3 *ni);

/* Orthonormal tangents t1, t2 of unit n (t1 x t2 = n). */
void lr_tangents(lr_vec3 n, lr_vec3 *t1, lr_vec3 *t2);

#endif
