/* lamprig — the renderer's private state, shared by its passes (one file per pass:
 * gbuffer.c, radiosity.c, vpl.c, compose.c; common.c holds meshes and shared uniforms).
 * Nothing outside render/renderer.c, render/renderer_debug.c and render/passes/ includes
 * this. The estimators are those of render/passes/PIPELINE.md. */
#ifndef LR_PASSES_H
#define LR_PASSES_H

#include <GLES3/gl31.h>
#include <stdbool.h>

#include "render/base/err.h"
#include "render/base/vec3.h"
#include "render/gl/gl.h"
#include "render/gl/shader.h"
#include "render/gl/tex.h"
#include "render/gl/timer.h"
#include "render/image/image.h"
#include "render/passes/blend.h"
#include "render/renderer.h"
#include "render/scene/scene.h"

/* Limits of the shaders' uniform arrays (render/shaders/lib/material.glsl, gather.glsl). */
#define LR_MAX_OBJECTS 8
#define LR_MAX_K 32
#define LR_MAX_RECEIVERS 16
#define LR_MAX_VPL 4096
/* Lights with their own G-buffer and radiosity maps (render/shaders/lib/lights.glsl unrolls
 * its sampler arrays for exactly this many); the scene loader refuses more. */
#define LR_MAX_LIGHTS LR_SCENE_MAX_LIGHTS
/* Frames accumulated at most in RGBA16F maps. Drivers may round the blended result toward
 * zero when storing half floats (llvmpipe does): the running mean then loses ~2^-13 of
 * itself per frame, 1.1% after 64 frames, 16% after 1024 (measured, tests/test_render_hard.c).
 * 32 frames keep that below 0.6%. */
#define LR_HALF_MAX_FRAMES 32

/* Tone curve of the output (lr_tonemap_op, render/image/image.h): the GPU pass and the PNG
 * writer of `lamprig render` use the same. */
#define LR_RENDER_TONEMAP LR_TONEMAP_ACES

/* Light G-buffer layouts (render/shaders/lib/gbuffer.glsl u_gb_mode). */
enum { LR_GB_CUBE = 0, LR_GB_PERSPECTIVE = 1, LR_GB_ORTHO = 2 };

typedef struct lr_gpu_mesh {
    GLuint vao, vbo[2], ebo;
    GLsizei count;
} lr_gpu_mesh;

struct lr_renderer {
    lr_gl *gl;
    lr_scene *scene;
    int width, height;
    bool no_vpl;
    bool vpl_visibility;
    unsigned seed;
    const lr_gl_caps *caps;
    lr_tex_format map_format; /* RGBA32F, or RGBA16F when float targets/blending are missing */
    char info[256];           /* renderer string for the stats */
    char shader_dir[512];
    lr_timer *timer;

    lr_program *p_surface, *p_depth, *p_radiosity, *p_vpl, *p_obj, *p_recv, *p_blit, *p_irr;

    /* Settings the resources were made for. */
    lr_render_settings rs;
    bool allocated;

    /* Meshes (re-uploaded when geometry, receivers or settings change). */
    int n_objects, n_receivers;
    lr_gpu_mesh obj[LR_MAX_OBJECTS];
    lr_gpu_mesh recv[LR_MAX_RECEIVERS];
    bool two_sided[LR_MAX_OBJECTS];
    float coef[5 * 4 * LR_MAX_OBJECTS];
    float sss[3 * 4 * LR_MAX_OBJECTS]; /* lr_passes_pack_sss per object */
    /* Per object: the S_d energy normalisation (lr_scene_object_sd_norm: coeffs.sd_norm, or 1
     * for "normalize": false and for the standard dipole), radiosity.frag's u_sd_norm
     * (PIPELINE.md "Energy"). */
    float sd_norm[3 * LR_MAX_OBJECTS];
    /* Per light and object, [3 (l LR_MAX_OBJECTS + i) + c]: the cavity gain of object i for
     * light l (render/cpu/cavity.h, measured on the CPU when the maps restart; 1 for lights
     * beyond n_lights). Composition multiplies light l's B of object i by it: folded into the
     * gather's weights per object (compose_object) and compose_receiver's u_cavity_gain for
     * the VPLs. */
    float cavity_gain[3 * LR_MAX_LIGHTS * LR_MAX_OBJECTS];

