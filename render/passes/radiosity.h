/* lamprig — pass 2, the scattered-radiosity maps (render/passes/PIPELINE.md; radiosity.c), and
 * Algorithm 1's bindings for the passes that gather from them (vpl, compose). */
#ifndef LR_RADIOSITY_H
#define LR_RADIOSITY_H

#include "render/passes/gbuffer.h"
#include "render/passes/passes.h"

typedef struct lr_radiosity {
    int K, size, n_lights;
    lr_vec3 center;
    double radius, r_max;
    lr_vec3 d[LR_MAX_K];
    double vp[LR_MAX_K][16];  /* world -> clip */
    double P[LR_MAX_K][16];   /* world -> texture (Algorithm 1's P_k) */
    float Pf[LR_MAX_K * 16];
    float df[LR_MAX_K * 3];
    float eps_bias, eps_comb; /* depth units, mm */
    /* B: K maps per light, layer l K + k for light l's map k (unit intensity); x_o, n_o and
     * depth: K layers shared by all lights (the map cameras do not depend on them). */
    lr_tex *B, *pos, *nrm, *depth;
    lr_fb *fb[LR_MAX_LIGHTS * LR_MAX_K]; /* [l K + k] */
    float scale[LR_MAX_LIGHTS]; /* light l's maps store B * scale[l] */
    int F; /* frames accumulated */
    unsigned gen; /* runs so far: a reader's result made from other maps is stale */
} lr_radiosity;

/* Maps for c->rs (K, map_size) and c->n_lights lights; accumulation restarts. */
int lr_radiosity_alloc(lr_radiosity *rad, const lr_pass_ctx *c, lr_err *e);
void lr_radiosity_free(lr_radiosity *rad);
/* Adds one frame to the running mean, or restarts it (restart, or nothing accumulated): the
 * map cameras from the current geometry, the scale per light from gb's light types. */
int lr_radiosity_run(lr_radiosity *rad, const lr_pass_ctx *c, const lr_gbuffer *gb, bool restart,
                     lr_err *e);

/* Algorithm 1 uniforms and samplers (units 4..6, render/shaders/lib/gather.glsl); the gather
 * returns sum_l w[l] B_l (u_light_w), w per light and band. */
void lr_radiosity_bind_gather(const lr_radiosity *rad, lr_program *p, const double w[][3]);
/* Only the gather's weights u_light_w (w[l] / scale[l]), for a per-object change. */
void lr_radiosity_set_light_w(const lr_radiosity *rad, lr_program *p, const double w[][3]);

#endif
