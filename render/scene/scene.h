/* lamprig — scenes: translucent objects, the lights inside or around them, the diffuse
 * receivers they light (table, wall), the camera, and the render settings; loaded from JSON,
 * changed at run time by name (`--set key=value`, event scripts, the control map).
 *
 * Units: millimetres, degrees where a name says _deg, radiometry linear. z is up.
 *
 * ---- Scene file (configs/scenes/NAME.json) -------------------------------------------------
 * {"name": string (default: the file name),
 *  "objects":   [ OBJECT, ... ]       one or more translucent objects: "name", "material"
 *                                     (a preset name or a material object), "mesh" (a "type"
 *                                     and its parameters), "transform", "model", "thickness_mm",
 *                                     "normalize"
 *  "lights":    [ LIGHT, ... ]        one to LR_SCENE_MAX_LIGHTS: point, spot, directional,
 *                                     quad, disk (area lights)
 *  "camera":    CAMERA
 *  "receivers": [ RECEIVER, ... ]     diffuse planes and boxes (optional)
 *  "render":    SETTINGS              (optional)
 *  "quality":   BUDGET                (optional)}
 * Every field of every record -- type, range, default, what a change invalidates -- is in the
 * field tables (render/scene/field_tables.c), which the loader, lr_scene_set/get and the
 * checks use; configs/scenes/README.md quotes the reference written from them
 * (lr_scene_fields_markdown). Every object rejects unknown and duplicate fields; absent
 * optional fields take their default. Errors read "FILE:LINE: field 'F': what".
 *
 * ---- Parameters -----------------------------------------------------------------------------
 * lr_scene_set() takes the same names: "lights[1].intensity", "light.intensity" (= lights[0]),
 * "objects[0].material", "objects[pillar].material.scale" (an element by index or by name),
 * "camera.position", "render.K", "objects[0].mesh.thickness", "receivers[wall].albedo".
 * Values: numbers as in JSON; vectors "x,y,z" (or "[x,y,z]"); names bare; booleans
 * true/false. Each change is validated like the file and either applies completely or
 * leaves the scene untouched.
 */
#ifndef LR_SCENE_H
#define LR_SCENE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "render/base/err.h"
#include "render/base/vec3.h"
#include "render/base/warn.h"
#include "render/material/material.h"
#include "render/mesh/bvh.h"
#include "render/mesh/mesh.h"
#include "render/models/model.h"
#include "render/optics/optics.h"
#include "render/photometry/profile.h"
#include "render/scene/dirty.h"

typedef struct lr_scene lr_scene;

#define LR_SCENE_NAME_MAX 64
/* Lights per scene: the GPU transport keeps a G-buffer and radiosity maps per light
 * (render/passes/PIPELINE.md), so their number is bounded; more is a load-time error. */
#define LR_SCENE_MAX_LIGHTS 4
/* Scattered-radiosity maps (render.K): the radiosity pass keeps a view and texture matrix per
 * map in fixed arrays, and the shaders unroll that many (render/passes/radiosity.h,
 * LR_MAX_K); more is a load-time error. */
#define LR_SCENE_MAX_K 32

/* ---- Objects ------------------------------------------------------------------------------ */

enum lr_mesh_kind { LR_MESH_CANDLE, LR_MESH_SHADE, LR_MESH_SPHERE, LR_MESH_BOX, LR_MESH_FILE };

