/* lamprig — physical reference: internals shared by the files of render/reference/ only. */
#ifndef LR_REF_PRIV_H
#define LR_REF_PRIV_H

#include <math.h>
#include <stdbool.h>

#include "render/reference/reference.h"

#define LR_REF_PI 3.14159265358979323846
#define LR_REF_NAME_MAX 64

/* Russian roulette: a path whose largest band throughput falls below this survives with
 * probability throughput / LR_REF_RR_THRESHOLD and is reweighted (unbiased). */
#define LR_REF_RR_THRESHOLD 0.1
/* Hard cap on events per path; reaching it is counted (lr_ref_stats.truncated). */
#define LR_REF_MAX_EVENTS 1000000

struct lr_ref_shape {
    const lr_ref_shape_ops *ops;
    void *self;
};

typedef struct lr_ref_medium {
    double sigma_a[3], sigma_s[3], sigma_t[3], albedo[3];
    double g, eta;
    char name[LR_REF_NAME_MAX];
} lr_ref_medium;

enum lr_ref_surf_kind { LR_REF_SURF_BOUNDARY, LR_REF_SURF_RECEIVER, LR_REF_SURF_LIGHT };

typedef struct lr_ref_object {
    enum lr_ref_surf_kind kind;
    lr_ref_shape *shape;
    int inside, outside; /* boundary */
    double albedo[3];    /* receiver */
    int light;           /* light: index into lights */
    char name[LR_REF_NAME_MAX];
} lr_ref_object;

typedef struct lr_ref_light {
    lr_ref_light_desc d;
    lr_vec3 normal;              /* area lights: emitting side; spot: unit axis */
    lr_vec3 t1, t2;              /* area lights: tangent frame (disk sampling) */
    double area;                 /* area lights */
    double cos_inner, cos_outer; /* spot */
    double power[3];             /* W per band */
    int medium;                  /* the medium the light emits into */
    int object;                  /* area lights: its object index, else -1 */
    lr_light_profile *profile;   /* the desc's, owned; NULL none */
    lr_profile_sampler *sampler; /* emission directions by the profile */
} lr_ref_light;

struct lr_ref_scene {
    lr_ref_medium *media;
    int n_media, cap_media;
    lr_ref_object *objects;
    int n_objects, cap_objects;
    lr_ref_light *lights;
    int n_lights, cap_lights;
    double *light_pick; /* selection probability of each light for NEE (by total power) */
    double *delta_pick; /* ... for light tracing: point and spot lights only (0 for others) */
    /* Colour bands whose coefficients agree in every medium share one path: n_groups groups,
     * each a bit mask of bands and the band whose coefficients drive distance sampling. */
    int n_groups;
    int group_mask[3], group_hero[3];
    lr_ref_hash hash;
    bool finished;
};

/* The render settings with every zero replaced by its default (render.c). */
lr_ref_render_desc lr_ref_render_desc_resolve(const lr_ref_render_desc *d);
lr_ref_camera lr_ref_camera_resolve(const lr_ref_camera *c);

/* A surface event. */
typedef struct lr_ref_surf {
    double t;
    lr_vec3 p; /* hit point */
    lr_vec3 n; /* outward unit normal of the object */
    int object;
} lr_ref_surf;

static inline double lr_ref_max3(const double v[3])
{
    return fmax(v[0], fmax(v[1], v[2]));
}

/* Self-intersection guard for rays leaving a surface: relative to the coordinates' magnitude
 * so it stays far above double rounding (1e-16 relative) and far below any mean free path of
 * interest (scenes are metres at most: 1e-9 * 1e3 mm = 1 nm). */
static inline double lr_ref_eps(lr_vec3 p)
{
    double m = fmax(fabs(p.x), fmax(fabs(p.y), fabs(p.z)));
    return 1e-9 * (1.0 + m);
}

/* Nearest surface with tmin < t < tmax; true when found. */
bool lr_ref_scene_intersect(const lr_ref_scene *s, lr_vec3 o, lr_vec3 d, double tmin,
                            double tmax, lr_ref_surf *out);

/* ---- the shared transport steps (walk.c) ------------------------------------------------ */

typedef struct lr_ref_walker {
    lr_vec3 x, d;    /* position and unit direction of travel */
    int medium;      /* medium the walker is in */
    bool on_surface; /* x lies on a surface: the next ray starts with tmin = eps */
} lr_ref_walker;

enum lr_ref_event { LR_REF_EV_ESCAPE, LR_REF_EV_SCATTER, LR_REF_EV_SURFACE };

