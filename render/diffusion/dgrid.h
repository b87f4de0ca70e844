/* lamprig — seed 001 (Wang et al. 2008): light diffusion on a voxel grid over an object.
 *
 * The diffusion equation of seed 001 Eq. 1, with the diffusion coefficient kappa = D and the
 * absorption mu = sigma_a varying per voxel and per band,
 *
 *     div(D grad phi) - mu phi = 0                        inside the object V,
 *     phi + 2 A D dphi/dn      = 4 q / (1 - F_dr)         on its surface (n outward),
 *
 * the Robin (extrapolated-boundary) condition of seed 001 Eq. 2 with A = (1 + F_dr)/(1 - F_dr)
 * from eta, written with the partial currents J-+ = phi/4 +- (D/2) dphi/dn: the inward current is
 * the internally reflected part of the outward one plus q, the incident irradiance that the
 * Fresnel interface lets in (unit light intensity). The light leaving the surface is then
 *
 *     B = (1 - F_dr) J+ = (phi - 2 q) / (2 A)             (W/mm^2 per unit intensity)
 *
 * (seed 001 Eq. 3 integrated over the outgoing hemisphere): the exitance, Fresnel included.
 * Composition renders every model's B as F_t(w_o) B / pi, whose exitance is T_hem B, so the
 * renderer's field is this B / T_hem (render/diffusion/dscene.c). Energy: the integral of
 * q - B over the surface equals the integral of mu phi over the volume (divergence theorem),
 * which the tests check on the discrete solution.
 *
 * Discretisation (our choice; the paper's polygrid needs a hand-built polycube per object):
 * a regular grid of spacing h over the object's bounds, classified with the mesh BVH. Nodes
 * inside are the unknowns of the 7-point finite-difference form of Eq. 1 (face coefficients the
 * mean of the two nodes' D; seed 001 Eq. 8). Nodes outside within 1.75 h of the surface are
 * ghost nodes (a ghost-fluid method): each carries the boundary condition at its closest surface
 * point b along n = (node - b)/|node - b|, with phi on that normal line fitted by the quadratic
 * through the ghost value and the trilinear values at depths h and 2 h inside. The ghost is the
 * paper's boundary node "connected to one interior node along the inward normal" (seed 001
 * Sec. 5, Eq. 9), made second order in h by the third point. Every trilinear cell touching the
 * object then has all eight corners solved, so phi and B interpolate to second order anywhere on
 * the surface (tests/diffusion/test_diffusion.c: slab and sphere closed forms).
 *
 * The linear system is kept as a sparse matrix whose entries are affine in the per-node
 * parameters (D, mu): that gives the adjoint gradients of the inverse problem (inverse.c)
 * exactly. Solves are BiCGSTAB with a Jacobi preconditioner (the ghost rows make the matrix
 * non-symmetric), coarse-to-fine over grids of spacing 4h, 2h, h (seed 001 Sec. 5.3, the
 * N-cycle without V-cycles), and warm-started from the previous solution when one is given
 * (seed 001 Sec. 5.3: "the rendering result of the last frame").
 *
 * Units: mm, mm^-1, irradiance per unit light intensity.
 */
#ifndef LR_DGRID_H
#define LR_DGRID_H

#include <stdbool.h>
#include <stddef.h>

#include "render/base/cancel.h"
#include "render/base/err.h"
#include "render/base/vec3.h"
#include "render/mesh/bvh.h"

/* ---- Shapes the grid is built over (shape.c) --------------------------------------------- */

/* A shape: whether p is inside, and the closest surface point b of p with the outward face
 * normal there (false when no surface point is within max_dist). The grid's normals at nodes
 * off the surface are +-normalize(p - b), exact for the closest point. */
typedef bool (*lr_dshape_inside_fn)(const void *ctx, lr_vec3 p);
typedef bool (*lr_dshape_closest_fn)(const void *ctx, lr_vec3 p, double max_dist, lr_vec3 *b,
                                     lr_vec3 *n_face);
/* Optional: the z of every surface crossing of the vertical line through (x, y), ascending,
 * at most max; returns the count (the grid builder then classifies a whole column with one
 * cast instead of one per node). */
typedef int (*lr_dshape_column_fn)(const void *ctx, double x, double y, double *z, int max);
typedef struct lr_dshape {
    lr_dshape_inside_fn inside;
    lr_dshape_closest_fn closest;
    const void *ctx;
    lr_vec3 lo, hi; /* bounds of the object */
    lr_dshape_column_fn column; /* NULL: inside() per node */
} lr_dshape;

