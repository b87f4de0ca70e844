/* lamprig — the physical reference: a volumetric Monte Carlo path tracer on the CPU.
 *
 * This is the ground truth every rendering mode's error is measured against (docs/ARCHITECTURE.md,
 * "CPU twin and reference"; issue 6). It solves the radiative transfer equation by random walks, with
 * no diffusion or dipole approximation:
 *
 *   media      homogeneous, sigma_a and sigma_s per colour band (mm^-1), Henyey-Greenstein
 *              phase function (sampled exactly), absolute refractive index n; a closed shape
 *              separates an inside medium from an outside one (nesting is allowed);
 *   boundaries smooth dielectric: exact unpolarised Fresnel reflection / refraction with total
 *              internal reflection (render/optics), radiance scaled by (n_from / n_to)^2 on
 *              refraction; a boundary between equal indices is index-matched (null): no
 *              reflection, no bending, only the change of medium;
 *   receivers  opaque two-sided Lambertian surfaces (table, wall) with an RGB albedo;
 *   lights     point, spot (smoothstep cone), and one-sided Lambertian quad and disk area
 *              lights;
 *   camera     pinhole, box-filtered pixels.
 *
 * Estimators (render/reference/README.md; each light path is counted by exactly one):
 *   - camera paths (lr_ref_radiance, lr_ref_render): unidirectional random walk from the
 *     camera with next-event estimation (NEE) at every non-specular vertex: diffuse receivers
 *     and scattering events inside media. NEE toward a light behind smooth refractive
 *     boundaries (a flame enclosed by wax, a bulb inside a shade) solves for the refracted
 *     connection path (planar steps, then Newton on the emission direction) and weights it
 *     with the exact ray-tube (generalised geometry) Jacobian: a point light enclosed by a
 *     dielectric is otherwise unreachable by any unidirectional estimator. Hits on area
 *     lights count only for paths NEE cannot produce. A point light inside a scattering
 *     medium adds equiangular distance samples (MIS with free flights).
 *   - light tracing (renders): photons from point and spot lights whose first specular event
 *     is a Fresnel reflection, connected to the pinhole at each non-specular vertex.
 *   - photons (lr_ref_photon_trace): the same transport functions run forward from a source;
 *     "photon in, count what comes out" estimators validate them against published slab
 *     solutions and closed-form sphere results (lr_ref_slab_rt, lr_ref_sphere_escape).
 *
 * Determinism: every path's random numbers come from a PCG32 stream keyed by (seed, pixel,
 * sample) or (seed, photon batch), and sums run in a fixed order, so results are identical
 * for any thread count and scheduling.
 *
 * Units: millimetres, W, sr. Colour: three bands carried independently; bands whose media
 * coefficients coincide in every medium share one path (grey media cost one path, not three).
 */
#ifndef LR_REFERENCE_H
#define LR_REFERENCE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "render/base/err.h"
#include "render/base/vec3.h"
#include "render/base/warn.h"
#include "render/photometry/profile.h"
#include "render/image/image.h"
#include "render/reference/rng.h"

/* Version of the transport code; part of every cache key. Bump it whenever a change alters
 * what a given scene renders to (a bug fix, a new estimator), so stale references are not
 * reused. */
#define LR_REF_VERSION "lamprig-reference 2"

/* Most refractive interfaces a next-event connection may pass through (e.g. 2 for the outer
 * and inner surface of a lamp shade between a receiver and the bulb). Longer chains are left
 * to the random walk. */
#define LR_REF_MAX_CHAIN 4

/* ---- hashing (cache keys) --------------------------------------------------------------- */

/* 64-bit FNV-1a over a canonical byte stream (Fowler, Noll, Vo; the 64-bit offset basis and
 * prime of the reference description). Doubles are hashed by their bit patterns, with -0.0
 * folded into +0.0 so equal values hash equally. */
typedef struct lr_ref_hash {
    uint64_t h;
} lr_ref_hash;

