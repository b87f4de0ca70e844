/* lamprig — translucent radiosity (seed 000: Sheng, Shi, Wang, Narasimhan, "Translucent
 * Radiosity", IEEE TVCG): light transport between translucent objects and diffuse receivers
 * over patches,
 *
 *     B = (I - S F)^-1 S E                                   (seed 000 Eq. 14)
 *
 * F the form-factor matrix (light that leaves patch j diffusely and reaches patch i), S the
 * subsurface-scattering matrix (light that enters patch i and leaves patch j of the same
 * object, Eq. 8; for a diffuse patch S = P, its albedo, which gives back Eq. 2), E the direct
 * light from the scene's lights at unit intensity.
 *
 * What is built (render/transrad/README.md has the derivations):
 *   patches   translucent and diffuse meshes: triangles clustered by a cubic cell of edge
 *             patch_mm and by the dominant axis of their normal (so the inner and outer faces
 *             of a shell never share a patch); planes: a grid of cells (patches.c);
 *   F         by cosine-distributed ray casts from points spread over each patch against every
 *             surface's BVH (visibility included; a ray that leaves the scene is the patch's
 *             escape), stored sparse per row (formfactor.c);
 *   S         per object, from a diffusion profile (the slab multipole's R and T where a wall
 *             thickness is given or, for translucent_radiosity, measured under each patch;
 *             the standard dipole R_d for a half-space) indexed by the in-object distance:
 *             straight where the segment between the two patches' inner points stays inside
 *             the material, otherwise a Dijkstra shortest path over the inner points of the
 *             object's patches (optdist.c), so the profile leaks neither across a concave gap
 *             nor through air. Exit at the patch centroid, entry integrated over the source
 *             patch with more points when near (seed 000 Sec. 4.1); each column scaled so that
 *             the power that leaves equals the model's plane total (subsurface.c); on thin
 *             walls (lr_tr_wall_thin) the slab's R_tot leaves the lit face and T_tot the far
 *             one, spread by the profiles and integrated over both patches (thinwall.c);
 *   E         per light, unit intensity, shadowed by every surface, averaged over points of each
 *             patch; on a translucent patch split into the part that enters (F_t(cos)) and the
 *             Fresnel-reflected rest (direct.c); a quad or disk light at unit radiance: the
 *             closed-form irradiance of render/area times the visible fraction from shadow
 *             rays to stratified points on the emitter (direct_area.c);
 *   solve     the Jacobi iteration of seed 000 Sec. 5 (L = S E, then L <- S E + S F L),
 *             warm-started from the last solution of the same light slot (solve.c); or,
 *             where the budget allows, the precomputed transfer: LU factors of I - S F
 *             (with the interfaces' reflection), so a light move is E and two triangular
 *             solves (transfer.c).
 *
 * Radiometry. The solution W is the radiosity that leaves each patch (W/mm^2 per W/sr of the
 * light). A translucent patch's W = W_sss + W_refl: W_sss left the material after scattering
 * in it, W_refl is the Fresnel-reflected part of its incident light (taken as diffuse). The
 * renderer's maps hold B with L_o = F_t(w_o) B / pi, whose exitance is T_hem B: the map value of
 * a patch is W_sss / T_hem (lr_tr_map_radiosity). Light arriving diffusely at a translucent
 * patch enters with T_hem and is reflected with 1 - T_hem.
 *
 * Opaque struct; create/destroy; errors name the surface and field.
 */
#ifndef LR_TRANSRAD_H
#define LR_TRANSRAD_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "render/base/cancel.h"
#include "render/base/err.h"
#include "render/base/vec3.h"
#include "render/base/warn.h"
#include "render/base/warn_once.h"
#include "render/mesh/bvh.h"
#include "render/mesh/mesh.h"
#include "render/optics/optics.h"
#include "render/scene/scene.h"

enum lr_tr_kind {
    LR_TR_TRANSLUCENT, /* a scattering object: S from its profile */
    LR_TR_DIFFUSE,     /* an opaque diffuse mesh (a box receiver, a test's sphere) */
    LR_TR_PLANE,       /* a one-sided rectangle (a plane receiver): a grid of patches */
};

