/* lamprig — scene internals shared by the files of render/scene/ (not a public header). */
#ifndef LR_SCENE_INTERNAL_H
#define LR_SCENE_INTERNAL_H

#include <limits.h>

#include "render/mesh/shapes.h"
#include "render/scene/scene.h"

#define LR_SCENE_PATH_MAX 1024

/* An object's material as the scene file (or the latest change) wrote it, so that a change of
 * one field can be re-resolved through lr_material_from_json with the file's semantics. */
typedef struct mat_spec {
    bool is_preset; /* "material": "NAME" */
    char preset[LR_MATERIAL_NAME_MAX];
    /* Inline object fields (has_*: present). */
    char name[LR_MATERIAL_NAME_MAX];
    char source[LR_MATERIAL_SOURCE_MAX];
    bool has_base, has_scale, has_sigma_a, has_sigma_s_prime, has_eta, has_g;
    char base[LR_MATERIAL_NAME_MAX];
    double scale[3];
    double sigma_a[3], sigma_s_prime[3], eta, g;
} mat_spec;

/* An object's mesh as written: generator descriptors hold 0 for "default" so that defaults
 * derived from other fields (pool_radius from radius) follow changes of those fields. */
typedef struct mesh_spec {
    enum lr_mesh_kind kind;
    lr_candle_desc candle;
    lr_shade_desc shade;
    lr_sphere_desc sphere;
    lr_box_desc box;
    char path[LR_SCENE_PATH_MAX]; /* file: as written */
    double file_scale;            /* file: default 1 */
} mesh_spec;

typedef struct xform_spec {
    lr_vec3 translate, rotate_deg, scale;
} xform_spec;

typedef struct obj_rec {
    lr_scene_object pub;
    mat_spec mat;
    mesh_spec mesh;
    xform_spec xf;
    lr_mesh *world; /* refined (the renderer's) */
    lr_mesh *built; /* as described; may be world */
    lr_bvh *bvh;
} obj_rec;

typedef struct recv_rec {
    lr_receiver pub;
    lr_mesh *mesh;
    lr_bvh *bvh;
} recv_rec;

struct lr_scene {
    char name[LR_SCENE_NAME_MAX];
    char path[LR_SCENE_PATH_MAX];
    char dir[LR_SCENE_PATH_MAX]; /* where relative mesh paths start */
    lr_warn_sink warn;
    obj_rec *obj;
    int nobj;
    lr_light *light;
    int nlight;
    recv_rec *recv;
    int nrecv;
    lr_camera camera;
    lr_render_settings render;
    /* Bit i: render field i of lr_scene_render_desc was given (in the file's render block or
     * by lr_scene_set), not defaulted (lr_scene_render_given: the planner turns on the light
     * transport a scene needs only where the scene did not say). */
    unsigned long long render_given;
    lr_quality quality;
    lr_scene_journal journal; /* lr_scene_set_journal; never copied by lr_scene_clone */
};

/* Marks the render field `name` as given; unknown names are ignored. */
void lr_scene_render_mark_given(lr_scene *s, const char *name);

/* ---- checks shared by the file and lr_scene_set (check.c) ---------------------------------
 * Each returns LR_OK, or LR_EINVAL with a message (no location) and *field set to the name of
 * the offending field inside the record ("intensity", "flicker.amplitude"). They may
 * normalise (directions to unit length). */
int lr_scene_check_light(lr_light *l, const char **field, lr_err *e);
int lr_scene_check_camera(lr_camera *c, const char **field, lr_err *e);
int lr_scene_check_receiver(lr_receiver *r, const char **field, lr_err *e);
int lr_scene_check_render(lr_render_settings *r, const char **field, lr_err *e);
int lr_scene_check_quality(const lr_quality *q, const char **field, lr_err *e);
int lr_scene_check_transform(const xform_spec *x, const char **field, lr_err *e);
/* Generator parameters (through the shapes' own checks) and the file mesh's scale. */
int lr_scene_check_mesh(const mesh_spec *m, const char **field, lr_err *e);

/* Defaults for a zero-initialised record (lights of the given type, camera, settings). */
void lr_scene_light_defaults(lr_light *l, enum lr_light_type type);
void lr_scene_camera_defaults(lr_camera *c);
void lr_scene_render_defaults(lr_render_settings *r);

/* ---- building (build.c) --------------------------------------------------------------------- */

/* No edge of the mesh the renderer draws is longer than this (mm). Translucent radiosity's
 * solved B and the receivers' light on objects (render/bounce/objlight.h) are values per
 * vertex, interpolated linearly over each triangle: a mockup mesh whose wall is one quad from
 * foot to rim (configs/meshes/votive.obj, 65 mm) showed its wall only as the mean of the foot
 * and the rim (translucent radiosity's outer wall 0.63-0.71 of the reference, evenly in the
 * three bands). Translucent radiosity's patch (12 mm), over which its B is averaged: the
 * votive read the same with 6 mm (0.146 / 0.346 objects / receivers against 0.150 / 0.346),
 * which would have tripled the lamp shade's triangles (10 mm edges, untouched at 12); 24 mm
 * left the multipole votive's inner wall at 0.83 of the reference (the receivers' light on
 * it, per vertex). The midpoint split keeps the surface and the interpolated normal field.
 * The radiosity maps draw the built mesh unless B is per vertex (render/passes/passes.h
 * lr_pass_objects.built: small triangles doubled llvmpipe's radiosity pass). */
#define LR_SCENE_MAX_EDGE_MM 12.0
#define LR_SCENE_REFINED_MAX_VERTICES ((size_t)1 << 22)

/* Builds the world meshes and BVH of an object from its mesh and transform specs (replacing
 * nothing: the caller swaps them in on success). `built` is the surface as the spec describes
 * it; `world` the renderer's copy, refined so that no edge is longer than
 * LR_SCENE_MAX_EDGE_MM (`built` itself where none is); the BVH is over `world`. Free both
 * with lr_scene_object_meshes_destroy. `where` names the object in messages. */
int lr_scene_build_object(const lr_scene *s, const char *where, const mesh_spec *ms,
                          const xform_spec *xf, lr_mesh **world, lr_mesh **built, lr_bvh **bvh,
                          double model[16], lr_err *e);
void lr_scene_object_meshes_destroy(lr_mesh *world, lr_mesh *built);
int lr_scene_build_receiver(const lr_scene *s, lr_receiver *r, lr_mesh **mesh, lr_bvh **bvh,
                            lr_err *e);
/* Fills pub's mesh-derived fields (mesh, built_mesh, bvh, bounds, area, closed). */
void lr_scene_object_attach(lr_scene_object *pub, const lr_mesh *world, const lr_mesh *built,
                            const lr_bvh *bvh);

/* Resolves a material spec by writing it as JSON and reading it back through
 * lr_material_from_json (the file's semantics, base and scale included); `where` names it. */
int lr_scene_resolve_material(const mat_spec *ms, const char *where, lr_material *out,
                              lr_err *e);

/* Resolves a path relative to the scene's directory (absolute paths pass through). */
int lr_scene_resolve_path(const lr_scene *s, const char *rel, char *out, size_t cap);

#endif