void lr_ref_hash_init(lr_ref_hash *h);
void lr_ref_hash_bytes(lr_ref_hash *h, const void *data, size_t n);
void lr_ref_hash_str(lr_ref_hash *h, const char *s); /* includes the terminating NUL */
void lr_ref_hash_u64(lr_ref_hash *h, uint64_t v);
void lr_ref_hash_double(lr_ref_hash *h, double v);
void lr_ref_hash_vec3(lr_ref_hash *h, lr_vec3 v);
/* The hash of n bytes alone (a file payload's check). */
uint64_t lr_ref_hash_of(const void *data, size_t n);

/* ---- shapes: the geometry interface ----------------------------------------------------- */

/* A ray-surface hit. */
typedef struct lr_ref_hit {
    double t;  /* ray parameter: hit point = origin + t * direction */
    lr_vec3 n; /* unit geometric normal pointing out of the shape (the "front" side) */
} lr_ref_hit;

/* What a shape must provide. Analytic shapes are below; meshes with a BVH plug in through
 * lr_ref_shape_create with their own ops. */
typedef struct lr_ref_shape_ops {
    const char *name;
    /* Nearest hit with tmin < t < tmax along origin + t * dir (dir is unit); true when there
     * is one. Must be safe to call from several threads at once. */
    bool (*intersect)(const void *self, lr_vec3 origin, lr_vec3 dir, double tmin, double tmax,
                      lr_ref_hit *hit);
    /* Feeds every parameter that changes the shape into h (cache keys). */
    void (*hash)(const void *self, lr_ref_hash *h);
    /* Frees self. */
    void (*destroy)(void *self);
    /* True when the shape encloses a volume (it may then bound a medium). */
    bool closed;
} lr_ref_shape_ops;

typedef struct lr_ref_shape lr_ref_shape;

/* Wraps caller geometry; the shape owns self from here on (ops->destroy frees it, also when
 * this call fails). */
int lr_ref_shape_create(const lr_ref_shape_ops *ops, void *self, lr_ref_shape **out, lr_err *e);
void lr_ref_shape_destroy(lr_ref_shape *s);
bool lr_ref_shape_intersect(const lr_ref_shape *s, lr_vec3 origin, lr_vec3 dir, double tmin,
                            double tmax, lr_ref_hit *hit);

/* Sphere; the normal points outwards. */
int lr_ref_sphere_create(lr_vec3 center, double radius, lr_ref_shape **out, lr_err *e);
/* The slab top - thickness < z < top, infinite in x and y; thickness = INFINITY gives the
 * half-space z < top (a semi-infinite medium). Normals point out of the slab (+z on top). */
int lr_ref_slab_create(double top, double thickness, lr_ref_shape **out, lr_err *e);
/* Parallelogram corner + u * edge1 + v * edge2, u, v in [0, 1]; normal edge1 x edge2. */
int lr_ref_quad_create(lr_vec3 corner, lr_vec3 edge1, lr_vec3 edge2, lr_ref_shape **out,
                       lr_err *e);
/* Disk of the given radius around center; normal is its front side. */
int lr_ref_disk_create(lr_vec3 center, lr_vec3 normal, double radius, lr_ref_shape **out,
                       lr_err *e);

/* A triangle mesh of render/mesh (ray casts through its BVH, flat triangle normals: the
 * faceted surface itself). It may bound a medium when it is watertight and consistently
 * oriented (lr_mesh_analyze). take: the shape owns and frees m; otherwise m must outlive it. */
typedef struct lr_mesh lr_mesh;
int lr_ref_mesh_create(lr_mesh *m, bool take, lr_ref_shape **out, lr_err *e);

/* ---- scene ------------------------------------------------------------------------------ */

/* A homogeneous medium. Zero-initialised: a vacuum of index 1. */
typedef struct lr_ref_medium_desc {
    double sigma_a[3]; /* absorption, mm^-1, per band */
    double sigma_s[3]; /* scattering (not reduced), mm^-1, per band */
    double g;          /* Henyey-Greenstein mean cosine, -1 < g < 1 */
    double eta;        /* absolute refractive index; 0 means 1 */
    const char *name;  /* for messages; may be NULL */
} lr_ref_medium_desc;

/* From the render model's medium (render/optics: reduced scattering sigma_s' and eta relative
 * to the outside): sigma_s = sigma_s' / (1 - g), and eta taken as absolute, i.e. for a medium
 * whose outside is air (index 1). */
