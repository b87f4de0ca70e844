/* lamprig tests — scenes and renderers for the render tests (small images and maps: llvmpipe
 * under ASan is slow). Every helper fails the running cmocka test on error. */
#ifndef LR_TEST_RENDER_H
#define LR_TEST_RENDER_H

#include <stdbool.h>

#include "render/base/vec3.h"
#include "render/gl/gl.h"
#include "render/renderer.h"
#include "render/scene/scene.h"

/* Settings small enough for tests: K = 6, N = 4, 48^2 maps, 64^2 G-buffer faces, 16^2 VPL
 * cube, 48 VPLs, 2 frames. */
extern const char *const lr_test_small_settings[];

/* Loads configs/scenes/NAME.json and applies the NULL-terminated "key=value" lists (either
 * may be NULL). */
lr_scene *lr_test_scene(const char *name, const char *const *sets1, const char *const *sets2);
/* Parses scene text. */
lr_scene *lr_test_scene_text(const char *text, const char *const *sets);
lr_renderer *lr_test_renderer(lr_gl *gl, lr_scene *s, int w, int h, bool no_vpl, unsigned seed);
/* The same from a full descriptor (gl and scene filled in by the caller). */
lr_renderer *lr_test_renderer_desc(const lr_renderer_desc *d);
/* Renders frames until lr_renderer_needs_frame is false (at most max); returns the count. */
int lr_test_converge(lr_renderer *r, int max);
/* One frame; returns its stats. */
lr_frame_stats lr_test_frame(lr_renderer *r);
/* lr_scene_set + lr_renderer_invalidate. */
void lr_test_set(lr_scene *s, lr_renderer *r, const char *key, const char *value);
/* HDR readback (w*h*3 floats, rows bottom up); the caller frees. */
float *lr_test_hdr(lr_renderer *r);
/* The GPU's converged final image of S (w x h, seed 3, 20 frames at most) against the CPU
 * twin's (LR_CPU_PASS), summed over object pixels (the ray meets objects[0]) and receiver
 * pixels: the object sums within 4 sigma of the twin's variance + 5 %, the receivers' within
 * RECV_TOL relative (without VPLs: direct light only) or 20 % with them. LABEL heads the
 * printed line. */
void lr_test_final_image_vs_twin(lr_gl *gl, lr_scene *s, int w, int h, const char *label,
                                 bool no_vpl, double recv_tol);
/* The pixel (GL order: row 0 at the bottom) where the camera sees world point p; false when
 * outside the image. */
bool lr_test_project(const lr_scene *s, int w, int h, lr_vec3 p, int *x, int *y);

/* World point where the ray through the centre of pixel (x, y) meets the plane through c with
 * normal n. */
lr_vec3 lr_test_pixel_on_plane(const lr_scene *s, int w, int h, int x, int y, lr_vec3 c, lr_vec3 n);

#endif
