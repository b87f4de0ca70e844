/* lamprig — pass 4, emergent light: virtual point lights on the objects' outer surface
 * (render/passes/PIPELINE.md; vpl.c), and their bindings for the passes that sum them
 * (irradiance, compose: render/shaders/lib/vpl_irradiance.glsl). */
#ifndef LR_VPL_H
#define LR_VPL_H

#include "render/passes/passes.h"
#include "render/passes/radiosity.h"

typedef struct lr_vpl {
    int n, size, n_lights;
    lr_vec3 center;
    double radius; /* the objects' bounding sphere about center, mm (the cube map lies in it) */
    lr_tex *outer_pos, *outer_nrm, *dirs;
    lr_fb *outer_fb[6];
    lr_tex *pos, *nrm, *B; /* N_vpl x 1; B: N_vpl x n_lights, row l for light l */
    lr_fb *fb;             /* NULL: not allocated (the renderer's no_vpl) */
    bool outer_valid;
} lr_vpl;

/* N_vpl VPLs and their vpl_map_size outer-surface cube (c->rs). */
int lr_vpl_alloc(lr_vpl *v, const lr_pass_ctx *c, lr_err *e);
void lr_vpl_free(lr_vpl *v);
/* B of every VPL through Algorithm 1 over rad's maps, row l for light l at unit intensity;
 * the outer-surface cube is redrawn first when the geometry changed. */
int lr_vpl_run(lr_vpl *v, const lr_pass_ctx *c, const lr_radiosity *rad, bool geometry_changed,
               lr_err *e);
/* The VPL inputs of lib/vpl_irradiance.glsl (units 7..10) and the cavity gains it applies;
 * v may be unallocated. rad gives the visibility test's scale. Returns whether there are
 * VPLs to sum (compose_receiver.frag's u_use_vpl). */
bool lr_vpl_bind(const lr_vpl *v, const lr_pass_ctx *c, const lr_radiosity *rad,
                 lr_program *p);

#endif
