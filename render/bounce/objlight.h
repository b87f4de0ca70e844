/* lamprig — the receivers' light on the objects (issue 12 part 3, second half;
 * render/bounce/README.md "Objects lit by the receivers").
 *
 * The receivers' radiosity solve (rbounce.h, seed 000 Eq. 2 over 30 mm patches) gives every
 * receiver patch q the radiosity W_q that leaves it: its albedo times the direct light, the
 * VPLs' light and the bounce. What of it reaches an object's surface point x of normal n is
 *
 *     E(x, n) = sum_q F_{x->q} W_q,                                   (seed 000 Eq. 2's F)
 *
 * F_{x->q} the differential form factor: the probability that a cosine-distributed ray from
 * x over n's hemisphere first hits q. It is taken by M rays (the same stratified directions
 * for every point, so that neighbouring points share their quadrature and its error varies
 * smoothly) through the solver's own ray caster (lr_tr_cast: every object and receiver
 * occludes; a plane hit is shared by the 4 cells around it, bilinear between their centres,
 * as the receivers' grid shows W), at every vertex of every object mesh. Composition
 * interpolates it over the triangle (linear, as the GPU's varyings; the CPU twin by the hit's
 * barycentrics).
 *
 * Two values per vertex: E+ = E(x, n) and E-: for an open (two-sided) object E(x, -n), for a
 * closed wall of thickness d (thickness_mm) E+ at the point of the wall's far face that the
 * ray from x along -n leaves through (within 2 d + 1 mm; the opposite face of a thin wall,
 * where the multipole's T sends light entering at x), else 0.
 *
 * From irradiance to emission (lr_objlight_factors): light that arrives diffusely enters with
 * <F_t> = 2 int F_t(mu) mu dmu, and the model's total diffuse reflectance R (transmittance T
 * through a wall; the totals render/lpv uses, lr_lpv_object_totals) of it leaves. Composition
 * emits L_o = F_t(w_o) B / pi, whose exitance is t_hem B, so
 *
 *     B_recv = (<F_t> / t_hem) (R E+ + T E-),                          (front side)
 *
 * and R E- + T E+ on an open object's back side: the exitance leaving is <F_t> R E (<F_t> and
 * t_hem are the same integral; kept as the two for objects with "normalize": false, which
 * keep the published factor as the maps do, PIPELINE.md "Energy"). The same local response
 * as render/lpv's object term: a profile's convolution of an E linear across the surface is
 * exactly R E (objfield.h derives the second-order bound).
 *
 * Linear in W, so in the lights: per light slot at unit intensity on the GPU (a dimmer turn
 * stays blend-only), once with the intensities in the CPU twin. Opaque struct. */
#ifndef LR_OBJLIGHT_H
#define LR_OBJLIGHT_H

#include <stdbool.h>
#include <stddef.h>

#include "render/base/err.h"
#include "render/mesh/bvh.h"
#include "render/mesh/mesh.h"
#include "render/scene/scene.h"
#include "render/transrad/transrad.h"

typedef struct lr_objlight lr_objlight;

typedef struct lr_objlight_desc {
    const lr_mesh *mesh; /* world space */
    const lr_bvh *bvh;   /* over mesh (the far face's ray) */
    bool two_sided;      /* open: E- by rays over -n */
    double far_mm;       /* closed wall: E- from the far face within far_mm; 0: E- = 0 */
} lr_objlight_desc;

/* Default rays per vertex (hemisphere). */
#define LR_OBJLIGHT_RAYS 512

/* Where the rows are cached: dir (NULL: no cache); a store that fails (read-only, full) is
 * said to warn, once per folder per `warned` (the caller's; NULL: at every store). */
typedef struct lr_objlight_cache {
    const char *dir;
    lr_warn_sink warn;
    lr_warn_once *warned;
} lr_objlight_cache;

/* The form-factor rows of every vertex of the count meshes against t's patches from
 * first_source on (the receivers; earlier patches, the objects, absorb), rays per hemisphere
 * (0: LR_OBJLIGHT_RAYS). cache (NULL or dir NULL: none): the rows are read from
 * <dir>/objlight-<key>.bin when it holds them for this geometry, else built and written
 * there (best effort, a failure warned; objlight_cache.c). LR_EINVAL, LR_ENOMEM. */
int lr_objlight_create(const lr_tr *t, size_t first_source, const lr_objlight_desc *d, int count,
                       int rays, const lr_objlight_cache *cache, lr_objlight **out, lr_err *e);
void lr_objlight_destroy(lr_objlight *ol);

/* E+ and E- of every vertex from slot's solution (lr_tr_radiosity of the source patches). */
int lr_objlight_eval(lr_objlight *ol, const lr_tr *t, int slot, lr_err *e);
int lr_objlight_count(const lr_objlight *ol);
size_t lr_objlight_vertex_count(const lr_objlight *ol, int mesh);
/* Slot's values of mesh i: 6 floats per vertex (E+ rgb, E- rgb, W/mm^2); NULL before an eval
 * of that slot. */
const float *lr_objlight_E(const lr_objlight *ol, int mesh, int slot);
/* The same at barycentrics (u, v) of triangle tri (weights 1 - u - v, u, v of its corners). */
void lr_objlight_at(const lr_objlight *ol, int mesh, int slot, size_t tri, double u, double v,
                    double E[6]);
/* Object o's kR, kT (above): B_recv = kR E+ + kT E- on the front side. */
void lr_objlight_factors(const lr_scene_object *o, double kR[3], double kT[3]);
/* The diffuse albedo object o shows the receivers' light (rbounce.c's object patches): the
 * interface's reflection of diffuse light, 1 - <F_t>, plus what enters and its total diffuse
 * reflectance R sends back out, <F_t> R (kR's exitance). Light the model sends through a wall
 * (T) is not in it: it leaves on the far side, which the receivers' patches do not tell. */
void lr_objlight_albedo(const lr_scene_object *o, double rho[3]);
/* Seconds the last create took. */
double lr_objlight_build_s(const lr_objlight *ol);
/* Whether create read the rows from the cache instead of casting them. */
bool lr_objlight_cache_hit(const lr_objlight *ol);

#endif
