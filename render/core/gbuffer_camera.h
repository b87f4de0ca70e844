/* lamprig — the light G-buffer's cameras (pass 1, render/passes/PIPELINE.md) as plain math, so
 * that the CPU twin can cast its rays through the very texels the GPU draws (the sh_translucency
 * projection, render/optics/sh_translucency.h). No GL here. */
#ifndef LR_CORE_GBUFFER_CAMERA_H
#define LR_CORE_GBUFFER_CAMERA_H

#include <stdbool.h>

#include "render/base/vec3.h"
#include "render/scene/scene.h"

/* Light G-buffer layouts (render/shaders/lib/gbuffer.glsl u_gb_mode; reach GLSL as the defines
 * of the same names). */
enum lr_gb_mode { LR_GB_CUBE = 0, LR_GB_PERSPECTIVE = 1, LR_GB_ORTHO = 2 };

typedef struct lr_gb_camera {
    enum lr_gb_mode mode;
    int views;        /* 6 cube faces (lr_cube_face_vp order) or 1 */
    double vp[6][16]; /* world -> clip of each view */
} lr_gb_camera;

/* The cameras gbuffer.c draws light `light` with, for objects in the bounding sphere (c, R):
 * a cube around an enclosed point light or area-light sample (or one within 1.05 R of c), else a perspective map
 * holding the sphere (point) or the spot cone (spot), or an orthographic map over the sphere
 * (directional). */
void lr_gb_camera_make(const lr_light *light, lr_vec3 c, double R, bool enclosed,
                       lr_gb_camera *out);
/* The same for light l of scene s (its bounds and the light's enclosure); an area light at
 * accumulation frame `frame`'s sample (lr_light_at_frame, render/area/frames.h), frame 0 for
 * lr_gb_camera_scene (the sh_translucency projection sees an area light from that sample). */
void lr_gb_camera_scene(const lr_scene *s, int l, lr_gb_camera *out);
void lr_gb_camera_scene_frame(const lr_scene *s, int l, long frame, lr_gb_camera *out);

/* View-projection of cube face f (0..5 = +X..-Z) around `at`. */
void lr_cube_face_vp(lr_vec3 at, int f, double znear, double zfar, double out[16]);

#endif