typedef struct lr_scene_object {
    char name[LR_SCENE_NAME_MAX];
    enum lr_mesh_kind kind;
    lr_material material; /* effective (base and scale applied) */
    lr_coeffs coeffs;     /* lr_coeffs_derive(&material.medium) */
    const lr_mesh *mesh;  /* world space, refined: no edge longer than 12 mm (per-vertex
                           * values; render/scene/scene_internal.h); the passes, the CPU twin
                           * and the ray casts use it (the radiosity maps draw built_mesh
                           * where B is not per vertex: render/passes/passes.h) */
    const lr_mesh *built_mesh; /* the same surface as described (file or generator), world
                           * space, unrefined: what the physical reference traces, so that its
                           * cache key does not move with the refinement; may equal mesh */
    const lr_bvh *bvh;    /* over mesh */
    double model[16];     /* object to world (column-major) */
    lr_vec3 center;       /* world bounding sphere (lr_mesh_bounding_sphere): the K map */
    double radius;        /*   cameras sit on it */
    double area;          /* world surface area, mm^2 */
    bool closed;          /* watertight (a shade with rims is; one without is not) */
    double wall_mm;       /* closed: its thinnest wall (lr_mesh_wall_thickness); else 0 */
    enum lr_sss_model sss_model; /* "model": the S_d the radiosity estimator evaluates */
    double thickness_mm;  /* "thickness_mm": the wall the multipole models; 0: not given */
    double dgrid_h_mm;    /* "dgrid_h_mm": diffusion_grid spacing; 0: auto */
    char dgrid_volume[1024]; /* "dgrid_volume": volume file as written; "": homogeneous */
    bool sd_raw;          /* scene "normalize": false: [14]'s S_d as published, without
                           * coeffs.sd_norm (PIPELINE.md "Energy"); default: normalised */
} lr_scene_object;

/* The factor S_d is multiplied by for band c (0..2), so that the map holds B with exitance
 * t_hem B = the profile's (composition emits L_o = F_t(w_o) B / pi, whose hemispherical
 * integral is t_hem B): coeffs.sd_norm[c] for the directional dipole (it scales [14]'s
 * half-space total t_hem pi int S_d dA to the standard dipole's R_d total), 1 / t_hem for the
 * standard dipole and the multipole (their R_d, R and T are exitances: Jensen 2001's
 * F_t(w_o) / pi alone lets out only t_hem of them, 0.908 at eta 1.5), 1 for the raw models
 * as published (sd_raw) and for the models that write B themselves. The GLSL pass and the
 * CPU twin both use it. */
/* Why object o cannot render with model m as it stands ("needs thickness_mm": the multipole
 * models a wall of the object's thickness_mm), or NULL when it can. The planner and the
 * bench use it to leave such a model out for that object. */
const char *lr_scene_object_model_unmet(const lr_scene_object *o, enum lr_sss_model m);

static inline double lr_scene_object_sd_norm(const lr_scene_object *o, int c)
{
    return lr_sss_sd_norm(o->sss_model, &o->coeffs, o->sd_raw, c);
}

/* ---- Lights ------------------------------------------------------------------------------- */

/* QUAD and DISK are Lambertian area lights (LED panels and strips, seed 004): radiance L_e
 * over a rectangle or a disk, emitted on the normal's side or on both (two_sided). */
enum lr_light_type { LR_LIGHT_POINT, LR_LIGHT_SPOT, LR_LIGHT_DIRECTIONAL, LR_LIGHT_QUAD,
                     LR_LIGHT_DISK };

typedef struct lr_flicker {
    double amplitude;    /* relative intensity swing, 0..1; 0: steady */
    double frequency_hz; /* dominant frequency */
    double jitter_mm;    /* position sway amplitude; 0: the flame stays put */
    unsigned seed;       /* phases */
} lr_flicker;

/* Which of a light's strength fields the others are derived from (the one the file gave, or
 * the last one lr_scene_set changed): W/sr or W/(mm^2 sr) (`intensity` / `radiance`), candela
 * (`intensity_cd`) or lumens (`flux_lm`). */
enum lr_light_strength { LR_STRENGTH_RADIOMETRIC, LR_STRENGTH_CD, LR_STRENGTH_LM };

