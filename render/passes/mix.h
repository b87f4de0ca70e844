/* lamprig — the mix pass: per-light images as a per-band weighted geometric mean of up to
 * LR_MIX_MAX_SETS image arrays, out[l] = prod_k (in_k[l] / d_k[l])^a_k (per band, the
 * weights a_k summing to 1 in each band, d_k[l] set k's scale of light l), for the
 * control-space cache (render/async/cache.h): an interpolated state's images from the cached
 * states around it, drawn once per new interpolation; the blend pass then weighs them per
 * light at every frame as it does the worker's own (render/passes/blend.h).
 *
 * It owns its program and takes its inputs and target explicitly; nothing here reads the
 * renderer.
 */
#ifndef LR_MIX_H
#define LR_MIX_H

#include "render/base/err.h"
#include "render/gl/gl.h"
#include "render/gl/tex.h"
#include "render/scene/scene.h"

#define LR_MIX_MAX_SETS 6

typedef struct lr_mix lr_mix;

typedef struct lr_mix_input {
    const lr_tex *sets[LR_MIX_MAX_SETS]; /* 2D arrays, at least `layers` layers, the target's size */
    int n;                               /* 1..LR_MIX_MAX_SETS */
    int layers;                          /* of the target to draw, 1..LR_SCENE_MAX_LIGHTS */
    double a[LR_MIX_MAX_SETS][3];           /* weight per set and band, summing to 1 per band */
    double d[LR_MIX_MAX_SETS][LR_SCENE_MAX_LIGHTS]; /* divisor per set and layer (> 0) */
} lr_mix_input;

int lr_mix_create(lr_gl *gl, const char *shader_dir, lr_mix **out, lr_err *e);
void lr_mix_destroy(lr_mix *m);
/* Draws in into target's layers 0..in->layers-1 (an RGBA32F 2D array). */
int lr_mix_run(lr_mix *m, const lr_mix_input *in, lr_tex *target, lr_err *e);

#endif