typedef struct lr_medium lr_medium;
void lr_ref_medium_from_optics(const lr_medium *m, lr_ref_medium_desc *out);

typedef enum lr_ref_object_kind {
    LR_REF_BOUNDARY = 0, /* closed shape separating `inside` from `outside` medium */
    LR_REF_RECEIVER,     /* opaque two-sided Lambertian surface */
} lr_ref_object_kind;

typedef struct lr_ref_object_desc {
    lr_ref_object_kind kind;
    lr_ref_shape *shape; /* ownership passes to the scene, also when adding fails */
    int inside;          /* boundary: medium id behind the normal (from add_medium) */
    int outside;         /* boundary: medium id in front; 0 (the ambient medium) by default */
    double albedo[3];    /* receiver: diffuse reflectance per band, in [0, 1] */
    const char *name;    /* for messages and stats; may be NULL */
} lr_ref_object_desc;

typedef enum lr_ref_light_kind {
    LR_REF_LIGHT_POINT = 0,
    LR_REF_LIGHT_SPOT,
    LR_REF_LIGHT_QUAD,
    LR_REF_LIGHT_DISK,
} lr_ref_light_kind;

typedef struct lr_ref_light_desc {
    lr_ref_light_kind kind;
    lr_vec3 position;     /* point, spot: position; quad: corner; disk: centre */
    lr_vec3 direction;    /* spot: axis; disk: normal of the emitting side */
    lr_vec3 edge1, edge2; /* quad: edges; it emits on the side of edge1 x edge2 */
    double radius;        /* disk */
    /* Spot cone half-angles in degrees: full intensity inside `inner`, smoothstep in cos theta
     * down to zero at `outer`. outer 0 means 30; inner 0 means a hard edge at outer. */
    double inner_deg, outer_deg;
    /* point, spot: radiant intensity on the axis, W/sr; quad, disk: radiance, W/(mm^2 sr),
     * emitted on the front side only (Lambertian). */
    double emission[3];
    /* A photometric profile (render/photometry/profile.h; NULL none), copied: point and spot
     * intensity emission rel(w) (a spot's times its cone), an area element's emission rel(w)
     * dA in place of cos theta dA (gamma from the emitting side's normal, 0 behind it). Its
     * frame: prof_x = C0, prof_y = C90, prof_z = nadir (a spot's axis, an area's normal). */
    const lr_light_profile *profile;
    lr_vec3 prof_x, prof_y, prof_z;
} lr_ref_light_desc;

typedef struct lr_ref_scene_desc {
    double ambient_eta; /* index of the ambient medium (id 0), which does not scatter; 0 means 1 */
} lr_ref_scene_desc;

typedef struct lr_ref_scene lr_ref_scene;

int lr_ref_scene_create(const lr_ref_scene_desc *desc, lr_ref_scene **out, lr_err *e);
void lr_ref_scene_destroy(lr_ref_scene *s);
/* Adds a medium and returns its id (1, 2, ...; 0 is the ambient medium). */
int lr_ref_scene_add_medium(lr_ref_scene *s, const lr_ref_medium_desc *m, int *id, lr_err *e);
int lr_ref_scene_add_object(lr_ref_scene *s, const lr_ref_object_desc *o, lr_err *e);
int lr_ref_scene_add_light(lr_ref_scene *s, const lr_ref_light_desc *l, lr_err *e);
/* Validates and precomputes (the medium each light sits in, light selection probabilities,
 * colour band groups). Required before rendering; the scene is read-only afterwards and may
 * be shared by threads. */
int lr_ref_scene_finish(lr_ref_scene *s, lr_err *e);
/* Hash of everything added so far (media, objects with their shapes, lights). */
uint64_t lr_ref_scene_hash(const lr_ref_scene *s);
/* The medium containing point p (by the side of the first boundary a ray from p meets). */
int lr_ref_scene_medium_at(const lr_ref_scene *s, lr_vec3 p);

/* ---- counters --------------------------------------------------------------------------- */

