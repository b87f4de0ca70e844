/* lamprig tests — the light G-buffer's texels as the CPU twin's lookups, for GPU/twin parity:
 * the twin casts through the texel centres the GPU's G-buffer holds (lr_cpu_radiosity_desc's
 * snap), so texel quantisation is not counted as a difference. */
#ifndef LR_TEST_GBUFFER_SNAP_H
#define LR_TEST_GBUFFER_SNAP_H

#include "render/base/vec3.h"
#include "render/renderer.h"
#include "render/renderer_debug.h"

typedef struct lr_test_snap {
    lr_debug_gbuffer_info info;
    double inv[6][16];
} lr_test_snap;

/* The light G-buffer's texel for a lookup (render/shaders/lib/gbuffer.glsl): cube face by the
 * major axis (GL's selection), or the 2D map; the texel floor((ndc * 0.5 + 0.5) * size) its
 * rasterisation put there; returned: the direction (point for a directional light) through
 * that texel's centre, whose first surface the texel holds. p is an lr_test_snap. */
lr_vec3 lr_test_snap_lookup(void *p, lr_vec3 v);
/* Reads light `light`'s G-buffer cameras from the renderer; fails the test if one is singular. */
void lr_test_snap_init(lr_renderer *r, int light, lr_test_snap *g);

#endif
