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
    /* The bounce while it is off, kept for when it comes back (the rig's preview frame turns
     * it off and the refinement right after it on again: rebuilt, its F and the receivers'
     * light on the objects cost about a second on the candle at every change). */
    struct lr_rbounce *rb_parked;
    /* The receivers' light on the objects (render/bounce/objlight.h;
     * render.receiver_light_on_objects), per object: E+ and E- per vertex and light at unit
     * intensity, LR_RL_TEX_WIDTH texels a row, light l side s (0: E+, 1: E-) from row
     * (2 l + s) rl_rows[i]; by vertex index (rl, compose_object.vert) and by corner 3 t + c of
     * the unindexed mesh (rlu, compose_cached.vert). NULL when off. */
    lr_tex *rl[LR_MAX_OBJECTS], *rlu[LR_MAX_OBJECTS];
    int rl_rows[LR_MAX_OBJECTS], rlu_rows[LR_MAX_OBJECTS];
    /* The objects' inner faces' light through their openings (render/openings/openings.h;
     * render.opening_light): added to the read-back grids before the bounce; NULL when off. */
    struct lr_openings *op;
} lr_irradiance;

#define LR_RL_TEX_WIDTH 1024 /* render/shaders/lib/recv_light_vert.glsl */

/* Frees the grids (they are laid out again at the next run). */
void lr_irradiance_free(lr_irradiance *irr);
/* The grids and textures alone: the receiver bounce's patches, F and per-vertex rows and the
 * openings' geometry stay (their own keys rebuild them when the geometry, the receivers or a
 * light change), so a material change (which lays the grids out again) does not rebuild them:
 * the objects' rows cost about a second per change on llvmpipe's machine. */
void lr_irradiance_free_grids(lr_irradiance *irr);
/* The grids from the VPLs v (rad: their visibility scale). */
int lr_irradiance_run(lr_irradiance *irr, const lr_pass_ctx *c, const lr_vpl *v,
                      const lr_radiosity *rad, lr_err *e);
/* Receiver i's grid for compose_receiver.frag (unit 15), or u_cached = false. */
void lr_irradiance_bind(const lr_irradiance *irr, const lr_pass_ctx *c, lr_program *p,
                        int receiver);
/* Object i's receiver light for compose_object / compose_cached (unit 19; unindexed: the
 * surface cache's mesh): u_rl_on, the texture and row, kR and kT times the images' scale per
 * light (lib/recv_light.glsl). */
void lr_irradiance_bind_objects(const lr_irradiance *irr, const lr_pass_ctx *c, lr_program *p,
                                int object, bool unindexed, const float scale[LR_MAX_LIGHTS]);

#endif