/* Per-run counters; the failure counts say how far a result may be from exact. */
typedef struct lr_ref_stats {
    uint64_t paths;          /* camera paths or validation photons started */
    uint64_t photons;        /* light-tracing photons started (renders) */
    uint64_t events;         /* scattering, reflection, refraction and receiver events */
    uint64_t nee;            /* next-event connections attempted */
    uint64_t nee_refracted;  /* ... of which through at least one refractive interface */
    uint64_t nee_unsolved;   /* refracted connections Newton did not converge for (lost) */
    uint64_t truncated;      /* paths stopped by the event cap (lost energy) */
    uint64_t medium_mismatch;/* crossings where the tracked medium disagreed with geometry */
    uint64_t nonfinite;      /* pixel samples dropped for NaN/Inf (a bug if ever non-zero) */
} lr_ref_stats;

void lr_ref_stats_add(lr_ref_stats *into, const lr_ref_stats *from);

/* ---- camera-path estimator -------------------------------------------------------------- */

/* Radiance arriving at `origin` along -dir (i.e. seen looking along dir), one sample per band
 * group, added into L (W/(mm^2 sr), per band). `medium` is the medium at origin (see
 * lr_ref_scene_medium_at). The rng is advanced; stats may be NULL. */
void lr_ref_radiance(const lr_ref_scene *s, lr_vec3 origin, lr_vec3 dir, int medium,
                     lr_ref_rng *rng, lr_ref_stats *stats, double L[3]);

/* ---- photon estimator ------------------------------------------------------------------- */

typedef struct lr_ref_photon_exit {
    bool escaped;       /* left the scene; otherwise absorbed, killed by roulette or capped */
    bool hit_light;     /* absorbed by an area light's surface (weight: what arrived there) */
    lr_vec3 position;   /* last medium boundary it met (where it left an object); the
                         * origin when boundaries == 0 */
    int boundaries;     /* reflections and refractions at medium boundaries */
    lr_vec3 direction;  /* direction it escaped in */
    double weight;      /* carried flux fraction, 1 at launch */
    int scatterings;    /* medium scattering events (0: reflected or transmitted specularly) */
    int receiver_hits;  /* diffuse bounces on receivers */
} lr_ref_photon_exit;

/* Traces one photon of the given colour band (0..2) forward from origin along dir, starting
 * in `medium`, with the same flight, boundary and scattering code as the camera paths (flux,
 * not radiance: no (n1/n2)^2 scaling). Absorption is by weight (w *= albedo per scattering)
 * with Russian roulette below 0.1. */
void lr_ref_photon_trace(const lr_ref_scene *s, lr_vec3 origin, lr_vec3 dir, int medium,
                         int band, lr_ref_rng *rng, lr_ref_stats *stats,
                         lr_ref_photon_exit *out);

/* Samples an emitted photon from light `light` (in add order): origin, unit direction and the
 * power it carries if the light emitted one photon per call (W; the mean over calls is the
 * light's power in that band). Returns the medium the light sits in. */
int lr_ref_light_emit(const lr_ref_scene *s, int light, int band, lr_ref_rng *rng,
                      lr_vec3 *origin, lr_vec3 *dir, double *power);
/* Total emitted power of a light in a band, W. */
double lr_ref_light_power(const lr_ref_scene *s, int light, int band);

/* ---- validation problems: "photon in, count what comes out" ----------------------------- */

/* A collimated pencil beam at normal incidence onto a slab (or half-space) of the given
 * medium in vacuum, as in the published benchmarks. */
typedef struct lr_ref_slab_problem {
    double albedo;          /* sigma_s / sigma_t */
    double g;               /* Henyey-Greenstein */
    double eta;             /* slab index (outside 1) */
    double optical_depth;   /* sigma_t * thickness; INFINITY for a half-space */
    uint64_t photons;
    uint64_t seed;
    int threads;            /* 0: all online CPUs */
} lr_ref_slab_problem;

/* Each quantity is a fraction of the incident power with its Monte Carlo standard error
 * (sample standard deviation of the per-photon tallies / sqrt(photons)). */
typedef struct lr_ref_estimate {
    double value, se; /* estimate and its Monte Carlo standard error */
} lr_ref_estimate;

typedef struct lr_ref_slab_result {
    lr_ref_estimate r_total;     /* everything leaving the lit side, specular part included */
    lr_ref_estimate r_specular;  /* reflected at the first surface without scattering */
    lr_ref_estimate r_diffuse;   /* r_total - r_specular (at least one scattering) */
    lr_ref_estimate t_total;     /* everything leaving the far side, unscattered included */
    lr_ref_estimate t_unscattered;
    lr_ref_estimate absorbed;
    lr_ref_stats stats;
} lr_ref_slab_result;