typedef struct lr_light {
    char name[LR_SCENE_NAME_MAX];
    enum lr_light_type type;
    lr_vec3 position;  /* point, spot; quad and disk: the centre; mm */
    lr_vec3 direction; /* spot, directional: unit, the way the light travels; disk: unit
                        * normal of the emitting side */
    lr_vec3 edge_u, edge_v; /* quad: half-edge vectors from the centre (mm); the quad is
                             * position + s edge_u + t edge_v, s, t in [-1, 1]; it emits on
                             * the side of edge_u x edge_v */
    double radius;     /* disk: mm */
    bool two_sided;    /* quad, disk: emits on both sides */
    double inner_deg, outer_deg; /* spot: half-angles of full and zero intensity */
    /* The scale the dimmer turns, kept apart from the light's shape (position, direction,
     * cone, flicker) so that a renderer can rescale its result linearly. Point and spot:
     * radiant intensity in W/sr (on axis for a spot); directional: the file's `radiance`,
     * W/mm^2 on a surface facing the light; quad, disk: the file's `radiance`, the emitted
     * radiance L_e in W/(mm^2 sr) (render/area/emitter.h). */
    double intensity;
    double color[3]; /* relative per band (not normalised): band b gets intensity * color[b] */
    /* The same strength in a lighting designer's units (render/photometry/photometry.h):
     * point and spot: luminous intensity (cd, on axis for a spot); point, spot, quad, disk:
     * luminous flux (lm). One of them or `intensity` is given (`from`); the record check
     * derives the others, so each reads the light's present value. */
    double intensity_cd, flux_lm;
    enum lr_light_strength from;
    /* > 0: `color` is the Planckian radiator's at this temperature (K), scaled so that
     * `intensity` is its visible W/sr (lr_cct_color); 0: `color` as given. */
    double color_temperature_k;
    lr_flicker flicker;
    /* A photometric file's intensity per direction (render/photometry/profile.h), for point,
     * spot, quad and disk lights: "profile" as written ("" none) and its table, loaded with
     * the scene. Its nadir (gamma 0) is `direction` (point, spot, disk) or the quad's normal;
     * its C0 plane the direction of profile_c0 (zero: a quad's edge_u, else +x). */
    char profile_path[1024];
    lr_vec3 profile_c0;
    lr_light_profile profile;
} lr_light;

/* intensity * color. */
void lr_light_rgb(const lr_light *l, double out[3]);
/* Lumens per unit of `intensity` (lm per W/sr; quad and disk: per W/(mm^2 sr)): K_m Y(color)
 * (683 lm/W, render/photometry) times the solid angle the shape spreads the intensity over:
 * 4 pi for a point, 2 pi ((1 - cos inner) + (cos inner - cos outer) / 2) for a spot (the
 * smoothstep's mean over its band of cosines is 1/2), pi A for a Lambertian area light (2 pi A
 * two-sided); 0 for a directional light (no flux). */
double lr_light_lm_per_unit(const lr_light *l);
/* Derives color from color_temperature_k (when > 0), then intensity from the field `from`
 * names, then the other two strength fields. Fails (LR_EINVAL, *field set) when candela or
 * lumens are asked of a colour without a luminous part. */
int lr_light_resolve_units(lr_light *l, const char **field, lr_err *e);
/* The light's angular shape in travel direction dir (unit): 1 for a point light; for a spot
 * 1 inside inner_deg, 0 outside outer_deg, smoothstep in the cosine between; for a
 * directional light 1; for an area light A cos(theta_e) (0 behind a one-sided one): the
 * intensity per unit radiance of the emitter seen as a point, which a renderer places at one
 * sample point of the emitter per accumulation frame (render/area/frames.h).
 * With a profile: a point light's shape is the profile's rel (intensity / its largest), a
 * spot's rel times its cone, an area light's A rel in place of A cos(theta_e) (gamma measured
 * from the emitting side's normal; behind a one-sided emitter 0, a two-sided one mirrored). */
double lr_light_shape(const lr_light *l, lr_vec3 dir);
/* The profile's frame in world space (lr_light_profile_frame): x = C0, y = C90, z = nadir. */
void lr_light_profile_axes(const lr_light *l, lr_vec3 *x, lr_vec3 *y, lr_vec3 *z);
/* What the direct light per unit intensity depends on (not intensity, colour or flicker,
 * which scale it): type, position, direction, edges, radius, sidedness, cone, and the
 * profile's table and frame. The solvers' cache keys (receiver bounce, openings). */
