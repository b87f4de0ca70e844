/* lamprig — the light-propagation volume's pass (render.lpv > 0; render/lpv/, seed 004): a
 * row of its own in the renderer's pass table (render/renderer.c, "lpv"), due when the light
 * geometry, the objects, their material, the receivers or the settings change (the volume
 * depends on all of them and on nothing the camera or a dimmer changes). Per light, at unit
 * radiance (area) or intensity (point, spot): injection and gathering on the CPU, propagation
 * on the compute shader (render/lpv/gpu.h), giving
 *   - the plane receivers' indirect irradiance grids (`recv`, one layer per plane receiver
 *     and light, the area pass's layout: render/passes/area_direct.h adds them to every
 *     frame's direct light);
 *   - the objects' irradiance field (`obj`, render/lpv/objfield.h), read by composition
 *     (render/shaders/lib/lpv_object.glsl: compose_object.frag, compose_cached.frag).
 * The CPU twin builds the same with the CPU propagation (render/cpu/frame.c). */
#ifndef LR_LPV_PASS_H
#define LR_LPV_PASS_H

#include "render/lpv/scene_lpv.h"
#include "render/passes/passes.h"

typedef struct lr_lpv_pass {
    lr_tex *recv; /* NULL: no plane receiver */
    lr_tex *obj;  /* NULL: no light lit the objects through the volume */
    int n, n_lights;
    lr_vec3 origin;
    double h;
    bool valid;   /* built for the current scene */
    double build_s; /* wall time of the last run, s (CPU injection and gathering included) */
    lr_lpv_scene_stats stats[LR_MAX_LIGHTS];
} lr_lpv_pass;

void lr_lpv_pass_free(lr_lpv_pass *p);
/* Rebuilds both for every light of the scene (c->rs->lpv cells per axis). */
int lr_lpv_pass_run(lr_lpv_pass *p, const lr_pass_ctx *c, lr_err *e);
/* Sets lib/lpv_object.glsl's uniforms for object `object` (unit 18); scale[l] the image's
 * scale for light l (compose.c). With p NULL or not valid: off. */
void lr_lpv_pass_bind_objects(const lr_lpv_pass *p, const lr_pass_ctx *c, lr_program *prog,
                              int object, const float scale[LR_MAX_LIGHTS]);

#endif
