/* lamprig — inspection of the renderer's intermediate results, for the GPU/CPU parity tests
 * (render/cpu/), the bench and debugging. Reads back from the GPU (slow; not for the frame
 * loop). All calls need the renderer's GL context current and a frame rendered since the
 * last change (lr_renderer_frame). Arrays are in GL order: row 0 is the bottom of the map. */
#ifndef LR_RENDERER_DEBUG_H
#define LR_RENDERER_DEBUG_H

#include <stdbool.h>

#include "render/base/err.h"
#include "render/base/vec3.h"
#include "render/passes/slice.h"
#include "render/renderer.h"

/* ---- scattered-radiosity maps (pass 2) ---------------------------------------------------- */

typedef struct lr_debug_map_info {
    int K;           /* maps */
    int size;        /* side, texels */
    int frames;      /* frames accumulated (F) */
    int N;           /* samples per texel, band and frame */
    lr_vec3 center;  /* bounding sphere the map cameras look at */
    double radius;
    double r_max;    /* radius truncation of the exponential sampling (20 radii) */
    unsigned seed;
} lr_debug_map_info;

void lr_renderer_debug_map_info(const lr_renderer *r, lr_debug_map_info *out);

/* Direction d_k = lr_halton_sphere(k + 1) of map k (the camera sits at centre + 2 R d_k). */
lr_vec3 lr_renderer_debug_map_dir(const lr_renderer *r, int k);
/* World -> texture matrix P_k of map k (column-major, render/base/mat4.h): x, y in [0, 1]
 * across the map, z its depth in [0, 1] (depth range [R, 3R] from the camera). Texel (i, j)
 * covers [i, i+1] / size x [j, j+1] / size. */
void lr_renderer_debug_map_matrix(const lr_renderer *r, int k, double out[16]);

/* Map k, size*size texels. Any output may be NULL. B: 3 floats per texel, scattered radiosity
 * for a unit light intensity (W/mm^2 per W/sr), the running mean over `frames` frames;
 * pos / nrm: 3 floats per texel, x_o and n_o (the normal the estimator used); object: the
 * object index, -1 where the map sees no surface (covered == false). */
int lr_renderer_debug_read_map(lr_renderer *r, int k, float *B, float *pos, float *nrm, int *object,
                               lr_err *e);
/* The same for light l's map k (each light has its own K maps of B for unit intensity; x_o,
 * n_o and coverage are shared). lr_renderer_debug_read_map reads light 0's. */
int lr_renderer_debug_read_light_map(lr_renderer *r, int l, int k, float *B, float *pos,
                                     float *nrm, int *object, lr_err *e);

/* The cavity gain per band composition applies to object `object`'s emission for light 0
 * (PIPELINE.md "Energy"; 1 for objects that do not enclose the light); the second form for
 * light l (each light has its own: the gain depends on where the light sits). */
void lr_renderer_debug_cavity_gain(const lr_renderer *r, int object, double out[3]);
void lr_renderer_debug_light_cavity_gain(const lr_renderer *r, int l, int object, double out[3]);

/* ---- virtual point lights (pass 4) -------------------------------------------------------- */

typedef struct lr_debug_vpl {
    bool valid;      /* a surface exists along u */
    lr_vec3 u;       /* fixed direction from the bounding-box centre, lr_halton_sphere(v + 1) */
    lr_vec3 pos, nrm;
    double area;     /* A_v, mm^2 */
    double B[3];     /* B(x_v) from Algorithm 1, unit intensity of light 0 */
    double weight;   /* Algorithm 1's visibility weight n (0: fallback map) */
    int object;
} lr_debug_vpl;

/* Number of VPLs (render.N_vpl; 0 with no_vpl). */
int lr_renderer_debug_vpl_count(const lr_renderer *r);
/* The VPL centre c (bounding-box centre of the objects). */
lr_vec3 lr_renderer_debug_vpl_center(const lr_renderer *r);
/* Fills out[0 .. count). */
int lr_renderer_debug_read_vpls(lr_renderer *r, lr_debug_vpl *out, lr_err *e);

/* ---- light G-buffer (pass 1) -------------------------------------------------------------- */

typedef struct lr_debug_gbuffer_info {
    bool cube;          /* cube map (6 faces) or one 2D map */
    bool orthographic;  /* 2D map of a directional light */
    int size;           /* side (each face) */
    double vp[6][16];   /* world -> clip of each face (cube) or of the map ([0]) */
    lr_vec3 light_pos, light_dir;
} lr_debug_gbuffer_info;

