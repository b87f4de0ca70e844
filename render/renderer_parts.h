/* lamprig — read-only views of the renderer's passes for render/renderer_debug.c, which reads
 * their results back; struct lr_renderer itself stays private to render/renderer.c. Nothing
 * else includes this. */
#ifndef LR_RENDERER_PARTS_H
#define LR_RENDERER_PARTS_H

#include "render/gl/timer.h"
#include "render/passes/blend.h"
#include "render/passes/compose.h"
#include "render/passes/gbuffer.h"
#include "render/passes/irradiance.h"
#include "render/passes/radiosity.h"
#include "render/passes/vpl.h"
#include "render/renderer.h"

typedef struct lr_renderer_parts {
    lr_gl *gl;
    lr_timer *timer;
    lr_slicer *slicer;
    const char *shader_dir;
    const char *const *defines; /* the renderer's lr_passes_defines */
    int width, height;
    unsigned seed;
    const lr_render_settings *rs; /* the settings the resources were made for */
    const lr_pass_objects *objs;
    const lr_gbuffer *gbuffer;
    const lr_radiosity *radiosity;
    const lr_vpl *vpl;
    const lr_compose *compose;
    const lr_surface *surface;
    const lr_irradiance *irradiance;
    lr_blend *blend; /* NULL when resources failed to allocate */
} lr_renderer_parts;

void lr_renderer_parts_get(const lr_renderer *r, lr_renderer_parts *out);

#endif
