/* lamprig — the light-propagation volume's propagation on GLES 3.1 compute shaders
 * (render/shaders/lpv_propagate.comp; the CPU twin is lpv.c/propagate.c, the layouts are
 * lpv.h's). Injection and blocking stay on the CPU (GLES 3.1 has no float image atomics) and
 * are uploaded; each step is one dispatch of 4^3 groups ping-ponging two rgba32f 3D textures
 * of the light, with the absorbed record in an r32f 3D image updated in place. No geometry
 * shaders. All calls need the lr_gl's context current. */
#ifndef LR_LPV_GPU_H
#define LR_LPV_GPU_H

#include "render/base/err.h"
#include "render/gl/gl.h"
#include "render/lpv/lpv.h"

typedef struct lr_lpv_gpu lr_lpv_gpu;

/* Textures for n^3 cells and the program (shaders under `shader_dir`, NULL: render/shaders
 * from the source tree). LR_EINVAL for n out of [2, 128]; LR_EGL. */
int lr_lpv_gpu_create(lr_gl *gl, int n, const char *shader_dir, lr_lpv_gpu **out, lr_err *e);
void lr_lpv_gpu_destroy(lr_lpv_gpu *g);

/* Uploads the CPU volume's light in flight, blocking and absorbed record (its n must match:
 * LR_EINVAL) and its stencil. */
int lr_lpv_gpu_upload(lr_lpv_gpu *g, const lr_lpv *v, lr_err *e);
/* `steps` steps (0 to 4 n, LR_EINVAL otherwise). */
int lr_lpv_gpu_propagate(lr_lpv_gpu *g, int steps, lr_err *e);
/* Reads the light in flight and the absorbed record back into v (lr_lpv_set_state). */
int lr_lpv_gpu_download(lr_lpv_gpu *g, lr_lpv *v, lr_err *e);
/* Upload, STEPS propagation steps, read back: the `propagate` callback of lr_lpv_scene_desc
 * (render/lpv/scene_lpv.h) for the compute shader; ctx is the lr_lpv_gpu. */
int lr_lpv_gpu_run(void *ctx, lr_lpv *v, int steps, lr_err *e);

#endif