typedef struct lr_tr_surface_desc {
    enum lr_tr_kind kind;
    const lr_mesh *mesh; /* world space, faces outward (toward where their light goes) */
    const lr_bvh *bvh;   /* over mesh */
    double albedo[3];    /* diffuse, plane */
    /* translucent */
    const lr_coeffs *coeffs;
    enum lr_sss_model model; /* multipole: R and T of a slab of thickness_mm; others: R_d */
    double thickness_mm;
    /* plane: the rectangle (the receiver's) */
    lr_vec3 center, normal, u_dir;
    double size_u, size_v;
    int cells_u, cells_v; /* plane grid; 0: from patch_mm */
    double patch_mm;      /* cluster cell edge; 0: the settings' */
    /* diffuse or translucent: a closed body; the part of a plane cell inside it is no
     * surface (render/transrad/cover.c): the plane cells' F, E and solution are over their
     * open part, lr_tr_open_fraction */
    bool covers;
} lr_tr_surface_desc;

typedef struct lr_tr_settings {
    double patch_mm;        /* object cluster cell; 0: 12 mm */
    double receiver_mm;     /* plane grid cell; 0: 30 mm (at most 64 cells a side) */
    int rays_per_patch;     /* form-factor rays; 0: 512 */
    int direct_samples;     /* points per patch for E; 0: 16 */
    int area_samples;       /* quad/disk lights: shadow rays per point to the emitter
                             * (stratified), 0: 16, at most 256 (direct_area.c) */
    int max_iterations;     /* Jacobi sweeps; 0: 50 */
    double tolerance;       /* stop when the relative residual is below; 0: 1e-4 */
    uint64_t seed;
    int threads;            /* 0: all online CPUs */
    int transfer_mb;        /* budget of the precomputed transfer (transfer.c: 24 n^2 bytes),
                             * e.g. 256 (the 4 GB target's share); <= 0 (default): not built.
                             * Over the budget the warm-started sweeps solve instead. Off by
                             * default: measured slower than the warm sweeps after a light
                             * move (render/transrad/README.md) */
    int thin_wall;          /* S on slab walls (render/transrad/thinwall.c): LR_TR_THIN_AUTO
                             * (0, default) by lr_tr_wall_thin per patch, LR_TR_THIN_OFF the
                             * profile at in-object distances everywhere, LR_TR_THIN_ON the
                             * thin-wall column on every slab patch */
    const char *cache_dir;  /* F and S cached in this folder (cache.c), keyed by a hash of the
                             * geometry, materials and the settings above; NULL: no cache.
                             * Read during create only (the pointer is not kept in use) */
    lr_warn_sink warn;      /* a store into cache_dir that fails (read-only, full): said here,
                             * once per folder per `warned` (the next start rebuilds F and S) */
    lr_warn_once *warned;   /* the caller's: folders already said; NULL: said at every store */
    /* Polled during create (form factors, subsurface, direct light) and by every solve (per
     * sweep); kept (lr_tr_set_cancel replaces it). NULL: never cancelled. A cancelled create
     * fails with LR_ECANCELED and stores no cache; a cancelled solve leaves its partial sweep
     * as the next solve's warm start. Not part of the cache key. */
    const lr_cancel *cancel;
} lr_tr_settings;

enum { LR_TR_THIN_AUTO = 0, LR_TR_THIN_OFF = 1, LR_TR_THIN_ON = 2 };

#define LR_TR_MAX_SURFACES 32
#define LR_TR_MAX_SLOTS 4

typedef struct lr_tr lr_tr;

typedef struct lr_tr_stats {
    int iterations;
    double residual;        /* ||W_k+1 - W_k||_1 / ||W_k+1||_1, power-weighted, all bands */
    double residual10;      /* the same after 10 sweeps (or the last, if fewer) */
    double ms_direct, ms_solve;
    bool transfer;          /* solved by the precomputed transfer (iterations 0) */
} lr_tr_stats;

/* Builds patches, F and S (the precomputation: after geometry or material changes). */
int lr_tr_create(const lr_tr_surface_desc *surfaces, int count, const lr_tr_settings *settings,
                 lr_tr **out, lr_err *e);