/* Samples the distance to the next collision in the walker's medium with the coefficients of
 * band `hero` (exponential free path) and moves the walker to whichever comes first: the
 * collision, or the next surface (filled into *hit). ESCAPE when neither exists. segment
 * (may be NULL) receives the distance to the next surface along the ray (INFINITY if none). */
enum lr_ref_event lr_ref_flight(const lr_ref_scene *s, lr_ref_walker *w, int hero,
                                lr_ref_rng *rng, lr_ref_surf *hit, double *segment);

enum lr_ref_crossing { LR_REF_PASS, LR_REF_REFLECT, LR_REF_REFRACT };

/* At a boundary surface hit: index-matched → PASS (medium changes, direction kept); else
 * Fresnel reflection with probability R (exact unpolarised, TIR included) or refraction.
 * *n_ratio2 receives (n_from / n_to)^2 for a refraction (1 otherwise): radiance carried by a
 * camera path is multiplied by it, photon flux is not. */
enum lr_ref_crossing lr_ref_cross(const lr_ref_scene *s, lr_ref_walker *w,
                                  const lr_ref_surf *hit, lr_ref_rng *rng, double *n_ratio2,
                                  lr_ref_stats *st);

/* A non-specular event of a forward (photon) walk: a medium collision or a receiver bounce. */
typedef struct lr_ref_photon_vertex {
    lr_vec3 x;
    int medium;
    lr_vec3 d_in;                  /* direction of travel arriving at x */
    const double *beta;            /* throughput per band before this event's albedo */
    const lr_ref_object *receiver; /* NULL for a medium collision */
    lr_vec3 n;                     /* receiver: its normal on the arriving side */
    int index;                     /* 0 for the first non-specular event of the walk */
    bool reflected;                /* a Fresnel reflection came before the first event */
    int refractions;               /* refractions before the first event */
} lr_ref_photon_vertex;

/* Called at each non-specular event before it is applied; returning false ends the walk. */
typedef bool (*lr_ref_photon_visit)(void *user, const lr_ref_photon_vertex *v);

/* The forward walk behind lr_ref_photon_trace and light tracing: from w, carrying throughput
 * beta (bands in mask; distances sampled with band hero), until it escapes, is absorbed
 * (roulette), is capped or visit stops it. out may be NULL; beta holds the final throughput. */
void lr_ref_photon_walk(const lr_ref_scene *s, lr_ref_walker w, int mask, int hero,
                        lr_ref_rng *rng, lr_ref_stats *st, lr_ref_photon_visit visit,
                        void *user, lr_ref_photon_exit *out, double beta[3]);

/* Henyey-Greenstein (phase.c). */
double lr_ref_hg_eval(double g, double cos_theta);
/* New direction scattered from travel direction d, with cos(d, new) drawn exactly from HG. */
lr_vec3 lr_ref_hg_sample(double g, lr_vec3 d, double u1, double u2);
/* Unit vector of cosine-weighted direction around n. */
lr_vec3 lr_ref_cosine_sample(lr_vec3 n, double u1, double u2);
/* Orthonormal t1, t2 completing unit n (Duff et al. 2017, "Building an orthonormal basis,
 * revisited"). */
void lr_ref_frame(lr_vec3 n, lr_vec3 *t1, lr_vec3 *t2);

/* Smooth dielectric interface directions. n faces the incident side (dot(d, n) < 0);
 * eta_rel = n_incident / n_transmitted. Returns false under total internal reflection. */
static inline lr_vec3 lr_ref_reflect(lr_vec3 d, lr_vec3 n)
{
    return lr_v3_sub(d, lr_v3_scale(n, 2.0 * lr_v3_dot(d, n)));
}
bool lr_ref_refract(lr_vec3 d, lr_vec3 n, double eta_rel, lr_vec3 *out);

/* ---- lights (light.c) ------------------------------------------------------------------- */

/* A point that emits: a point or spot light, one sampled point of an area light, or (light
 * tracing) a photon's scattering vertex re-emitting its flux toward the camera. */
typedef struct lr_ref_emitter {
    const lr_ref_light *light; /* NULL: a photon vertex */
    lr_vec3 p;
    int medium;                /* the medium p emits into */
    double area_weight;        /* area lights: 1 / pdf of the sampled point (the area); else 1 */
    /* photon vertex: flux leaving it per band (after albedo), and its angular distribution,
     * HG about d_in for a medium collision or Lambertian about n for a receiver */
    double power[3];
    lr_vec3 d_in, n;
    double g;
    bool lambert;
} lr_ref_emitter;

/* Radiant intensity (W/sr) the emitter sends along unit w, in band b: point I; spot I times
 * the cone profile; area point L_e * cos * area_weight on the front side, 0 behind; photon
 * vertex power * HG(d_in . w), or power * max(0, n . w) / pi. */
