/* lamprig — area lights (seed 004, Koa, Johan & Sourin: translucent materials under area
 * lights): the geometry and radiometry of Lambertian quad and disk emitters (LED panels and
 * strips inside a shade), independent of any renderer.
 *
 * An emitter of radiance L_e (W/(mm^2 sr)) and area A emits, per unit solid angle in direction
 * w from a point y on it, dI = L_e cos(theta_e) dA with cos(theta_e) = n.w (one-sided: 0 behind;
 * two-sided: |n.w|). The irradiance it gives a point x with normal n_x is
 *     E(x) = L_e * integral_A cos(theta_e) cos(theta_x) / |x - y|^2 dA(y)     (seed 004 Sec. 4)
 * which the closed forms below evaluate exactly (quad: Lambert's polygon formula; disk: the
 * on-axis pi L a^2/(a^2+h^2) and a many-sided polygon of equal area elsewhere) and the sample
 * sets estimate: N points y_j on the emitter, each a point light of intensity
 * I_j(w) = L_e (A / N) cos(theta_e), so sum_j I_j cos(theta_x) / d_j^2 -> E.
 * Units: mm. */
#ifndef LR_AREA_EMITTER_H
#define LR_AREA_EMITTER_H

#include <stdbool.h>
#include <stdint.h>

#include "render/base/err.h"
#include "render/base/vec3.h"

enum lr_area_kind { LR_AREA_QUAD, LR_AREA_DISK };

typedef struct lr_area_emitter {
    enum lr_area_kind kind;
    lr_vec3 center;
    lr_vec3 u, v;      /* quad: half-edge vectors (the quad is center + s u + t v, |s|,|t| <= 1);
                        * disk: an orthonormal tangent frame with u x v = normal */
    lr_vec3 normal;    /* unit, the emitting side (quad: normalize(u x v)) */
    double radius;     /* disk */
    double area;       /* mm^2 */
    bool two_sided;
} lr_area_emitter;

/* A quad from its centre and half-edges (not parallel), or a disk from centre, normal (any
 * length > 0) and radius > 0. LR_EINVAL for a degenerate emitter. */
int lr_area_quad(lr_vec3 center, lr_vec3 half_u, lr_vec3 half_v, bool two_sided,
                 lr_area_emitter *out, lr_err *e);
int lr_area_disk(lr_vec3 center, lr_vec3 normal, double radius, bool two_sided,
                 lr_area_emitter *out, lr_err *e);

/* The emitted intensity per unit radiance of the whole emitter toward w (unit), as if it were
 * a point: A cos(theta_e), 0 behind a one-sided emitter. */
double lr_area_intensity_factor(const lr_area_emitter *em, lr_vec3 w);

/* ---- sampling ------------------------------------------------------------------------------ */

/* The point of (u1, u2) in [0,1)^2 under the area-preserving map of the emitter: uniform
 * (u1, u2) give area-uniform points. Quad: bilinear; disk: Shirley & Chiu's concentric map
 * (area-preserving and continuous, so strata stay compact). */
lr_vec3 lr_area_point(const lr_area_emitter *em, double u1, double u2);

/* n area-uniform points, one per stratum of a jittered g x h grid of the unit square (g h = n,
 * g the divisor of n nearest sqrt(n)) mapped by lr_area_point. Deterministic in seed. */
void lr_area_stratified(const lr_area_emitter *em, int n, uint64_t seed, lr_vec3 *out);

/* A Poisson-disk set on the emitter (seed 004 Sec. 3, after Bowers et al. 2010): dart throwing
 * of uniform candidates in the parameter square of lr_area_point, each accepted when it is at
 * least r_min (mm) from every accepted point, until `max_fails` candidates in a row were
 * refused or cap points were placed; *n receives the count. The distance is measured on the
 * torus: the parameter square with its axes scaled by the emitter's extent (lr_area_param_
 * scales; on a rectangle the Euclidean distance away from the wrap, on a disk that of the
 * concentric map's square). The torus has no boundary, so the set's density is uniform: dart
 * throwing in a bounded domain packs points more densely along the boundary, which would bias
 * the estimate A/n sum f(y_j) toward the rim. r_min <= 0 or cap < 1: LR_EINVAL. */
int lr_area_poisson(const lr_area_emitter *em, double r_min, int cap, int max_fails,
                    uint64_t seed, lr_vec3 *out, int *n, lr_err *e);
/* The same in the parameter square: axis scales (sx, sy), points uv. */
void lr_area_poisson_uv(double sx, double sy, double r_min, int cap, int max_fails,
                        uint64_t seed, double (*uv)[2], int *n);
/* The axis scales of the parameter square (mm): a quad's full edge lengths, a disk's
 * diameter. */
void lr_area_param_scales(const lr_area_emitter *em, double *sx, double *sy);

/* The radius at which dart throwing places about n points on an area A: disks of radius
 * r_min/2 around the points are disjoint, and random sequential adsorption jams when they
 * cover 0.547 of the plane (Feder 1980); aiming at a coverage of 1/2, n pi r_min^2 / 4 = A / 2,
 * gives r_min = sqrt(2 A / (pi n)), which a few thousand refusals in a row reach. */
double lr_area_poisson_radius(double area, int n);

/* ---- irradiance ----------------------------------------------------------------------------- */

/* Irradiance at x (normal n_x, unit) from the emitter at radiance L: the closed forms, with the
 * emitter clipped to the part above x's tangent plane; 0 behind a one-sided emitter. */
double lr_area_irradiance(const lr_area_emitter *em, double L, lr_vec3 x, lr_vec3 n_x);

/* On the axis of a disk of radius a at height h, facing it: pi L a^2 / (a^2 + h^2). */
double lr_area_disk_irradiance_axis(double L, double a, double h);

/* Lambert's formula for a uniform Lambertian polygon of radiance L (vertices in order, planar,
 * n <= 512) seen from x with normal n_x:
 *     E = (L / 2) |sum_i theta_i (gamma_i . n_x)|,
 * theta_i the angle subtended by edge i at x and gamma_i the unit normal of the plane through
 * x and that edge (Lambert 1760; Arvo 1995 Eq. 9). The polygon is first clipped to n_x's
 * hemisphere, so the formula holds for any placement. */
double lr_area_polygon_irradiance(const lr_vec3 *verts, int n, double L, lr_vec3 x,
                                  lr_vec3 n_x);

/* The sample-set estimate sum_j L (A/n) cos(theta_e,j) cos(theta_x,j)^+ / d_j^2 (no
 * visibility), the estimator the renderer's samples implement. */
double lr_area_irradiance_samples(const lr_area_emitter *em, const lr_vec3 *pts, int n,
                                  double L, lr_vec3 x, lr_vec3 n_x);

#endif
