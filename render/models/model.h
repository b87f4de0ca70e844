/* lamprig — the per-object models: one ops table each, one registry (render/models/registry.c).
 *
 * An object's model is the light transport inside its material: which B(x_o, n_o) the map
 * pass, the CPU twin and the light paths see for it. Each model is a folder under
 * render/models/ defining one `const lr_model_ops` (its name, what sets it apart, its profile
 * S_d on the CPU, its GLSL, its limits); registry.c is the only list of them and
 * `enum lr_sss_model` their ids, in the registry's order. Code outside render/models/ asks the
 * table (lr_model_of, lr_sss_model_props_of, the lr_sss_* evaluations below) and never compares
 * an id: `make test` fails on such a comparison (tests/base/test_layers.c).
 *
 * The table shape follows hal/dev_impl.h: a struct of properties and function pointers, NULL
 * where a model has nothing to say (the caller's default is written next to each member).
 */
#ifndef LR_MODELS_MODEL_H
#define LR_MODELS_MODEL_H

#include <stdbool.h>
#include <stddef.h>

#include "render/base/err.h"
#include "render/base/vec3.h"
#include "render/optics/optics.h"

struct lr_scene_object; /* render/scene/scene.h: the object a hook is asked about */

/* The ids, in registry.c's order (the scene's objects[i].model names them). */
enum lr_sss_model {
    LR_SSS_DIRECTIONAL_DIPOLE = 0, /* seed 003's choice [14]: profile/directional_dipole.c */
    LR_SSS_STANDARD_DIPOLE = 1,    /* Jensen et al. 2001, for comparison (seed 003 Fig. 6) */
    LR_SSS_MULTIPOLE = 2,          /* Donner & Jensen 2005, thin walls (thickness_mm) */
    LR_SSS_TRANSLUCENT_RADIOSITY = 3, /* seed 000's patch solve: translucent_radiosity/ */
    LR_SSS_DIFFUSION_GRID = 4,        /* seed 001's grid: diffusion_grid/ */
    LR_SSS_SH_TRANSLUCENCY = 5,       /* seed 002: sh_translucency/ */
};
#define LR_SSS_MODEL_COUNT 6

/* What sets a model apart, for the code that treats models differently. All-zero is a BSSRDF
 * profile model like the dipoles: an S_d, any mesh, evaluated on the GPU frame by frame, the
 * cavity closure and the openings apply. */
typedef struct lr_sss_model_props {
    /* No S_d profile: lr_sss_sd_fresnel gives 0 and the passes read the model's own B (the
     * grid's solved field, the SH evaluation). */
    bool no_profile;
    /* Why the model renders only with the object's thickness_mm, or only on a closed mesh
     * (lr_scene_object_model_unmet returns these; the scene refuses the model without them);
     * NULL: it does not need it. */
    const char *needs_thickness;
    const char *needs_closed;
    /* Why the one-gain cavity closure (render/core/cavity.h) does not apply to it; NULL: it
     * applies. raw_no_closure: the same for the object's raw (unnormalised) profile only. */
    const char *no_closure;
    const char *raw_no_closure;
    /* Why the light its inner faces send through the openings is not gathered for it
     * (render/openings); NULL: it is (its B is known at any point: the profile sampler's, or
     * the grid's solved field). */
    const char *no_openings;
    /* Why a material change costs a CPU solve before its first image (seconds on the proxy,
     * configs/bench/models.csv); NULL: the model is evaluated on the GPU frame by frame. */
    const char *solves;
    /* The largest sigma_tr = sqrt(3 sigma_a (sigma_a + sigma_s')), mm^-1, in any band, at which
     * the model's numerics hold, and why (lr_sss_model_check_medium); 0: no limit of its own
     * beyond lr_medium_validate's. */
    double max_sigma_tr;
    const char *max_sigma_tr_why;
    /* Where its B comes from, when not from the profile sampler:
     *   patch_solve  the scene's patch system (render/transrad/tr_scene.h), receivers in F: the
     *                scene's receiver bounce and openings are its own, not the paths';
     *   grid_field   the diffusion grid's solved field (render/diffusion/dscene.h);
     *   light_env    each light's environment through the G-buffer cameras (SH, seed 002). */
    bool patch_solve, grid_field, light_env;
    /* Its profile models a slab of the object's thickness_mm (the multipole's pole pairs, on
     * the GPU too); measures_thickness: where the object gives none, the wall is measured per
     * patch by ray (render/transrad/subsurface.c). */
    bool slab, measures_thickness;
} lr_sss_model_props;

