/* lamprig — CPU twin of the sh_translucency model (seed 002; render/optics/sh_translucency.h):
 * the light G-buffer replaced by ray casts through the same texels (render/passes/
 * gbuffer_camera.h), so the projection and the thickness are the GPU pass's, up to the
 * rasteriser's coverage at silhouettes. */
#ifndef LR_MODELS_SH_H
#define LR_MODELS_SH_H

#include <stdbool.h>

#include "render/models/twin/radiosity.h"
#include "render/optics/sh_translucency.h"
#include "render/core/gbuffer_camera.h"
#include "render/scene/scene.h"

/* Projects the light entering `obj` from `light` (unit intensity) through cam's views of
 * size x size texels: one ray per texel centre, first surface of obj (open objects two-sided,
 * as the G-buffer), none where another of `others` is nearer (lr_cpu_radiosity_desc). Returns
 * the finished environment. */
void lr_cpu_sh_env(const lr_scene_object *obj, const lr_light *light, const lr_gb_camera *cam,
                   int size, const lr_scene_object *const *others, int n_others, int threads,
                   lr_sh_env *out);
/* The thickness the light crossed to reach x_o (seed 002 Sec. 2.2, the shadow-map depth
 * difference): |x_o - x_l| minus the distance to the first surface toward x_o (directional:
 * the depth difference along the light), >= 0; 0 where the ray meets nothing. False where
 * another object is the first surface (its shadow: no light of obj's own). d (may be NULL)
 * gives the other objects and the G-buffer texel emulation (snap, as the pass estimator). */
bool lr_cpu_sh_thickness(const lr_scene_object *obj, const lr_light *light, lr_vec3 xo,
                         const lr_cpu_radiosity_desc *d, double *thickness, lr_vec3 *ni);
/* B per band at (x_o, n_o) for a unit light: lr_sh_translucency_B with the object's energy
 * scale (lr_sh_object_scale of its material's sh_scale) and the thickness above, plus the
 * direct term where x_o is the light's first surface (lr_sh_lit, lr_sh_direct). *ni (may be
 * NULL) receives the G-buffer's normal toward x_o (0 where there is no surface). */
void lr_cpu_sh_B(const lr_scene_object *obj, const lr_light *light, const lr_sh_env *env,
                 lr_vec3 xo, lr_vec3 no, const lr_cpu_radiosity_desc *d, double out[3]);

#endif
