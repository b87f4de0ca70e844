/* lamprig — pass 1, the light G-buffer (render/passes/PIPELINE.md; gbuffer.c): one per light,
 * the first surface of the translucent objects seen from it. Owned by the renderer's pass
 * table; radiosity and composition read it through lr_gbuffer_bind / lr_gbuffer_bind_lights. */
#ifndef LR_GBUFFER_H
#define LR_GBUFFER_H

#include "render/core/gbuffer_camera.h"
#include "render/passes/passes.h"


/* Light l's G-buffer, as the last run drew it. */
typedef struct lr_light_gbuffer {
    enum lr_light_type type;
    lr_vec3 pos, dir;
    float spot_cos[2]; /* cos(outer), cos(inner) */
    /* Area light (quad, disk; render/area/frames.h): pos is the frame's sample p_f, and the
     * radiosity pass's shape is area * cos(theta_e) about area_n (|cos| when two-sided). */
    lr_vec3 area_n;
    float area;
    bool two_sided;
    /* A photometric profile (lr_light_shape): its planes in the pass's profile texture at
     * rows l * LR_PROFILE_NC, its frame (C0, C90, nadir) in world space. */
    bool profile_on;
    lr_vec3 prof_x, prof_y, prof_z;
    enum lr_gb_mode mode;
    int size;
    lr_tex *pos_cube, *nrm_cube, *pos_2d, *nrm_2d;
    lr_fb *fb[6], *fb_2d;
    float vp[16]; /* 2D map: world -> clip */
    double vp_d[16];
    double face_vp[6][16];
} lr_light_gbuffer;

typedef struct lr_gbuffer {
    int n_lights;
    lr_light_gbuffer light[LR_MAX_LIGHTS];
    /* Every light's profile table (lib/profile.glsl): R32F, LR_PROFILE_NG wide, LR_PROFILE_NC
     * rows per light; uploaded when a light's table changes (profile_key: its hash, 0 none). */
    lr_tex *profiles;
    uint64_t profile_key[LR_MAX_LIGHTS];
    bool profiles_valid;
} lr_gbuffer;

/* The profile texture's unit in every program that reads it (lib/profile.glsl). */
#define LR_PROFILE_TEX_UNIT 20

/* Targets for c->n_lights lights of c->rs->gbuffer_size. */
int lr_gbuffer_alloc(lr_gbuffer *g, const lr_pass_ctx *c, lr_err *e);
void lr_gbuffer_free(lr_gbuffer *g);
/* `frame`: the accumulation frame about to be added to the maps (0 at a restart): an area
 * light is drawn from its sample of that frame (lr_area_frame_point, as the CPU twin's maps). */
int lr_gbuffer_run(lr_gbuffer *g, const lr_pass_ctx *c, long frame, lr_err *e);

/* Light l's G-buffer samplers and uniforms on units 0..3 (render/shaders/lib/gbuffer.glsl),
 * and its profile's (unit LR_PROFILE_TEX_UNIT). */
void lr_gbuffer_bind(const lr_gbuffer *g, lr_program *p, int l);
/* Every light's G-buffer positions and light uniforms (render/shaders/lib/lights.glsl): cube
 * maps on units 0..3, 2D maps on units 11..14; intensities from c->I. */
void lr_gbuffer_bind_lights(const lr_gbuffer *g, const lr_pass_ctx *c, lr_program *p);

#endif