/* A sphere (tests, closed forms). ctx points at the sphere, which must outlive the shape. */
typedef struct lr_dsphere {
    lr_vec3 c;
    double r;
} lr_dsphere;
lr_dshape lr_dshape_sphere(const lr_dsphere *s);
/* A slab 0 < z < thickness, infinite in x and y (tests: the grid is one node wide in x and y
 * and the array's x/y ends are zero-flux, so the problem is 1-D). */
typedef struct lr_dslab {
    double thickness;
} lr_dslab;
lr_dshape lr_dshape_slab(const lr_dslab *s);
/* An axis-aligned box (the inverse problem's block samples, seed 001 Sec. 4.1). */
typedef struct lr_dbox {
    lr_vec3 lo, hi;
} lr_dbox;
lr_dshape lr_dshape_box(const lr_dbox *b);
/* A closed mesh through its BVH (which must outlive the shape). Inside: parity of the crossings
 * of a ray from p along a fixed direction just off +z (coincident hits on a shared edge count
 * once). */
lr_dshape lr_dshape_mesh(const lr_bvh *bvh);

/* ---- The grid (grid.c) ------------------------------------------------------------------- */

enum lr_dnode_kind { LR_DNODE_OUT = 0, LR_DNODE_IN = 1, LR_DNODE_GHOST = 2 };

typedef struct lr_dgrid lr_dgrid;

/* Grid of spacing h over the shape's bounds plus a margin of 3 nodes. Rejects h not finite or
 * <= 0, a grid over LR_DGRID_MAX_NODES nodes, and a shape with no inside node (field "h"). */
#define LR_DGRID_MAX_NODES (8u * 1024u * 1024u)
int lr_dgrid_create(const lr_dshape *s, double h, lr_dgrid **out, lr_err *e);
/* Grid with an explicit box: nodes at origin + h (i, j, k), dims n[3]. */
int lr_dgrid_create_box(const lr_dshape *s, lr_vec3 origin, double h, const int n[3],
                        lr_dgrid **out, lr_err *e);
void lr_dgrid_destroy(lr_dgrid *g);

double lr_dgrid_h(const lr_dgrid *g);
void lr_dgrid_dims(const lr_dgrid *g, int n[3]);
lr_vec3 lr_dgrid_origin(const lr_dgrid *g);
size_t lr_dgrid_node_count(const lr_dgrid *g);    /* nx ny nz */
size_t lr_dgrid_inside_count(const lr_dgrid *g);  /* parameters per band */
size_t lr_dgrid_unknown_count(const lr_dgrid *g); /* inside + ghost */
enum lr_dnode_kind lr_dgrid_kind(const lr_dgrid *g, size_t node);
lr_vec3 lr_dgrid_node_pos(const lr_dgrid *g, size_t node);
/* Unknown index of a node (inside or ghost), or -1. */
long lr_dgrid_unknown(const lr_dgrid *g, size_t node);
/* Grid node of an unknown. */
size_t lr_dgrid_unknown_node(const lr_dgrid *g, size_t u);
/* Parameter index (0 .. inside_count-1) of an inside node's unknown; a ghost's owner (the inside
 * node whose D the boundary condition uses); -1 for outside nodes. */
long lr_dgrid_param(const lr_dgrid *g, size_t node);
/* Position of parameter p's node. */
lr_vec3 lr_dgrid_param_pos(const lr_dgrid *g, size_t p);
/* Ghost data: the surface point, outward normal and the ghost's distance outside. False for
 * a node that is not a ghost. */
bool lr_dgrid_ghost(const lr_dgrid *g, size_t node, lr_vec3 *b, lr_vec3 *n, double *t);
size_t lr_dgrid_ghost_count(const lr_dgrid *g);
/* The ghost's surface point by ghost number (0 .. ghost_count-1) and its unknown index. */
void lr_dgrid_ghost_at(const lr_dgrid *g, size_t k, lr_vec3 *b, lr_vec3 *n, size_t *unknown);

/* Trilinear weights of point p over the unknowns: up to 8 (index, weight) pairs, renormalised
 * over the corners that are unknowns (outside corners dropped); returns the count (0: no
 * corner is an unknown). Corners beyond the array are clamped to it. */
