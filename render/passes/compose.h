/* lamprig — pass 3, composition (render/passes/PIPELINE.md; compose.c): one linear image per
 * light at unit intensity for the current view, objects through Algorithm 1 over the
 * radiosity maps, receivers lit directly (shadowed through the G-buffers) and by the VPLs. */
#ifndef LR_COMPOSE_H
#define LR_COMPOSE_H

#include "render/passes/area_direct.h"
#include "render/passes/gbuffer.h"
#include "render/passes/irradiance.h"
#include "render/passes/lpv_pass.h"
#include "render/passes/passes.h"
#include "render/passes/radiosity.h"
#include "render/passes/surface.h"
#include "render/passes/vpl.h"

/* Composition's output: layer l of `images` (colour attachment l of `fb`, RGBA32F) is light
 * l's unit-intensity image times scale[l], alpha 0 on object pixels no map sees. Valid until
 * the view, the receivers or the transport change. */
typedef struct lr_compose {
    lr_tex *images;
    lr_fb *fb;
    int n;      /* layers (the scene's lights when allocated) */
    bool valid; /* composed since the last (re)allocation */
    bool gathered; /* the last run ran Algorithm 1 per pixel (no surface cache) */
    /* Per light: the images hold scale[l] L_l (the maps' scale, R^2 for point and spot
     * lights: O(1) values, as half floats would need); the blend divides it out. */
    float scale[LR_MAX_LIGHTS];
} lr_compose;

/* What composition reads: the other passes' results. */
typedef struct lr_compose_inputs {
    const lr_gbuffer *gbuffer;      /* direct light and its shadows on the receivers */
    const lr_radiosity *radiosity;  /* Algorithm 1 for the objects */
    const lr_vpl *vpl;              /* emergent light on box receivers (unallocated: none) */
    const lr_irradiance *irradiance; /* emergent light on plane receivers, cached */
    const lr_area_direct *area;     /* area lights' direct light on plane receivers */
    const lr_surface *surface;      /* the objects' B per refined vertex; NULL: Algorithm 1
                                     * per pixel (render.surface_cache off) */
    const lr_lpv_pass *lpv;         /* render.lpv: the volume's light on the objects; NULL:
                                     * none (lpv_pass.h) */
} lr_compose_inputs;

/* Images of the output size for c->n_lights lights. */
int lr_compose_alloc(lr_compose *img, const lr_pass_ctx *c, lr_err *e);
void lr_compose_free(lr_compose *img);
int lr_compose_run(lr_compose *img, const lr_pass_ctx *c, const lr_compose_inputs *in,
                   lr_err *e);

#endif
