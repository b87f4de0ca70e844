/* lamprig — what the render passes share: the limits of the shaders' arrays, the meshes and
 * per-object material uniforms on the GPU, the programs, and the read-only frame inputs
 * (lr_pass_ctx) every pass receives. Each pass owns its own state, declared in its header
 * (gbuffer.h, radiosity.h, vpl.h, irradiance.h, compose.h, blend.h), and takes the other
 * passes' results it reads as const arguments; the renderer (render/renderer.c) holds them
 * and runs them from its pass table. Nothing outside render/ includes this. The estimators
 * are those of render/passes/PIPELINE.md. */
#ifndef LR_PASSES_H
#define LR_PASSES_H

#include <GLES3/gl31.h>
#include <stdbool.h>

#include "render/base/cancel.h"
#include "render/base/err.h"
#include "render/base/vec3.h"
#include "render/gl/gl.h"
#include "render/gl/shader.h"
#include "render/gl/tex.h"
#include "render/image/image.h"
#include "render/passes/defines.h"
#include "render/passes/material_pack.h"
#include "render/passes/slice.h"
#include "render/scene/scene.h"

/* The scene loader refuses more (render.K). */
#define LR_MAX_K LR_SCENE_MAX_K
#define LR_MAX_RECEIVERS 16
#define LR_MAX_VPL 4096
/* Lights with their own G-buffer and radiosity maps (render/shaders/lib/lights.glsl unrolls
 * its sampler arrays for exactly this many); the scene loader refuses more. */
#define LR_MAX_LIGHTS LR_SCENE_MAX_LIGHTS
/* Frames accumulated at most in RGBA16F maps. Drivers may round the blended result toward
 * zero when storing half floats (llvmpipe does): the running mean then loses ~2^-13 of
 * itself per frame, 1.1% after 64 frames, 16% after 1024 (measured, tests/render/test_render_hard.c).
 * 32 frames keep that below 0.6%. */
#define LR_HALF_MAX_FRAMES 32

/* Tone curve of the output (lr_tonemap_op, render/image/image.h): the GPU pass and the PNG
 * writer of `lamprig render` use the same. */
#define LR_RENDER_TONEMAP LR_TONEMAP_ACES

typedef struct lr_gpu_mesh {
    GLuint vao, vbo[2], ebo;
    GLsizei count;
} lr_gpu_mesh;

/* The scene's meshes on the GPU and the per-object uniforms of material.glsl and
 * vpl_irradiance.glsl (common.c). Re-uploaded when geometry, receivers or settings change. */
typedef struct lr_pass_objects {
    int n_objects, n_receivers;
    lr_gpu_mesh obj[LR_MAX_OBJECTS];
    /* The object's surface as built (lr_scene_object.built_mesh), where the scene refined it
     * (vao 0 where not): the radiosity pass draws this one unless the object's B comes per
     * vertex (translucent radiosity), as the refined copy's small triangles cost llvmpipe
     * about twice the fragment work for the same texels (the votive, 16x the triangles). */
    lr_gpu_mesh built[LR_MAX_OBJECTS];
    lr_gpu_mesh recv[LR_MAX_RECEIVERS];
    bool two_sided[LR_MAX_OBJECTS];
    float coef[5 * 4 * LR_MAX_OBJECTS];
    float sss[3 * 4 * LR_MAX_OBJECTS]; /* lr_passes_pack_sss per object */
    /* Per object: the S_d energy normalisation (lr_scene_object_sd_norm: coeffs.sd_norm, or 1
     * for "normalize": false and for the standard dipole), radiosity.frag's u_sd_norm
     * (PIPELINE.md "Energy"). */
    float sd_norm[3 * LR_MAX_OBJECTS];
    /* Per light and object, [3 (l LR_MAX_OBJECTS + i) + c]: the cavity gain of object i for
     * light l (render/core/cavity.h, measured on the CPU when the maps restart; 1 for lights
     * beyond the scene's). Composition multiplies light l's B of object i by it: folded into
     * the gather's weights per object (compose_object) and compose_receiver's u_cavity_gain
     * for the VPLs. */
    float cavity_gain[3 * LR_MAX_LIGHTS * LR_MAX_OBJECTS];
} lr_pass_objects;