int lr_dgrid_trilinear(const lr_dgrid *g, lr_vec3 p, size_t idx[8], double w[8]);
/* phi (per unknown) at p by lr_dgrid_trilinear; 0 where no corner is an unknown. */
double lr_dgrid_sample(const lr_dgrid *g, const double *phi, lr_vec3 p);

/* ---- Material per node (volume.c) --------------------------------------------------------- */

/* Per-band coefficient fields over a box: a small text file (format in
 * render/diffusion/README.md), piecewise constant per cell, outside the box clamped. */
typedef struct lr_dvolume lr_dvolume;
int lr_dvolume_load(const char *path, lr_dvolume **out, lr_err *e);
int lr_dvolume_parse(const char *text, const char *name, lr_dvolume **out, lr_err *e);
void lr_dvolume_destroy(lr_dvolume *v);
/* sigma_a and sigma_s' at p (mm, the object's frame). */
void lr_dvolume_at(const lr_dvolume *v, lr_vec3 p, double sigma_a[3], double sigma_s_prime[3]);
int lr_dvolume_region_count(const lr_dvolume *v);

/* ---- The system and its solve (system.c, solve.c) ----------------------------------------- */

typedef struct lr_dsystem lr_dsystem;

/* eta: the medium's relative index (A and F_dr). */
int lr_dsystem_create(const lr_dgrid *g, double eta, lr_dsystem **out, lr_err *e);
/* A copy of s with its own values and parameters: the pattern and the coefficient terms do not
 * depend on the parameters, so the solver assembles each level once and copies it per band. */
int lr_dsystem_clone(const lr_dsystem *s, lr_dsystem **out, lr_err *e);
void lr_dsystem_destroy(lr_dsystem *s);
const lr_dgrid *lr_dsystem_grid(const lr_dsystem *s);
double lr_dsystem_A(const lr_dsystem *s);
double lr_dsystem_Fdr(const lr_dsystem *s);
/* Sets the per-parameter D (mm) and mu (mm^-1), each inside_count long, all finite, D > 0,
 * mu >= 0 (else LR_EINVAL naming the node). */
int lr_dsystem_set_params(lr_dsystem *s, const double *D, const double *mu, lr_err *e);
const double *lr_dsystem_D(const lr_dsystem *s);
const double *lr_dsystem_mu(const lr_dsystem *s);
/* Right-hand side of the ghost rows from q at each ghost's surface point (ghost_count values):
 * rhs (unknown_count values) = 4 q / (1 - F_dr) on ghost rows, 0 elsewhere. */
void lr_dsystem_rhs(const lr_dsystem *s, const double *q_ghost, double *rhs);
/* y = M x and y = M^T x. */
void lr_dsystem_apply(const lr_dsystem *s, const double *x, double *y);
void lr_dsystem_apply_t(const lr_dsystem *s, const double *x, double *y);
/* Solves M x = b (transpose: M^T x = b) to relative residual tol, x holding the initial guess.
 * Returns LR_OK, or LR_EINVAL when it does not converge in max_iter (message: the residual
 * reached); *iters may be NULL. */
int lr_dsystem_solve(const lr_dsystem *s, bool transpose, const double *b, double *x,
                     double tol, int max_iter, int *iters, lr_err *e);
/* The same, polling `cancel` (may be NULL) between iterations: LR_ECANCELED once requested, x
 * then a partial iterate to be discarded. */
int lr_dsystem_solve_cancel(const lr_dsystem *s, bool transpose, const double *b, double *x,
                            double tol, int max_iter, int *iters, const lr_cancel *cancel,
                            lr_err *e);
/* Gradient accumulation for the adjoint method: for objective F with M phi = rhs and
 * M^T lambda = dF/dphi, dF/dD_p += -sum lambda^T (dM/dD_p) phi, same for mu. */
void lr_dsystem_grad(const lr_dsystem *s, const double *lambda, const double *phi,
                     double *grad_D, double *grad_mu);
/* phi on the surface at a ghost's point (the quadratic of the ghost row) and
 * B = (phi - 2 q)/(2 A) there. */
double lr_dsystem_ghost_phi(const lr_dsystem *s, size_t ghost, const double *phi);
/* Linear weights of phi(b_ghost): up to LR_DGHOST_MAX_W (unknown, weight) pairs; returns the
 * count. */
