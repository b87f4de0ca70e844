/* lamprig — translucent radiosity for the renderer and its CPU twin: one solver per scene,
 * rebuilt only when geometry, materials or receivers change (its F and S are the costly
 * part) and re-solved per light (warm-started) when the maps restart, turned into what the
 * passes consume (render/passes/PIPELINE.md, "Translucent radiosity"):
 *
 *   per vertex of every object whose model is translucent_radiosity, per light: the map value
 *     B (lr_tr_map_radiosity) interpolated from the object's patches (Gaussian weights over
 *     patches within two patch sizes whose normal agrees with the vertex's), which the GPU's
 *     radiosity pass and the CPU twin's maps interpolate over each triangle (barycentric);
 *   per plane receiver and light, on the LR_RECV_GRID grid of the receiver irradiance cache:
 *     the irradiance the VPLs do not carry, bilinear over the receiver's patch grid: light from
 *     the other receivers (receiver inter-reflection, all orders) and from the inner faces of
 *     those objects (a shade's inside through its openings; a face is inner when its normal
 *     points toward the object's centre). The VPLs keep carrying the outer faces' light, now
 *     with the solved B.
 * Everything is per unit intensity, so a dimmer change stays blend-only. F and S are cached on
 * disk under lr_tr_cache_default_dir ($XDG_CACHE_HOME/lamprig), so a second start with the
 * same geometry and materials skips their build (render/transrad/cache.c). */
#ifndef LR_TR_SCENE_H
#define LR_TR_SCENE_H

#include <stdbool.h>

#include "render/base/err.h"
#include "render/scene/scene.h"
#include "render/transrad/transrad.h"

typedef struct lr_tr_scene lr_tr_scene;

/* Appends to k (at *n, advanced) the LR_TR_KEY_MESH doubles that tell whether a solver built
 * on mesh m (BVH b) still matches: its and the BVH's addresses (a new mesh means a rebuild,
 * even with the same shape; user-space addresses fit a double's 53 bits), counts, bounds,
 * first vertex and area. For in-memory rebuild checks (here and render/bounce). */
#define LR_TR_KEY_MESH 14
/* Values X (3 per patch, row v of nu patches at X + 3 nu v) on a plane receiver's nu x nv
 * patch grid, bilinear between the patch centres (clamped at the edges) at the LR_RECV_GRID^2
 * texel centres of its receiver grid, into out (3 floats per texel, s + LR_RECV_GRID t). With
 * open (a fraction per patch, lr_tr_open_fraction) the bilinear weights are scaled by it and
 * renormalised (0 where every weight is 0); NULL: plain bilinear. */
void lr_tr_plane_to_grid(const double *X, const double *open, int nu, int nv, float *out);
void lr_tr_key_mesh(double *k, int *n, const lr_mesh *m, const lr_bvh *b);

/* Whether any object of s uses the model. */
bool lr_tr_scene_needed(const lr_scene *s);
/* Creates *ts on first use (NULL when no object needs it: *ts stays NULL), rebuilds the
 * solver when the scene's geometry, materials or receivers differ from the last call's, and
 * solves every light. `cancel` (NULL: never; render/base/cancel.h) is polled by the build and
 * the solves: LR_ECANCELED, and the next update rebuilds or re-solves what was cut short (a
 * vertex B may be the last state's until then). */
int lr_tr_scene_update(lr_tr_scene **ts, const lr_scene *s, const lr_cancel *cancel, lr_err *e);
void lr_tr_scene_destroy(lr_tr_scene *ts);

/* Per-vertex B (vertex_count x 3, the object's mesh's vertex order) of object o and light l;
 * NULL when o does not use the model (or ts is NULL). */
const float *lr_tr_scene_vertex_B(const lr_tr_scene *ts, int o, int l);
/* Extra irradiance on plane receiver r for light l at the LR_RECV_GRID^2 texel centres
 * (s + R t, 3 per texel); NULL when none. */
const float *lr_tr_scene_recv_E(const lr_tr_scene *ts, int r, int l);
/* B at point x of object o's triangle tri with barycentric weights w (the CPU twin's maps). */
void lr_tr_scene_B_at(const lr_tr_scene *ts, int o, int l, size_t tri, const double w[3],
                      double out[3]);
const lr_tr *lr_tr_scene_solver(const lr_tr_scene *ts);
/* Seconds the last update spent: building (0 when reused) and solving. */
void lr_tr_scene_times(const lr_tr_scene *ts, double *build_s, double *solve_s);

#endif