/* The programs (made once per renderer; several passes draw with the same). A pass sets only
 * the uniforms its program declares: another name is an error at the end of the pass
 * (lr_program_check). */
typedef struct lr_pass_programs {
    lr_program *surface, *depth, *radiosity, *vpl, *obj, *irr;
    /* compose_receiver.frag, [n - 1] for n lights (LR_RECV_LIGHTS) */
    lr_program *recv[LR_MAX_LIGHTS];
    lr_program *area; /* area lights' direct grid (area_direct.c) */
    lr_program *cache;      /* surface_cache.frag: Algorithm 1 at the cache's entries */
    /* compose_cached.{vert,frag}: objects from the cache, [n - 1] for n lights */
    lr_program *obj_cached[LR_MAX_LIGHTS];
} lr_pass_programs;

/* The read-only inputs of a pass: the context, the scene, the settings the resources were
 * made for, and the objects. */
typedef struct lr_pass_ctx {
    lr_gl *gl;
    const lr_gl_caps *caps;
    const lr_scene *scene;
    const lr_render_settings *rs;
    const lr_pass_objects *objs;
    const lr_pass_programs *prog;
    const char *shader_dir;
    int width, height;     /* output */
    int n_lights;          /* the scene's lights the resources were made for */
    lr_tex_format map_format; /* RGBA32F, or RGBA16F when float targets/blending are missing */
    unsigned seed;
    bool no_vpl, vpl_visibility;
    /* Per light and band: intensity x colour x flicker at the renderer's clock (the blend's
     * weights, lights.glsl's u_lights_I); 0 beyond n_lights. */
    double I[LR_MAX_LIGHTS][3];
    /* The renderer's (lr_renderer_set_cancel), handed to the CPU solves a pass runs (the
     * diffusion grid, translucent radiosity, the receiver bounce); NULL: never cancelled. */
    const lr_cancel *cancel;
    /* The renderer's slice ends (render/passes/slice.h): the long GPU passes end each piece of
     * their work with lr_slice_end, which waits and polls `cancel` when it is set. */
    lr_slicer *slicer;
} lr_pass_ctx;

/* common.c */
int lr_pass_objects_upload(lr_pass_objects *o, const lr_scene *s, lr_err *e);
void lr_pass_objects_free(lr_pass_objects *o);
/* Coefficient blocks (u_coef, u_sss, u_sd_norm) of every object of s. */
void lr_pass_objects_update_coeffs(lr_pass_objects *o, const lr_scene *s);
/* Measures o->cavity_gain for every light of s (PIPELINE.md "Energy"). */
int lr_pass_objects_update_cavity(lr_pass_objects *o, const lr_scene *s, lr_err *e);
/* Sets u_coef and u_sss (programs that include lib/material.glsl). */
void lr_passes_set_coeffs(const lr_pass_objects *o, lr_program *p);
/* glUniform3fv of `count` vec3 to uniform array `name`. */
void lr_passes_uniform_v3_array(lr_program *p, const char *name, const float *v, int count);
void lr_passes_draw(const lr_gpu_mesh *m);
/* A mesh from arrays (3 floats per vertex for pos and nrm, 3 indices per triangle); `name`
 * for messages. lr_passes_release_mesh frees it (idempotent). */
int lr_passes_upload_arrays(lr_gpu_mesh *g, const float *pos, const float *nrm, size_t nv,
                            const uint32_t *idx, size_t nt, const char *name, lr_err *e);
void lr_passes_release_mesh(lr_gpu_mesh *g);
void lr_passes_uniform_mat4(lr_program *p, const char *name, const double m[16]);
void lr_passes_uniform_v3(lr_program *p, const char *name, lr_vec3 v);
void lr_passes_uniform_i(lr_program *p, const char *name, int v);
void lr_passes_uniform_f(lr_program *p, const char *name, float v);
void lr_passes_bind_tex(lr_program *p, const char *name, int unit, const lr_tex *t);

#endif