/* From a scene: its objects (translucent, the object's model and thickness) and its
 * receivers (planes and boxes). */
int lr_tr_create_scene(const lr_scene *s, const lr_tr_settings *settings, lr_tr **out,
                       lr_err *e);
void lr_tr_destroy(lr_tr *t);
/* The token the solves poll from now on (NULL: never cancelled). */
void lr_tr_set_cancel(lr_tr *t, const lr_cancel *cancel);

/* Direct light of a unit-intensity light (shadowed, per patch) and the solve, warm-started
 * from slot's last solution. */
int lr_tr_solve_light(lr_tr *t, const lr_light *light, int slot, lr_tr_stats *st, lr_err *e);
/* The same with the direct irradiance given (n x 3, W/mm^2; translucent patches take it as
 * diffuse light). */
int lr_tr_solve_irradiance(lr_tr *t, const double *E, int slot, lr_tr_stats *st, lr_err *e);

/* The direct irradiance of a unit-intensity light per patch (n x 3, W/mm^2 into E), shadowed by
 * every surface: lr_tr_solve_light's E, for callers that add light of their own before
 * lr_tr_solve_irradiance (render/bounce/: the receivers' bounce adds the VPLs' light). */
int lr_tr_direct_irradiance(lr_tr *t, const lr_light *light, double *E, lr_err *e);

/* A diffuse or plane surface's albedo, changed after create: F does not depend on it (the
 * next solve uses it; the cache key keeps the albedo create had). LR_EINVAL for a translucent
 * surface, a value outside [0, 1], or when the precomputed transfer was built (its factors
 * hold the old albedo). render/bounce: an object's albedo follows its material. */
int lr_tr_set_albedo(lr_tr *t, int s, const double albedo[3], lr_err *e);

/* The thin-wall rule (render/transrad/thinwall.c): a slab of thickness d (mm) of medium c is
 * thin against patches of patch_mm when it is no thicker than a patch, d <= patch_mm; its S
 * columns then send the slab's R_tot out of the lit face and T_tot out of the opposite one,
 * spread by the profiles. Why: T spreads over about d, and the two faces' patches overlap,
 * so exit centroids a patch apart sample T too coarsely to split the light between the faces
 * (the votive's 7 mm wax at 12 mm patches: 0.69 / 0.26 out of the lit / far face against the
 * slab's 0.76 / 0.19). An earlier rule (the wider profile's r90 <= patch_mm / 4) left
 * such walls to those centroid sums; it implied d <= patch_mm, as T's r90 is at least about
 * d. False for c NULL, d or patch_mm not positive. */
bool lr_tr_wall_thin(const lr_coeffs *c, double d, double patch_mm);

/* ---- Queries ------------------------------------------------------------------------------- */
/* Whether create took F and S from the cache (settings.cache_dir) instead of building them. */
bool lr_tr_cache_hit(const lr_tr *t);
/* The on-disk cache's key of t (cache.c): its settings, surfaces and patches. Caches of what
 * is built on t's patches (render/bounce's object rows) start from it. */
uint64_t lr_tr_geometry_key(const lr_tr *t);
/* The default cache folder: $XDG_CACHE_HOME/lamprig, else $HOME/.cache/lamprig (absolute
 * paths only); NULL when neither is set. buf receives it. */
const char *lr_tr_cache_default_dir(char *buf, size_t cap);
/* Bytes of the precomputed transfer; 0 when it was not built (over the budget). */
size_t lr_tr_transfer_bytes(const lr_tr *t);
size_t lr_tr_patch_count(const lr_tr *t);
/* First patch and count of surface s (in the order given to create; for a scene: objects,
 * then receivers). */
void lr_tr_surface_patches(const lr_tr *t, int s, size_t *first, size_t *count);
void lr_tr_patch_geometry(const lr_tr *t, size_t p, lr_vec3 *centroid, lr_vec3 *normal,
                          double *area);
int lr_tr_patch_surface(const lr_tr *t, size_t p);
/* A plane surface's grid: patch first + u + nu v is the cell (u, v), u along its size_u.
 * False (and 0 x 0) for other kinds. */
