/* lamprig — a light's angular profile from a photometric file, in the form every estimator
 * reads: the intensity per direction relative to its largest, on one fixed grid.
 *
 * The grid is regular in the vertical angle gamma (0 at nadir .. 180, LR_PROFILE_NG samples,
 * 2.5 degrees apart) and the C plane (0 .. 360, LR_PROFILE_NC samples, 5 degrees apart; the
 * last repeats the first). lr_light_profile_eval interpolates bilinearly between them, and the
 * GLSL side (render/shaders/lib/profile.glsl) does the same arithmetic on the same floats, so
 * the GPU passes, the CPU twin, translucent radiosity and the physical reference see one shape.
 * Resampling the file's own (often coarser) angles onto this grid keeps its flux to the
 * interpolation's error: the tests bound it at 1 % for the shipped examples.
 *
 * Directions are taken in the luminaire's frame: z the nadir (gamma 0), x the C0 plane (the
 * luminaire's length), y = C90 = C0 x nadir (counter-clockwise seen from above a luminaire
 * hanging down, as LM-63 and EULUMDAT count C). */
#ifndef LR_PROFILE_H
#define LR_PROFILE_H

#include <stdbool.h>
#include <stdint.h>

#include "render/base/vec3.h"
#include "render/photometry/luminaire.h"

#define LR_PROFILE_NG 73 /* gamma 0..180 at 2.5 degrees */
#define LR_PROFILE_NC 73 /* C 0..360 at 5 degrees */
#define LR_PROFILE_DG 2.5
#define LR_PROFILE_DC 5.0

typedef struct lr_light_profile {
    bool on;
    /* rel[c * LR_PROFILE_NG + g]: intensity at (C = c DC, gamma = g DG) over max_cd, in [0, 1]. */
    float rel[LR_PROFILE_NC * LR_PROFILE_NG];
    double max_cd;      /* the file's largest intensity (cd) */
    double lumens;      /* the flux the file states (lm; 0: none) */
    double omega;       /* the integral of rel over the sphere (sr): flux = max_cd * omega */
    double omega_down;  /* ... over gamma < 90 (the front of an area emitter) */
    uint64_t hash;      /* of rel: a cache key's part */
} lr_light_profile;

/* Resamples a parsed file onto the grid (max_cd > 0 required: an all-dark file is refused). */
int lr_light_profile_from_luminaire(const lr_luminaire *lum, lr_light_profile *out, lr_err *e);
/* Loads and resamples a .ies / .ldt file. */
int lr_light_profile_load(const char *path, lr_light_profile *out, lr_err *e);

/* rel at gamma (from the cosine, clamped to [-1, 1]) and C (degrees, any value: wrapped). */
double lr_light_profile_at(const lr_light_profile *p, double cos_gamma, double c_deg);
/* rel along local direction d (unit; z the nadir, x C0). */
double lr_light_profile_eval(const lr_light_profile *p, lr_vec3 d);

/* The integral over the sphere (sr) of rel times a spot's cone about the nadir: 1 within
 * inner_deg, 0 beyond outer_deg, the smoothstep in cos between (lr_light_shape). The midpoint
 * rule at 0.5 degree from the axis (the smoothstep band needs it) and 5 degrees around it. */
double lr_light_profile_cone_omega(const lr_light_profile *p, double inner_deg, double outer_deg);

/* The luminaire's frame for nadir n (unit) and a C0 hint (any vector not parallel to n; a zero
 * or parallel hint takes +x, or +y when n is near x): x = C0 (orthogonalised), y = x cross n, z = n. */
void lr_light_profile_frame(lr_vec3 n, lr_vec3 c0_hint, lr_vec3 *x, lr_vec3 *y, lr_vec3 *z);

/* Importance sampling by the profile (the physical reference's emission): a table of cell
 * weights, each cell's rel averaged at its corners times its solid angle. */
typedef struct lr_profile_sampler {
    double cdf[(LR_PROFILE_NC - 1) * (LR_PROFILE_NG - 1)];
    double total; /* the sum of the weights (sr) */
    int gamma_cells; /* LR_PROFILE_NG - 1, or half of that: lower hemisphere only */
} lr_profile_sampler;
/* lower_only: sample gamma < 90 only (a one-sided area emitter). Fails on a profile dark there. */
int lr_profile_sampler_init(const lr_light_profile *p, bool lower_only, lr_profile_sampler *s,
                            lr_err *e);
/* A local direction from two uniforms, with its density (1/sr) among the sampler's cells. */
lr_vec3 lr_profile_sample(const lr_profile_sampler *s, double u1, double u2, double u3,
                          double *pdf);

#endif