double lr_ref_emitter_intensity(const lr_ref_emitter *em, lr_vec3 w, int b);
/* Picks a light by power (pick probability in *pick) and a point on it. */
void lr_ref_light_sample(const lr_ref_scene *s, lr_ref_rng *rng, lr_ref_emitter *em,
                         double *pick);

/* Samples an emitted photon: origin, direction and the power it carries per band. */
void lr_ref_light_emit_all(const lr_ref_light *l, lr_ref_rng *rng, lr_vec3 *origin,
                           lr_vec3 *dir, double power[3]);

/* ---- next-event connections (connect.c) ------------------------------------------------- */

/* Flux density E (W/mm^2 per band, measured across the beam) arriving at x in medium mx from
 * the emitter (in em->medium), along unit *w_in (pointing from x back toward where the light comes from).
 * The connection passes straight through index-matched boundaries and is solved through up
 * to LR_REF_MAX_CHAIN refractive ones (Newton on the emission direction; see connect.c).
 * Returns false when there is no connection (blocked, too many interfaces, not solved): E is
 * then zero. rr (may be NULL) allows Russian roulette on refracted connections whose
 * transmittance estimate (lr_ref_topology.tau_bound) is below 1e-3. Bands outside mask are
 * left zero. */
bool lr_ref_connect(const lr_ref_scene *s, const lr_ref_emitter *em, lr_vec3 x, int mx,
                    int mask, lr_ref_rng *rr, lr_ref_stats *st, double E[3], lr_vec3 *w_in);

/* What the straight segment from an emitter point p (in medium mp) to x (in mx) crosses. */
typedef struct lr_ref_topology {
    int k;             /* refractive interfaces crossed; -1: blocked by an opaque surface,
                        * inconsistent media, or more than LR_REF_MAX_CHAIN */
    double tau[3];     /* optical depth along the straight segment, per band */
    /* Optical depth of x below the tangent plane of the last refractive interface, plus that
     * of p below the plane of the first (no refracted path through planes can be shorter),
     * plus the straight optical depth between the first and last interface (an estimate):
     * exp(-tau_bound) estimates, and for k = 1 bounds, a refracted connection's
     * transmittance. Equal to tau when k == 0. */
    double tau_bound[3];
} lr_ref_topology;

/* The straight-segment analysis lr_ref_connect starts from; also used to tell path hits on
 * area lights apart from what next-event estimation covers. */
void lr_ref_chain_topology(const lr_ref_scene *s, lr_vec3 p, int mp, lr_vec3 x, int mx,
                           lr_ref_topology *out);

/* The pinhole camera of a render, as light tracing needs it: position, unit frame, image
 * plane half-extents at distance 1, size and the medium the camera sits in. */
typedef struct lr_ref_pinhole {
    lr_vec3 c, f, r, u;
    double tx, ty;
    int width, height, medium;
} lr_ref_pinhole;

void lr_ref_pinhole_init(lr_ref_pinhole *p, const lr_ref_camera *cam, int width, int height,
                         int medium);
/* Pixel (row-major, rows top to bottom) that sees direction w (unit, from the camera toward
 * what it sees), or -1 outside the image; *cos3 receives cos^3 of its angle to the axis. */
long lr_ref_pinhole_pixel(const lr_ref_pinhole *p, lr_vec3 w, double *cos3);

/* ---- light tracing (lighttrace.c) ------------------------------------------------------- */

/* Whether camera-path NEE covers a light path whose light end is: the light at p (medium mp),
 * then the specular events recorded in v, then v's vertex. It does when there was no
 * reflection and the refractions are those of the straight segment (at most
 * LR_REF_MAX_CHAIN): the connection lr_ref_connect solves. Light tracing takes the rest. */
bool lr_ref_nee_covers_light_end(const lr_ref_scene *s, lr_vec3 p, int mp,
                                 const lr_ref_photon_vertex *v);

typedef struct lr_ref_splat {
    long pixel;
    double rgb[3];
} lr_ref_splat;

typedef struct lr_ref_splats {
    lr_ref_splat *v;
    size_t n, cap;
    bool oom;
} lr_ref_splats;

/* Traces photons [first, first + count) of sample index j from the point and spot lights and
 * appends their contributions to the pinhole's pixels (radiance, to be divided by the number
 * of photons of the sample index). Only paths camera-path NEE cannot produce contribute. */
void lr_ref_light_trace(const lr_ref_scene *s, const lr_ref_pinhole *cam, uint64_t seed,
                        uint64_t j, uint64_t first, uint64_t count, lr_ref_splats *out,
                        lr_ref_stats *st);

#endif