bool lr_tr_plane_grid(const lr_tr *t, int s, int *nu, int *nv);
/* The fraction of plane cell p outside every covering body (the desc's covers; cover.c):
 * its F, E and solution are means over that part. 1 for any other patch. */
double lr_tr_open_fraction(const lr_tr *t, size_t p);
/* All patches' open fractions (n, by patch index), or NULL when no surface covers (every
 * fraction 1): what lr_tr_plane_cells and lr_tr_plane_to_grid take, from a plane's first. */
const double *lr_tr_open_fractions(const lr_tr *t);
/* Whether the point at (fu, fv) of plane surface s (fractions of size_u, size_v from its
 * corner at -size/2, as the receivers' texels) lies inside a covering body. */
bool lr_tr_plane_point_covered(const lr_tr *t, int s, double fu, double fv);
/* The patch a surface's triangle belongs to (plane: the cell of the point x on it). */
size_t lr_tr_patch_of(const lr_tr *t, int surface, size_t triangle, lr_vec3 x);
/* F_pq: fraction of the light leaving p diffusely that reaches q (first hit). */
double lr_tr_form_factor(const lr_tr *t, size_t p, size_t q);
/* Fraction of p's rays that left the scene. */
double lr_tr_escape(const lr_tr *t, size_t p);
/* S_qp per band: radiosity leaving q per unit irradiance entering p (0 across objects). */
void lr_tr_subsurface(const lr_tr *t, size_t q, size_t p, double out[3]);
/* Where S sends the light that enters translucent surface s under unit irradiance on every
 * patch, per unit power entered and band: out of patches facing the same way as the entry
 * (lit face, n_p . n_q >= 0) and the opposite way (the far face of a wall). For a slab these
 * are its R_tot and T_tot; zeros for another kind of surface. */
void lr_tr_subsurface_split(const lr_tr *t, int s, double lit[3], double opposite[3]);
/* Slot's solution: W leaving p (all of it), the irradiance H arriving at p (direct + bounce),
 * the indirect part of H, and the renderer's map value W_sss / T_hem. */
void lr_tr_radiosity(const lr_tr *t, int slot, size_t p, double out[3]);
void lr_tr_irradiance(const lr_tr *t, int slot, size_t p, double out[3]);
void lr_tr_indirect(const lr_tr *t, int slot, size_t p, double out[3]);
void lr_tr_map_radiosity(const lr_tr *t, int slot, size_t p, double out[3]);
/* Power per band that leaves the scene (escaping rays) in slot's solution, W per W/sr. */
void lr_tr_escaped_power(const lr_tr *t, int slot, double out[3]);

/* A ray's first hit over every surface (the solver's own caster, cast.c): false when it leaves
 * the scene; n 0 for a back face (absorbed: a one-sided receiver from behind, a wall from
 * inside); else the hit surface and n patches with weights summing to 1: the hit's patch on a
 * mesh, on a plane the up to 4 cells around it, bilinear between their centres (clamped at
 * the edges) with the weights scaled by the cells' open fractions and renormalised, as the
 * receivers' grid is written (n 0 where every weight is 0). */
typedef struct lr_tr_cast_hit {
    int surface, n;
    size_t patch[4];
    double w[4];
    double dist;
} lr_tr_cast_hit;
bool lr_tr_cast(const lr_tr *t, lr_vec3 o, lr_vec3 d, lr_tr_cast_hit *h);
/* The cells of a plane's nu x nv grid around its point at (fu, fv) (fractions of size_u,
 * size_v from the corner at -size/2): the up to 4 cells (u + nu v) whose centres surround it,
 * clamped at the edges, bilinear weights scaled by the cells' open fractions (open: one per
 * cell, lr_tr_open_fraction; NULL: all 1) and renormalised to sum 1 (all 0 where every one
 * is 0). The receivers' grid (lr_tr_plane_to_grid) and a ray's plane hit (lr_tr_cast) read a
 * plane's cells through it. */
void lr_tr_plane_cells(double fu, double fv, int nu, int nv, const double *open, size_t cell[4],
                       double w[4]);
/* The ray-origin offset the solver uses off a surface (scale of the scene). */
double lr_tr_ray_eps(const lr_tr *t);

#endif