#define LR_LIGHT_KEY_N 21
void lr_light_geometry_key(const lr_light *l, double k[LR_LIGHT_KEY_N]);
/* Flicker at time t seconds: the factor on intensity (>= 0, mean 1) and the position offset
 * (mm). Deterministic in (seed, t): a sum of three sines at incommensurate multiples of
 * frequency_hz with seed-derived phases, so that replays and tests see the same flame. */
void lr_light_flicker_at(const lr_light *l, double t, double *scale, lr_vec3 *offset);
/* Whether the light's intensity changes with time (flicker amplitude > 0 and a non-zero
 * intensity): a renderer's new clock then wants a blend. */
bool lr_light_flickers(const lr_light *l);
/* Area lights: the unit normal of the emitting side and the area (mm^2; 0 for others). */
lr_vec3 lr_light_area_normal(const lr_light *l);
double lr_light_area(const lr_light *l);
/* Whether the light is an area light (quad or disk). */
static inline bool lr_light_is_area(const lr_light *l)
{
    return l->type == LR_LIGHT_QUAD || l->type == LR_LIGHT_DISK;
}

/* Whether a light is surrounded by an object: then the light G-buffer is a cube map and the
 * radiosity sampling uses the stereographic correction (seed 003 Sec. 3.3).
 *   SOLID: the light is inside the object's material (winding number >= 1/2: an LED cast in
 *          wax);
 *   HULL:  inside the object's convex hull but not its material: a flame in the melt pool
 *          below the candle's rim, a bulb inside an open shade.
 * Directional lights are never enclosed. */
enum lr_enclosure { LR_ENCLOSURE_NONE, LR_ENCLOSURE_HULL, LR_ENCLOSURE_SOLID };

/* ---- Camera ------------------------------------------------------------------------------- */

typedef struct lr_camera {
    bool orthographic;
    lr_vec3 position, target, up;
    double fov_deg;   /* perspective: vertical field of view */
    double height_mm; /* orthographic: height of the view */
    double near_mm, far_mm;
} lr_camera;

/* World to view (OpenGL conventions, render/base/mat4.h). A scene's camera always has one:
 * position != target and up not along the view, checked on load and on every change. */
void lr_camera_view(const lr_camera *c, double out[16]);
/* View to clip for a viewport of the given aspect (width / height). */
void lr_camera_projection(const lr_camera *c, double aspect, double out[16]);
/* The same as float for glUniformMatrix4fv. */
void lr_camera_view_f(const lr_camera *c, float out[16]);
void lr_camera_projection_f(const lr_camera *c, double aspect, float out[16]);

/* ---- Receivers ---------------------------------------------------------------------------- */

enum lr_receiver_type { LR_RECEIVER_PLANE, LR_RECEIVER_BOX };

typedef struct lr_receiver {
    char name[LR_SCENE_NAME_MAX];
    enum lr_receiver_type type;
    double albedo[3];    /* diffuse reflectance per band, [0, 1] */
    lr_vec3 center;      /* mm */
    lr_vec3 normal;      /* plane: unit front normal */
    lr_vec3 u_dir;       /* plane: unit direction of size[0] */
    double size[3];      /* plane: w, h (size[2] = 0); box: x, y, z */
    int subdivisions;    /* plane */
    const lr_mesh *mesh; /* world space, front faces toward the scene */
    const lr_bvh *bvh;
} lr_receiver;

/* ---- Settings ------------------------------------------------------------------------------ */

