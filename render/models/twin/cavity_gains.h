/* lamprig — the cavity closure (render/core/cavity.h) of the per-object models: which models
 * close a cavity around an enclosed light, with what total, and the gains the GPU renderer and
 * the CPU twin both apply. */
#ifndef LR_MODELS_CAVITY_GAINS_H
#define LR_MODELS_CAVITY_GAINS_H

#include "render/base/err.h"
#include "render/core/cavity.h"
#include "render/scene/scene.h"

/* Measures the closure for object obj and light l (enclosure: lr_scene_light_enclosure's
 * answer for this pair; the gain is 1 unless it is LR_ENCLOSURE_HULL), with the object's
 * model's B (lr_cpu_radiosity, untruncated sampler) and half-space total. */
int lr_cavity_measure(const lr_scene_object *obj, const lr_light *l,
                      enum lr_enclosure enclosure, const lr_cavity_desc *d, lr_cavity *out,
                      lr_err *e);

/* The gains the renderer (GLSL composition) and lr_cpu_render apply, so that both get the same
 * numbers: for light `light` of scene s, gain[o] for every object o < nobj, 1 except for the
 * object that encloses the light (lr_scene_light_enclosure: LR_ENCLOSURE_HULL), measured with
 * LR_CAVITY_SCENE_DESC (a few ms). */
#define LR_CAVITY_SCENE_DESC {.directions = 2048, .points = 128, .N = 32, .seed = 1}
int lr_cavity_scene_gains(const lr_scene *s, int light, int threads, double (*gain)[3],
                              int nobj, lr_err *e);

#endif