#define LR_DGHOST_MAX_W 55
int lr_dsystem_ghost_phi_weights(const lr_dsystem *s, size_t ghost, size_t idx[LR_DGHOST_MAX_W],
                                 double w[LR_DGHOST_MAX_W]);

/* ---- Coarse-to-fine solver for one object (solver.c) -------------------------------------- */

/* Per-band material as a function of position: homogeneous, or from a volume. */
typedef struct lr_dmaterial {
    double sigma_a[3], sigma_s_prime[3]; /* homogeneous values (volume == NULL) */
    double eta;
    const lr_dvolume *volume;            /* optional, in the shape's frame */
} lr_dmaterial;

/* Transmitted irradiance q(b) for a unit-intensity light at surface point b, normal n (out):
 * E cos / r^2 times F_t and visibility; the caller's light model. */
typedef double (*lr_dirradiance_fn)(const void *ctx, lr_vec3 b, lr_vec3 n);
/* The same per band (q[0..2]): a source that is not one light's, e.g. the light an object's
 * own emission sends back into it across a cavity (render/diffusion/bounce.c). */
typedef void (*lr_dirradiance_rgb_fn)(const void *ctx, lr_vec3 b, lr_vec3 n, double q[3]);

typedef struct lr_dsolver lr_dsolver;
/* Levels: grids of spacing h 2^(levels-1) .. h (levels 1..4). */
int lr_dsolver_create(const lr_dshape *s, double h, int levels, const lr_dmaterial *m,
                      lr_dsolver **out, lr_err *e);
void lr_dsolver_destroy(lr_dsolver *s);
const lr_dgrid *lr_dsolver_grid(const lr_dsolver *s);
const lr_dsystem *lr_dsolver_system(const lr_dsolver *s, int band);
/* Solves the three bands for one light: phi per band (unknown_count each) in the solver's slot
 * `slot` (0..LR_DSOLVER_SLOTS-1, one per light), warm-started from the slot's last solution
 * when it has one (then the coarse levels are skipped). tol: relative residual. */
#define LR_DSOLVER_SLOTS 8
int lr_dsolver_solve(lr_dsolver *s, int slot, lr_dirradiance_fn q, const void *qctx, double tol,
                     lr_err *e);
/* The same with a source per band. */
int lr_dsolver_solve_rgb(lr_dsolver *s, int slot, lr_dirradiance_rgb_fn q, const void *qctx,
                         double tol, lr_err *e);
/* New coefficients on the same grids (a material edit, seed 001 Sec. 5.4): the slots' last
 * solutions stay as warm starts. */
int lr_dsolver_set_material(lr_dsolver *s, const lr_dmaterial *m, lr_err *e);
/* Polled by the solves from now on (NULL: never cancelled; render/base/cancel.h). A cancelled
 * solve returns LR_ECANCELED; its partial iterate stays in the slot as the next solve's warm
 * start (a failed solve forgets the slot). */
void lr_dsolver_set_cancel(lr_dsolver *s, const lr_cancel *cancel);
/* Forgets the slot's solution (the next solve starts coarse-to-fine). */
void lr_dsolver_reset(lr_dsolver *s, int slot);
const double *lr_dsolver_phi(const lr_dsolver *s, int slot, int band);
/* BiCGSTAB iterations of the last solve on the finest grid (sum over bands). */
int lr_dsolver_last_iters(const lr_dsolver *s);

/* ---- Surface radiosity field (field.c) ---------------------------------------------------- */

/* B per node near the surface for the renderer: every inside or ghost node within 1.75 h of
 * the surface gets B at its closest surface point b, (phi(b) - 2 q(b)) / (2 A) with phi(b)
 * trilinear; others are invalid. out: 4 floats per grid node (B_r, B_g, B_b, valid 0/1),
 * x fastest. */
int lr_dsolver_field(const lr_dsolver *s, int slot, lr_dirradiance_fn q, const void *qctx,
                     float *out, lr_err *e);
/* The same with the slot's source per band (lr_dsolver_solve_rgb). */
int lr_dsolver_field_rgb(const lr_dsolver *s, int slot, lr_dirradiance_rgb_fn q,
                         const void *qctx, float *out, lr_err *e);
/* Trilinear evaluation of such a field at p (renormalised over valid corners; 0 when none):
 * what the GLSL pass does (render/shaders/lib/dgrid.glsl). */
void lr_dfield_eval(const float *field, const int n[3], lr_vec3 origin, double h, lr_vec3 p,
                    double out[3]);

#endif