typedef struct lr_render_settings {
    int K;            /* scattered-radiosity maps */
    int N;            /* samples per texel, band and frame */
    int N_vpl;        /* virtual point lights */
    int map_size;     /* radiosity map side, texels */
    int gbuffer_size; /* light G-buffer side (each cube face when enclosed) */
    int vpl_map_size; /* cube map of the outer surface that places the VPLs */
    int frames;       /* progressive frames until converged */
    double exposure;  /* multiplies radiance before tone mapping */
    /* The same as a camera's EV100 (lr_ev_to_exposure); exposure_from_ev: the file or the
     * last change gave exposure_ev, and the check derives exposure from it (else the other
     * way round). */
    double exposure_ev;
    bool exposure_from_ev;
    /* Composition reads the objects' B from the view-independent surface cache
     * (render/passes/surface.h) instead of running Algorithm 1 per pixel (issue 11). */
    bool surface_cache;
    /* With surface_cache false: a camera move on converged maps composes from the surface
     * cache (drawn at the first such move after the maps change), and the first frame
     * without a camera change composes again with Algorithm 1 per pixel (issue 11: a
     * camera move costs a lookup, the still image stays the gather's). Default true. */
    bool surface_cache_moves;
    /* Light-propagation volume (render/lpv/, seed 004) for the area lights' indirect light on
     * the plane receivers: cells per axis, 0 off. */
    int lpv;
    /* Shadow each VPL's light on the receivers by the objects (beyond seed 003, whose VPLs
     * have no visibility term; lr_renderer_desc.vpl_visibility also turns it on). */
    bool vpl_visibility;
    /* Receiver inter-reflection for every model (render/bounce/, issue 12 part 4): the plane
     * receivers' radiosity solve, its bounce added to the receiver irradiance grid. */
    bool receiver_bounce;
    /* With receiver_bounce: the receivers' radiosity (direct + VPL + bounced) lights the
     * objects too (render/bounce/objlight.h; issue 12 part 3). Default true. */
    bool receiver_light_on_objects;
    /* The light the objects' inner faces send to the plane receivers through their openings
     * (render/openings/, issue 12 part 3), added to the receiver irradiance grid. */
    bool opening_light;
    /* The VPLs' light on the plane receivers from the view-independent irradiance grid (the
     * irradiance pass; default true), or, false, gathered per receiver pixel at composition:
     * cheaper for a small image and few VPLs (the rig's preview). The grid stays on while the
     * receiver bounce, the opening light or a patch-solve model needs it. */
    bool irradiance_grid;
} lr_render_settings;

typedef struct lr_quality {
    double max_error; /* relative RMS error budget; 0: none */
    double frame_ms;  /* time budget per frame; 0: none */
    double converge_ms; /* time budget from a change to the converged image; 0: none */
    double change_ms; /* longest wait after a material change (the planner); 0: none */
} lr_quality;

/* ---- Loading ------------------------------------------------------------------------------- */

/* Loads and validates a scene file, builds every mesh (world space) and BVH and resolves
 * every material. Warnings (mesh repairs) go to warn, which may be NULL; the sink is kept for
 * later changes and must stay valid for the scene's life. */
int lr_scene_load(const char *path, const lr_warn_sink *warn, lr_scene **out, lr_err *e);
/* The same from text; `name` is used in messages and relative mesh paths resolve against
 * its directory. */
int lr_scene_parse(const char *text, size_t len, const char *name, const lr_warn_sink *warn,
                   lr_scene **out, lr_err *e);
void lr_scene_destroy(lr_scene *s);
/* A deep copy (meshes, BVHs, materials, settings, what was given): the copy changes and is
 * destroyed independently of the original, so a worker thread can render it while the
 * caller changes the original (render/async/). Warnings of later changes to the copy go to
 * warn (may be NULL: discarded), not to the original's sink. */
int lr_scene_clone(const lr_scene *s, const lr_warn_sink *warn, lr_scene **out, lr_err *e);

const char *lr_scene_name(const lr_scene *s);
/* The sink given at load: for warnings about the scene's rendering too (a cache not stored). */
const lr_warn_sink *lr_scene_warn_sink(const lr_scene *s);
const char *lr_scene_path(const lr_scene *s);