/* One model. */
typedef struct lr_model_ops {
    const char *name; /* the scene's "model" value */
    lr_sss_model_props props;
    /* The profile it evaluates for an object of wall thickness_mm (0: none given), when that
     * is another model's (translucent radiosity: the multipole with a wall, else the standard
     * dipole); NULL: its own. */
    enum lr_sss_model (*profile)(double thickness_mm);
    /* S_d F_t(w_i), the integrand of seed 003 Eq. 4 with this diffusion term, per band;
     * pairs from the pairs hook. NULL for a model without a profile of its own. */
    void (*sd_fresnel)(const lr_coeffs *c, double thickness_mm, int pairs, lr_vec3 xi,
                       lr_vec3 ni, lr_vec3 wi, lr_vec3 xo, lr_vec3 no, double out[3]);
    /* The multipole's pole-pair count for the thickness; NULL: 0. */
    int (*pairs)(const lr_coeffs *c, double thickness_mm);
    /* Power let out per unit power in when nothing comes back (the cavity closure's A);
     * NULL: the standard dipole's half-space lr_dipole_rd_total. */
    void (*total)(const lr_coeffs *c, double thickness_mm, double out[3]);
    /* The per-band factor S_d is scaled by (PIPELINE.md "Energy"); NULL: 1. */
    double (*sd_norm)(const lr_coeffs *c, int band);
    /* Why the model is outside its validity limit for object o's current material (a knob or
     * preset may give the object another), written into buf and returned; NULL (the hook or
     * its result): within it. The planner leaves such a model out (render/plan/limits.h). */
    const char *(*limit)(const struct lr_scene_object *o, char *buf, size_t cap);
    /* GLSL, spliced into the generated dispatch (lr_models_glsl_defines):
     *   glsl_sd  an expression in (c, s, j, xi, ni, wi, xo, no) giving band j's S_d
     *            (render/shaders/lib/optics.glsl); NULL: 0.0 (no profile);
     *   glsl_B   an expression in (obj, mat, xo, no) giving the model's own vec3 B in the map
     *            pass (render/shaders/radiosity.frag); NULL: the estimator's. */
    const char *glsl_sd;
    const char *glsl_B;
} lr_model_ops;

/* The model's table; NULL for a value outside the enum. */
const lr_model_ops *lr_model_of(enum lr_sss_model m);

/* "directional_dipole", "standard_dipole", "multipole", "translucent_radiosity",
 * "diffusion_grid", "sh_translucency"; "?" outside the enum. */
const char *lr_sss_model_name(enum lr_sss_model m);
/* Inverse of lr_sss_model_name; false for any other text. */
bool lr_sss_model_parse(const char *name, enum lr_sss_model *out);
/* The model's properties; an all-zero row for a value outside the enum. */
const lr_sss_model_props *lr_sss_model_props_of(enum lr_sss_model m);
/* The model whose profile m evaluates at that thickness (m itself but for translucent
 * radiosity). */
enum lr_sss_model lr_sss_profile_of(enum lr_sss_model m, double thickness_mm);
/* S_d F_t(w_i) of the model's profile at thickness_mm: the integrand of seed 003 Eq. 4 with
 * that diffusion term; 0 for a model without a profile. */
void lr_sss_sd_fresnel(enum lr_sss_model m, const lr_coeffs *c, double thickness_mm, lr_vec3 xi,
                       lr_vec3 ni, lr_vec3 wi, lr_vec3 xo, lr_vec3 no, double out[3]);
/* The same with the pole-pair count given (lr_sss_pairs, once per object and thickness). */
void lr_sss_sd_fresnel_n(enum lr_sss_model m, const lr_coeffs *c, double thickness_mm, int pairs,
                         lr_vec3 xi, lr_vec3 ni, lr_vec3 wi, lr_vec3 xo, lr_vec3 no,
                         double out[3]);
/* The pole-pair count lr_sss_sd_fresnel_n wants: lr_multipole_pairs for a slab profile, 0
 * otherwise. */
int lr_sss_pairs(enum lr_sss_model m, const lr_coeffs *c, double thickness_mm);
/* Power the model lets out per unit power that entered, per band, when nothing comes back:
 * the multipole's R_total + T_total (lr_multipole_total), the standard dipole's
 * lr_dipole_rd_total for the two dipoles (the normalised directional dipole's half-space
 * total, PIPELINE.md "Energy"). The cavity closure's A (render/core/cavity.h). */
void lr_sss_total(enum lr_sss_model m, const lr_coeffs *c, double thickness_mm, double out[3]);
/* S_d's per-band normalisation for an object of model m with coefficients c (1 when raw). */
double lr_sss_sd_norm(enum lr_sss_model m, const lr_coeffs *c, bool raw, int band);
/* Whether model m holds medium med (already through lr_medium_validate): LR_OK, or LR_EINVAL
 * with "sigma_a = A, sigma_s_prime = S (BAND): sigma_tr = sqrt(3 sigma_a (sigma_a +
 * sigma_s_prime)) = T /mm, outside MODEL's valid range sigma_tr <= MAX /mm (WHY)" for the first
 * band over the row's max_sigma_tr. The scene's loader and lr_scene_set refuse such a material
 * or model change with it; the planner leaves the model out (render/plan/limits.h). */
int lr_sss_model_check_medium(enum lr_sss_model m, const lr_medium *med, lr_err *e);

/* The GLSL dispatch generated from the registry, as "NAME(ARGS) BODY" define lines for the
 * shader loader (render/gl/shader.h), written into buf (cap bytes, NUL-separated lines) with
 * their starts in lines[0..n-1]:
 *   LR_MODEL_SD_BAND(c, s, j, xi, ni, wi, xo, no)  band j's S_d of material s's model
 *   LR_MODEL_HAS_B(m)                              whether model m gives its own B
 *   LR_MODEL_B(m, obj, mat, xo, no)                that B
 * Returns n (3), or -1 when buf or lines is too small. */
#define LR_MODELS_GLSL_DEFINES 3
int lr_models_glsl_defines(char *buf, size_t cap, const char **lines, int max_lines);

#endif