/* Of light 0's G-buffer; the second form of light l's (zeroed for a light that does not exist). */
void lr_renderer_debug_gbuffer_info(const lr_renderer *r, lr_debug_gbuffer_info *out);
void lr_renderer_debug_light_gbuffer_info(const lr_renderer *r, int l, lr_debug_gbuffer_info *out);
/* Light 0's face `face` (0..5 = +X..-Z; 0 for a 2D map): pos and nrm 3 floats per texel, object the
 * object index or -1 for an empty texel. Any output may be NULL. */
int lr_renderer_debug_read_gbuffer(lr_renderer *r, int face, float *pos, float *nrm, int *object,
                                   lr_err *e);

/* ---- composition (pass 3) ------------------------------------------------------------------ */

/* Object pixels of the last composed image that no radiosity map sees (Algorithm 1's n = 0:
 * they took the map facing them most, without visibility; PIPELINE.md pass 3). */
int lr_renderer_debug_uncovered(lr_renderer *r, int *count, lr_err *e);
/* Whether the last composition ran Algorithm 1 per object pixel (render.surface_cache off)
 * rather than reading the surface cache (render/passes/surface.h). */
bool lr_renderer_debug_compose_gathered(const lr_renderer *r);

/* The long passes' slices (render/passes/slice.h): how many have ended since the renderer was
 * made, and a hook called at each slice end before its poll (NULL: none), from which a test
 * requests its token to cut a frame at a chosen slice. */
long lr_renderer_debug_slices(const lr_renderer *r);
void lr_renderer_debug_on_slice(lr_renderer *r, lr_slice_fn fn, void *ctx);

/* The surface cache: entries (lattice points, render/mesh/lattice.h, both sides of open
 * objects), and object i's lattice point count and edge bound in mm (0 when the cache is not
 * built). */
typedef struct lr_debug_surface_info {
    int entries, n_objects;
    int nv[8]; /* LR_MAX_OBJECTS (render/passes/material_pack.h) */
    double h[8];
} lr_debug_surface_info;
void lr_renderer_debug_surface_info(const lr_renderer *r, lr_debug_surface_info *out);
/* Light l's surface cache as drawn by the surface pass: 4 floats per entry (B rgb in the
 * maps' scale, a map saw it), info.entries of them into out. */
int lr_renderer_debug_read_surface(lr_renderer *r, int l, float *out, lr_err *e);

/* ---- the bench's floor (issue 11) ---------------------------------------------------------- */

/* Times `reps` (1..64) runs of the cheapest fullscreen pass that reads one RGBA16F texture of
 * the output size and writes the tone-mapped output target (render/shaders/floor.frag; the
 * blend's own target, SRGB8_ALPHA8 where it is, so the store's sRGB encode is in both),
 * measured exactly as lr_renderer_frame measures a dimmer frame's blend pass, so that the two
 * compare like with like: the draw inside one section of the renderer's timer (reset, begin,
 * end, collect: *timer_ms, the median of that section, GPU timer queries or CPU+glFinish as
 * the renderer's timer is), and the whole from glFinish to glFinish (*wall_ms, the median wall
 * time a caller waits, timer overhead included as in a frame). The output target is
 * overwritten: render a frame before reading the image again. */
int lr_renderer_debug_floor_ms(lr_renderer *r, int reps, double *wall_ms, double *timer_ms,
                               lr_err *e);

/* The same floor one run at a time, for benches that pair it with frames (tools/bench
 * dimmer_bench.c): its program and source texture are made once, so no run pays a compile or
 * llvmpipe's first-draw shader variant. Each run gives the wall and timer times as above and
 * the process CPU time from glFinish to glFinish (CLOCK_PROCESS_CPUTIME_ID: every thread).
 * The floor must not outlive r. */
typedef struct lr_debug_floor lr_debug_floor;
int lr_debug_floor_create(lr_renderer *r, lr_debug_floor **out, lr_err *e);
int lr_debug_floor_run(lr_debug_floor *f, double *wall_ms, double *timer_ms, double *cpu_ms,
                       lr_err *e);
void lr_debug_floor_destroy(lr_debug_floor *f);

/* The receiver bounce's solver (render/bounce/rbounce.h) as the last frame left it: false when
 * the scene has none; *build_s is what its last update spent rebuilding (0: nothing changed
 * its key, F and the object rows kept). */
bool lr_renderer_debug_bounce_build(const lr_renderer *r, double *build_s);

#endif