/* Pointers into the scene stay valid until the next lr_scene_set() or destroy. */
int lr_scene_object_count(const lr_scene *s);
const lr_scene_object *lr_scene_object_at(const lr_scene *s, int i);
int lr_scene_light_count(const lr_scene *s);
const lr_light *lr_scene_light_at(const lr_scene *s, int i);
int lr_scene_receiver_count(const lr_scene *s);
const lr_receiver *lr_scene_receiver_at(const lr_scene *s, int i);
const lr_camera *lr_scene_camera(const lr_scene *s);
const lr_render_settings *lr_scene_render(const lr_scene *s);
const lr_quality *lr_scene_quality(const lr_scene *s);
/* Whether render field `name` ("receiver_bounce") was given, in the file's render block or by
 * lr_scene_set, rather than left at its default. */
bool lr_scene_render_given(const lr_scene *s, const char *name);
/* Index of the object, light or receiver with that name; -1 when none. */
int lr_scene_find_object(const lr_scene *s, const char *name);
int lr_scene_find_light(const lr_scene *s, const char *name);
int lr_scene_find_receiver(const lr_scene *s, const char *name);

/* A sphere around every object (not the receivers). */
void lr_scene_bounds(const lr_scene *s, lr_vec3 *center, double *radius);

/* Whether light `light` is surrounded by an object (see lr_enclosure); *object receives the
 * index of the (first) enclosing object, or -1. */
enum lr_enclosure lr_scene_light_enclosure(const lr_scene *s, int light, int *object);

/* Whether light `light` lights nothing the renderer draws (render/scene/dark.c): it is inside
 * a closed object's material (LR_ENCLOSURE_SOLID: the models have no term for a source in the
 * medium, and the object hides it from everything else) or has zero power (intensity x colour
 * 0 in every band). why (may be NULL) gets one phrase naming the light and the cause, e.g.
 * "lights[0] 'core' at (0, 0, 0) is inside the material of objects[0] 'ball' (marble)";
 * empty when the light may light something. */
bool lr_scene_light_dark(const lr_scene *s, int light, char *why, size_t cap);
/* Whether every light of the scene lights nothing, so that every image of it is black; why
 * gets their phrases joined by "; " (truncated to cap). */
bool lr_scene_dark(const lr_scene *s, char *why, size_t cap);

/* ---- Changes ------------------------------------------------------------------------------- */

/* Sets one parameter by its scene-file name (see the top of this file) from its text value,
 * validated as the file would be; ORs the lr_dirty flags it implies into *dirty (which may be
 * NULL). On error nothing changes and the message names the key. Setting a value equal to the
 * current one still reports its flags (callers may want to re-render). A new material preset
 * ("objects[0].material") replaces the whole material, scale included. */
int lr_scene_set(lr_scene *s, const char *key, const char *value, unsigned *dirty, lr_err *e);

/* Told of every change lr_scene_set makes, after it is made: the key and value as given and
 * the flags it implied. render/async/ replays them on its worker's copy of the scene, so the
 * copy goes through exactly the changes (and dirty flags) the caller's scene did. */
typedef struct lr_scene_journal {
    void (*fn)(void *user, const char *key, const char *value, unsigned dirty);
    void *user;
} lr_scene_journal;
/* Sets (or, with NULL, clears) the scene's journal. */
void lr_scene_set_journal(lr_scene *s, const lr_scene_journal *j);

/* "key=value" (a --set argument): split at the first '=' and lr_scene_set. */
int lr_scene_set_assignment(lr_scene *s, const char *assignment, unsigned *dirty, lr_err *e);

/* The current value of a parameter as lr_scene_set accepts it (for `lamprig scene get`, logs
 * and event-script round trips). */
int lr_scene_get(const lr_scene *s, const char *key, char *buf, size_t cap, lr_err *e);

/* ---- Reference ----------------------------------------------------------------------------- */

/* Writes the reference of every scene field (markdown, a table per record: key, kinds, value,
 * range, default, what a change invalidates, description) from the tables that load, set and
 * check use (render/scene/field_tables.c). configs/scenes/README.md quotes it between
 * "<!-- BEGIN scene-fields -->" and "<!-- END scene-fields -->" (tests/base/test_scene.c compares). */
void lr_scene_fields_markdown(FILE *f);

#endif