int lr_ref_slab_rt(const lr_ref_slab_problem *p, lr_ref_slab_result *out, lr_err *e);

/* A sphere of the given medium (radius in mm, vacuum outside) around an isotropic point light
 * at `offset` from its centre: the fraction of the light's power that escapes. With cavity > 0
 * the sphere is a shell around a concentric vacuum cavity of that radius (a bulb in a
 * shade), and the light must sit in the cavity. */
typedef struct lr_ref_sphere_problem {
    lr_ref_medium_desc medium;
    double radius;
    double cavity;
    lr_vec3 offset;
    uint64_t photons;
    uint64_t seed;
    int threads;
} lr_ref_sphere_problem;

/* What leaves a scene to infinity, as fractions of a light's power (band 0). */
typedef struct lr_ref_escape_result {
    lr_ref_estimate escaped;           /* fraction of the light's power leaving the scene */
    lr_ref_estimate escaped_scattered; /* ... of which scattered at least once */
    /* ... of which reached the first scattering along a path camera-path NEE does not solve
     * (a Fresnel reflection came first): the part renders get from light tracing */
    lr_ref_estimate escaped_light_traced;
    lr_ref_stats stats;
} lr_ref_escape_result;

int lr_ref_sphere_escape(const lr_ref_sphere_problem *p, lr_ref_escape_result *out, lr_err *e);

/* The same count on any finished scene: photons from light `light`, in fixed batches. */
int lr_ref_escape(const lr_ref_scene *s, int light, uint64_t photons, uint64_t seed, int threads,
                  lr_ref_escape_result *out, lr_err *e);

/* ---- parallel batches ------------------------------------------------------------------- */

/* Runs fn(batch, user, slot) for batch = 0 .. batches-1 on `threads` pthreads (0: all online
 * CPUs). Batches are handed out dynamically but each must write only its own slot of the
 * caller's per-batch results, which the caller then combines in batch order: the result
 * cannot depend on scheduling. */
int lr_ref_parallel(int batches, int threads, void (*fn)(int batch, void *user), void *user,
                    lr_err *e);
/* Online CPUs (at least 1). */
int lr_ref_cpu_count(void);

/* ---- images and the progressive renderer ------------------------------------------------ */

/* Linear RGB floats, rows top to bottom: render/image's lr_image, so references are read
 * and written with its PFM functions (lr_image_read_pfm, lr_image_write_pfm; one PFM
 * implementation in the project). */
typedef lr_image lr_ref_image;

/* lr_image_free. */
void lr_ref_image_free(lr_ref_image *img);

typedef struct lr_ref_camera {
    lr_vec3 position, look_at;
    lr_vec3 up;        /* zero means +z */
    double fov_y_deg;  /* vertical field of view; 0 means 40 */
} lr_ref_camera;

typedef struct lr_ref_render_desc {
    int width, height;   /* 0 means 160 x 120 */
    int spp;             /* samples per pixel in all; 0 means 64 */
    int spp_per_pass;    /* samples added by one lr_ref_render_pass; 0 means 4 */
    int threads;         /* 0: all online CPUs (does not change the result) */
    uint64_t seed;
} lr_ref_render_desc;

typedef struct lr_ref_render lr_ref_render;

/* The scene must be finished and outlive the renderer. */
int lr_ref_render_create(const lr_ref_scene *s, const lr_ref_camera *cam,
                         const lr_ref_render_desc *d, lr_ref_render **out, lr_err *e);
void lr_ref_render_destroy(lr_ref_render *r);
/* Adds one pass (spp_per_pass samples per pixel, fewer on the last). Returns LR_OK. */
int lr_ref_render_pass(lr_ref_render *r, lr_err *e);
/* Samples per pixel accumulated so far, and the target. */
int lr_ref_render_spp_done(const lr_ref_render *r);
int lr_ref_render_spp_total(const lr_ref_render *r);
const lr_ref_stats *lr_ref_render_stats(const lr_ref_render *r);
/* Runs passes until spp is reached, calling progress (may be NULL) after each. */
int lr_ref_render_run(lr_ref_render *r, void (*progress)(const lr_ref_render *r, void *user),
                      void *user, lr_err *e);
