/* lamprig — pass 2, the scattered-radiosity maps (render/passes/PIPELINE.md; radiosity.c), and
 * Algorithm 1's bindings for the passes that gather from them (vpl, compose). */
#ifndef LR_RADIOSITY_H
#define LR_RADIOSITY_H

#include "render/passes/gbuffer.h"
#include "render/passes/passes.h"
#include "render/transrad/tr_scene.h"

/* Texels per row of the per-vertex B textures (radiosity.vert's u_tr_width). */
#define LR_TR_TEX_WIDTH 1024

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
    lr_fb *fb[LR_MAX_LIGHTS * LR_MAX_K]; /* [l K + k]: B, x_o, n_o and depth (restart) */
    /* [l K + k]: B and depth only, for the frames that write B alone (every frame after a
     * restart's first, and the first of further lights). glEnable(GL_BLEND) enables blending
     * for every attachment, draw buffer NONE or not, and blending a 32-bit float attachment
     * needs GL_EXT_float_blend: with x_o and n_o (RGBA32F) attached, a driver without it (the
     * Pi 5's V3D) rejects the accumulating draw with GL_INVALID_OPERATION. This needs nothing
     * beyond ES 3.0, unlike per-buffer glEnablei (ES 3.2 or OES_draw_buffers_indexed). */
    lr_fb *acc[LR_MAX_LIGHTS * LR_MAX_K];
    float scale[LR_MAX_LIGHTS]; /* light l's maps store B * scale[l] */
    int F; /* frames accumulated */
    /* Whether a frame's estimate differs from the last one's: some object's B is sampled by
     * the estimator (seeded by the frame) rather than solved or evaluated (translucent
     * radiosity's per-vertex B, the diffusion grid's field, SH: the same every frame). Set
     * at each restart; false: the running mean is its first frame, to float rounding. */
    bool sampled;
    /* Translucent radiosity (seed 000): the solver, rebuilt when geometry or materials
     * change, re-solved per light at each restart; per object a texture of its vertices' B,
     * rows tr_rows[i] per light (NULL for an object with another model). */
    lr_tr_scene *tr;
    lr_tex *trB[LR_MAX_OBJECTS];
    int tr_rows[LR_MAX_OBJECTS];
    /* Seed 001's diffusion_grid objects: their solves (CPU, redone when the maps restart) and
     * the solved fields on the GPU, one 2D array per object: layer l nz + z holds light l's
     * slice z (render/shaders/lib/dgrid.glsl). */
    struct lr_dscene *dscene;
    lr_tex *dg_tex[LR_MAX_OBJECTS];
    int dg_dims[LR_MAX_OBJECTS][3];
    int dg_lights[LR_MAX_OBJECTS];
    /* sh_translucency objects (seed 002, render/passes/sh.c): per light the finished E_lm of
     * each object, 3 vec3 per object (u_sh_E), and per object the energy scale (u_sh_scale). */
    bool has_sh;
    float sh_E[LR_MAX_LIGHTS][27 * LR_MAX_OBJECTS];
    float sh_scale[3 * LR_MAX_OBJECTS];
    float sh_rho[4 * LR_MAX_OBJECTS]; /* rho.rgb (lr_dipole_rd_total), lit threshold (mm) */
    unsigned gen; /* runs so far: a reader's result made from other maps is stale */
} lr_radiosity;

/* Maps for c->rs (K, map_size) and c->n_lights lights; accumulation restarts. */
int lr_radiosity_alloc(lr_radiosity *rad, const lr_pass_ctx *c, lr_err *e);
/* The maps' textures and framebuffers (laid out again by lr_radiosity_alloc for new settings);
 * the CPU solvers' states (the diffusion grids, translucent radiosity) stay: they are keyed on
 * the scene and rebuild only what changed, and every restart uploads their results again. */
void lr_radiosity_release(lr_radiosity *rad);
/* Everything, the solvers too. */
void lr_radiosity_free(lr_radiosity *rad);
/* Adds one frame to the running mean, or restarts it (restart, or nothing accumulated): the
 * map cameras from the current geometry, the scale per light from gb's light types. */
int lr_radiosity_run(lr_radiosity *rad, const lr_pass_ctx *c, const lr_gbuffer *gb, bool restart,
                     lr_err *e);

/* sh.c: when any object has model sh_translucency, reads back every light's G-buffer and
 * projects the light entering each such object (lr_sh_env_add per texel), fills sh_E and
 * sh_scale. Run at restart, after the G-buffer pass. */
int lr_radiosity_sh_project(lr_radiosity *rad, const lr_pass_ctx *c, const lr_gbuffer *gb,
                            lr_err *e);
/* Sets u_sh_E (light l's) and u_sh_scale on the radiosity program. */
void lr_radiosity_sh_uniforms(const lr_radiosity *rad, lr_program *p, int l);

/* Algorithm 1 uniforms and samplers (units 4..6, render/shaders/lib/gather.glsl); the gather
 * returns sum_l w[l] B_l (u_light_w), w per light and band. */
void lr_radiosity_bind_gather(const lr_radiosity *rad, lr_program *p, const double w[][3]);
/* Only the gather's weights u_light_w (w[l] / scale[l]), for a per-object change. */
void lr_radiosity_set_light_w(const lr_radiosity *rad, lr_program *p, const double w[][3]);
/* The running mean's blend weight for frame F (1/F; for RGBA16F targets rounded to a multiple
 * of 2^-11, radiosity.c says why). Shared with the area lights' direct grid (area_direct.c). */
float lr_radiosity_blend_weight(lr_tex_format format, int F);

#endif