    /* One light G-buffer per light of the scene (lights[l] as seen by the last gbuffer
     * pass). */
    int n_lights;
    struct lr_light_gbuffer {
        int type;  /* 0 point, 1 spot, 2 directional */
        lr_vec3 pos, dir;
        float spot_cos[2]; /* cos(outer), cos(inner) */
        int mode;  /* LR_GB_* */
        int size;
        lr_tex *pos_cube, *nrm_cube, *pos_2d, *nrm_2d;
        lr_fb *fb[6], *fb_2d;
        float vp[16]; /* 2D map: world -> clip */
        double vp_d[16];
        double face_vp[6][16];
    } gb[LR_MAX_LIGHTS];

    /* Scattered-radiosity maps. */
    struct {
        int K, size;
        lr_vec3 center;
        double radius, r_max;
        lr_vec3 d[LR_MAX_K];
        double vp[LR_MAX_K][16];  /* world -> clip */
        double P[LR_MAX_K][16];   /* world -> texture (Algorithm 1's P_k) */
        float Pf[LR_MAX_K * 16];
        float df[LR_MAX_K * 3];
        float eps_bias, eps_comb; /* depth units, mm */
        /* B: K maps per light, layer l K + k for light l's map k (unit intensity); x_o, n_o
         * and depth: K layers shared by all lights (the map cameras do not depend on them). */
        lr_tex *B, *pos, *nrm, *depth;
        lr_fb *fb[LR_MAX_LIGHTS * LR_MAX_K]; /* [l K + k] */
        float scale[LR_MAX_LIGHTS]; /* light l's maps store B * scale[l] (radiosity.c) */
        int F; /* frames accumulated */
    } rad;

    /* VPLs. */
    struct {
        int n, size;
        lr_vec3 center;
        lr_tex *outer_pos, *outer_nrm, *dirs;
        lr_fb *outer_fb[6];
        lr_tex *pos, *nrm, *B; /* N_vpl x 1; B: N_vpl x n_lights, row l for light l */
        lr_fb *fb;
        bool outer_valid;
    } vpl;

    /* Receiver irradiance grids (irradiance.c, render/cpu/recv_grid.h): E_vpl per light at
     * unit intensity, layers layer[i] + l for plane receiver i (-1: not cached). */
    struct {
        lr_tex *grid;
        lr_fb *fb[LR_MAX_RECEIVERS];
        int layer[LR_MAX_RECEIVERS];
        int n_receivers, n_lights; /* what the grids were allocated for */
        bool valid;                /* drawn from the current VPLs */
    } irr;

    /* Composition's output, owned by compose.c: one linear image per light for unit
     * intensity (layer l of `images`, colour attachment l of `fb`), alpha 0 on object pixels
     * no map sees. Valid until the view, the receivers or the transport change. */
    struct {
        lr_tex *images;
        lr_fb *fb;
        int n;      /* layers (the scene's lights when allocated) */
        bool valid; /* composed since the last (re)allocation */
    } img;

    /* The blend pass (render/passes/blend.h): tone-mapped output and HDR sum. */
    lr_blend *blend;

    unsigned dirty;
    int frame_index;

    /* The clock of lr_renderer_set_time (flicker at composition). */
    bool clock_set;
    double time_s;
};

/* common.c */
/* The shaders' defines (LR_MAX_OBJECTS, LR_MAX_K, LR_MAX_LIGHTS), NULL-terminated. */
const char *const *lr_passes_defines(void);
int lr_passes_upload_meshes(lr_renderer *r, lr_err *e);
void lr_passes_free_meshes(lr_renderer *r);
void lr_passes_draw(const lr_gpu_mesh *m);
/* One object's block of render/shaders/lib/material.glsl's u_coef (20 floats). */
void lr_passes_pack_coeffs(const lr_coeffs *c, float out[20]);
/* One object's block of render/shaders/lib/material.glsl's u_sss (12 floats): the model
 * switch and the standard dipole's albedo', z_r, z_v. */