/* The mean radiance per pixel, and the variance of that mean (sample variance of the
 * per-sample values / samples): its square root is the pixel's standard error. */
int lr_ref_render_mean(const lr_ref_render *r, lr_ref_image *out, lr_err *e);
int lr_ref_render_variance(const lr_ref_render *r, lr_ref_image *out, lr_err *e);

/* ---- reference cache -------------------------------------------------------------------- */

/* Key of a rendered reference: a hash of the scene content, the camera, the resolution, the
 * sample count, the seed and LR_REF_VERSION, as 16 hex digits. Thread count and pass size
 * do not change the image and are not part of it. */
void lr_ref_cache_key(const lr_ref_scene *s, const lr_ref_camera *cam,
                      const lr_ref_render_desc *d, char key[17]);

/* The reference for (s, cam, d): read from dir/<key>.pfm and dir/<key>.var.pfm when both are
 * there and pass the checks below, otherwise rendered (progress may be NULL) and written there
 * atomically (dir is created). *hit says which; mean and var are filled either way. dir NULL
 * means "build/reference-cache".
 *
 * An entry is served only when dir/<key>.json names the key and holds both images' content
 * hashes (lr_ref_image_hash), both images have the key's size and match their hashes, and every
 * value is finite and non-negative. An entry that fails (a damaged or edited file, a truncated
 * one, a NaN) is refused with one warning to warn (may be NULL) naming the file, and rendered
 * again; one without hashes (an older cache format) is stale and rendered again the same way.
 * A render with a value the checks would refuse is not stored: an error. */
int lr_ref_render_cached(const lr_ref_scene *s, const lr_ref_camera *cam,
                         const lr_ref_render_desc *d, const char *dir,
                         void (*progress)(const lr_ref_render *r, void *user), void *user,
                         const lr_warn_sink *warn, lr_ref_image *mean, lr_ref_image *var,
                         bool *hit, lr_err *e);

/* The loader under lr_ref_render_cached, without the render: the entry `key` (lr_ref_cache_key)
 * of a width x height reference under dir (NULL: "build/reference-cache"). True with *mean and
 * *var filled (the caller frees them) when the entry passes every check above; false with
 * nothing to free otherwise: quietly when dir/<key>.pfm is absent, else after one warning to
 * warn naming the file and what failed. Any bytes in the three files give one of the two
 * (tests/reference/test_reference_cache.c mutates them by the thousand under ASan). */
bool lr_ref_cache_load(const char *dir, const char key[17], int width, int height,
                       const lr_warn_sink *warn, lr_ref_image *mean, lr_ref_image *var);

/* Content hash of an image as the cache keeps it: 64-bit FNV-1a of the width and height
 * (uint64) and every value's bits (uint32), little-endian, rows top to bottom. */
uint64_t lr_ref_image_hash(const lr_ref_image *img);

/* ---- scene files ------------------------------------------------------------------------ */

/* Loads a reference scene file (format in render/reference/README.md, "Scene files") into a
 * finished scene
 * and its camera and render settings (fields absent from the file keep the values *cam and
 * *d had on entry). */
int lr_ref_scene_load(const char *path, lr_ref_scene **out, lr_ref_camera *cam,
                      lr_ref_render_desc *d, lr_err *e);

/* The reference scene of a project scene (render/scene: configs/scenes/NAME.json) and its
 * camera: each object's world mesh bounds its material (outside: air), each receiver's mesh
 * is a receiver (planes moved 1 um away from the scene so that a candle standing on the
 * table does not share its plane), point and spot lights at their steady intensity times
 * colour (flicker is a display effect). The object meshes are borrowed: sc must outlive the
 * returned scene and not change meanwhile. Directional lights and orthographic cameras have
 * no counterpart here (LR_EUNSUPPORTED); an object that is not watertight cannot bound its
 * material (LR_EINVAL). */
typedef struct lr_scene lr_scene;
int lr_ref_scene_from_scene(const lr_scene *sc, lr_ref_scene **out, lr_ref_camera *cam,
                            lr_err *e);

#endif
