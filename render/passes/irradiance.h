/* lamprig — the receiver irradiance pass (issue 11; render/passes/PIPELINE.md "Receiver
 * irradiance cache"; irradiance.c): E_vpl per light at unit intensity over every plane
 * receiver, view-independent, read by composition. */
#ifndef LR_IRRADIANCE_H
#define LR_IRRADIANCE_H

#include "render/passes/passes.h"
#include "render/passes/vpl.h"

/* The grid array and one framebuffer per plane receiver, allocated on first use and again
 * when the number of receivers or lights changes; layers layer[i] + l for plane receiver i
 * (-1: not cached). */
typedef struct lr_irradiance {
    lr_tex *grid;
    lr_fb *fb[LR_MAX_RECEIVERS];
    int layer[LR_MAX_RECEIVERS];
    int n_receivers, n_lights; /* what the grids were allocated for */
    bool valid;                /* drawn from the current VPLs */
    /* Translucent radiosity (seed 000): the irradiance the VPLs do not carry (receiver
     * inter-reflection, objects' inner faces), laid out like grid; NULL when no object uses
     * the model. */
    lr_tex *tr_E;
    /* Receiver inter-reflection for every model (render/bounce/rbounce.h; render.receiver_bounce):
     * after the grids are drawn they are read back, the receivers' radiosity solved per light
     * and the bounce added to them; NULL when off. */
    struct lr_rbounce *rb;
    /* The objects' inner faces' light through their openings (render/openings/openings.h;
     * render.opening_light): added to the read-back grids before the bounce; NULL when off. */
    struct lr_openings *op;
} lr_irradiance;

/* Frees the grids (they are laid out again at the next run). */
void lr_irradiance_free(lr_irradiance *irr);
/* The grids from the VPLs v (rad: their visibility scale). */
int lr_irradiance_run(lr_irradiance *irr, const lr_pass_ctx *c, const lr_vpl *v,
                      const lr_radiosity *rad, lr_err *e);
/* Receiver i's grid for compose_receiver.frag (unit 15), or u_cached = false. */
void lr_irradiance_bind(const lr_irradiance *irr, const lr_pass_ctx *c, lr_program *p,
                        int receiver);

#endif