void lr_passes_pack_sss(const lr_coeffs *c, enum lr_sss_model model, float out[12]);
/* The multipole's slab into that block (multipole.c): out[7] = thickness_mm, out[11] =
 * lr_multipole_pairs; both 0 unless model is LR_SSS_MULTIPOLE. */
void lr_passes_pack_multipole(const lr_coeffs *c, enum lr_sss_model model, double thickness_mm,
                              float out[12]);
/* Coefficient blocks (u_coef, u_sss) of every object (render/shaders/lib/material.glsl). */
void lr_passes_update_coeffs(lr_renderer *r);
void lr_passes_set_coeffs(lr_renderer *r, const lr_program *p);
/* Measures r->cavity_gain for every light of the current scene (PIPELINE.md "Energy"). */
int lr_passes_update_cavity(lr_renderer *r, lr_err *e);
/* Light l's G-buffer samplers and uniforms on units 0..3 (render/shaders/lib/gbuffer.glsl). */
void lr_passes_bind_gbuffer(lr_renderer *r, const lr_program *p, int l);
/* Every light's G-buffer positions and light uniforms (render/shaders/lib/lights.glsl):
 * cube maps on units 0..3, 2D maps on units 11..14. */
void lr_passes_bind_lights(lr_renderer *r, const lr_program *p);
/* Algorithm 1 uniforms and samplers (units 4..6); the gather returns
 * sum_l w[l] B_l (render/shaders/lib/gather.glsl u_light_w), w per light and band. */
void lr_passes_bind_gather(lr_renderer *r, const lr_program *p, const double w[][3]);
/* Only the gather's weights u_light_w (w[l] / rad.scale[l]), for a per-object change. */
void lr_passes_set_light_w(lr_renderer *r, const lr_program *p, const double w[][3]);
void lr_passes_uniform_mat4(const lr_program *p, const char *name, const double m[16]);
void lr_passes_uniform_v3(const lr_program *p, const char *name, lr_vec3 v);
void lr_passes_uniform_i(const lr_program *p, const char *name, int v);
void lr_passes_uniform_f(const lr_program *p, const char *name, float v);
void lr_passes_bind_tex(const lr_program *p, const char *name, int unit, const lr_tex *t);
/* View-projection of cube face f (0..5 = +X..-Z) around `at`. */
void lr_passes_cube_face_vp(lr_vec3 at, int f, double znear, double zfar, double out[16]);
/* Light l of the scene. */
const lr_light *lr_passes_light(const lr_renderer *r, int l);
/* Light l's per-band intensity at composition: intensity * color. */
void lr_passes_light_rgb(const lr_renderer *r, int l, double out[3]);

/* The passes. */
int lr_pass_gbuffer(lr_renderer *r, lr_err *e);
int lr_pass_radiosity(lr_renderer *r, bool restart, lr_err *e);
int lr_pass_vpl(lr_renderer *r, bool geometry_changed, lr_err *e);
int lr_pass_compose(lr_renderer *r, lr_err *e);
/* Receiver irradiance grids from the VPLs (irradiance.c). */
int lr_pass_irradiance(lr_renderer *r, lr_err *e);
void lr_irradiance_free(lr_renderer *r);
/* The VPL inputs of lib/vpl_irradiance.glsl (units 7..10). */
void lr_passes_bind_vpls(lr_renderer *r, const lr_program *p);
/* Receiver i's grid for compose_receiver.frag (unit 15), or u_cached = false. */
void lr_passes_bind_irradiance(lr_renderer *r, const lr_program *p, int receiver);
/* The blend of r->img with the lights' intensity x colour x flicker (render/passes/blend.h). */
int lr_pass_blend(lr_renderer *r, lr_err *e);

/* Resources of each pass (allocated for r->rs). */
int lr_gbuffer_alloc(lr_renderer *r, lr_err *e);
void lr_gbuffer_free(lr_renderer *r);
int lr_radiosity_alloc(lr_renderer *r, lr_err *e);
void lr_radiosity_free(lr_renderer *r);
int lr_vpl_alloc(lr_renderer *r, lr_err *e);
void lr_vpl_free(lr_renderer *r);
int lr_compose_alloc(lr_renderer *r, lr_err *e);
void lr_compose_free(lr_renderer *r);

#endif
