/* lamprig — seed 002 (Banterle & Chalmers), the `sh_translucency` model: the cheapest tier.
 *
 * Two steps per light and object (seed 002 Sec. 2):
 *   accumulation  the light that enters the object, read from the light's own G-buffer texel by
 *                 texel, is projected on the 9 real SH of l <= 2 (Eq. 6-9) as a function of the
 *                 direction it travels after refraction at x_in (the paper's "refracted
 *                 direction"), weighted by its transmitted power F_t(w_in) dPhi and normalised by
 *                 the lit area: E_lm = sum_texels F_t dPhi Y_lm(t_in) / sum_texels dA.
 *                 So for a uniformly lit face E(n) below is the entering irradiance F_t E_0.
 *   evaluation    B(x_out) = s_c a_c(d) E(n_out), with E(n) = sum A_l E_lm Y_lm(n) the clamped-
 *                 cosine convolution (Eq. 10-11, lr_sh9_irradiance) evaluated along n_out (light
 *                 travelling along n_out leaves through x_out: the reverse of the view ray's
 *                 refracted direction at normal exit, the mean of a diffuse exit; the maps are
 *                 view-independent), clamped >= 0 (l <= 2 rings negative), d the thickness the
 *                 light crossed, from the G-buffer (Sec. 2.2: "shadow map" depth), a_c the
 *                 attenuation below and s_c the material's fitted energy scale.
 *
 * Attenuation. Eq. 12's factor k(d) = (sigma_tr d + 1) e^{-sigma_tr d} / (sigma_t' d^3) is the
 * dipole's point-to-point kernel without its source-depth factor z; the paper multiplies it
 * into a B that is the whole accumulated light. With E normalised per lit area (above), the
 * matching factor is Eq. 12's kernel with z = d restored, integrated over the lit face:
 *     int_plane d k(sqrt(d^2 + rho^2)) dA = 2 pi e^{-sigma_tr d} / sigma_t'   (closed form),
 * and a_c(d) = e^{-sigma_tr d} is that over its d-independent constant 2 pi / sigma_t' (which
 * the fitted scale absorbs). Eq. 12 taken literally with one scale cannot follow a slab's
 * transmission: from 10 to 5 and 20 mm of candle wax it is off by factors of about 5
 * (tests/optics/test_optics_sh_translucency.c shows both). d is clamped below at one transport
 * mean free path 1/sigma_t' (the dipole's real source depth; Eq. 12's d^-3 then stays finite).
 *
 * Direct term. The paper's images are its scattering term over the object's ordinary direct
 * lighting (seed 002 Fig. 10, 11: "direct lighting only" / "subsurface scattering"); the maps
 * hold all of an object's radiosity, so the model adds the local diffuse reflection
 * B_direct,c = rho_c F_t(cos_i) E_direct(x_o) where x_o is the light's first surface (the
 * G-buffer texel's normal on x_o's side and the thickness under LR_SH_LIT_RADII bounding radii
 * plus one mean free path), rho_c the dipole's total diffuse reflectance (lr_dipole_rd_total,
 * what the normalised directional dipole gives a lit half-space).
 *
 * Energy scale. s_c = T_c(d_fit) / (LR_SH_DELTA_GAIN a_c(d_fit)): the slab's total diffuse transmission T per unit
 * power that entered (lr_multipole_total, the closed form the multipole tests check against
 * the photon-counted slab) at d_fit = LR_SH_FIT_MM, so that a slab of that thickness lit
 * uniformly gets the physical transmitted radiosity. Stored per band with the material preset
 * ("sh_scale"); lr_sh_fit_scale computes it.
 */
#ifndef LR_SH_TRANSLUCENCY_H
#define LR_SH_TRANSLUCENCY_H

#include <stdbool.h>

#include "render/optics/optics.h"

/* What the l <= 2 projection makes of light that all travels one way (a slab lit at normal
 * incidence): along that direction sum_l A_l (2l + 1) / (4 pi) = 1/4 + 1/2 + 5/16 = 17/16 of
 * the entering irradiance. The fit divides it out. */
#define LR_SH_DELTA_GAIN (17.0 / 16.0)
/* A point is the light's first surface (direct term) when its thickness is under this many
 * bounding radii plus the band-averaged mean free path (absorbs the G-buffer's quantised
 * depth) and the G-buffer's normal there faces x_o's side. */
#define LR_SH_LIT_RADII 0.02
/* Slab thickness (mm) at which the energy scale is fitted. */
#define LR_SH_FIT_MM 10.0
/* Texels whose surface is seen more grazing than this cosine are left out of the projection
 * (their area dPhi d^2 / cos blows up while their power F_t cos-> 0). */
#define LR_SH_MIN_COS 1e-3

/* The accumulated light of one object for one light (grey: F_t and the geometry do not depend
 * on the band; the band enters through a_c and s_c). */
typedef struct lr_sh_env {
    double E[9];  /* sum F_t dPhi Y_lm(t_in) (after lr_sh_env_finish: divided by area) */
    double power; /* sum F_t dPhi: power that entered per unit light intensity (W per W/sr) */
    double area;  /* sum dA: lit area, mm^2 */
} lr_sh_env;

void lr_sh_env_clear(lr_sh_env *env);
/* One G-buffer texel (seed 002 Eq. 6 as a quadrature): the light travels along unit v and
 * meets the surface at a point with unit outward normal n_i; `flux` is the power that arrives
 * on the texel per unit light intensity (point/spot: its solid angle times the spot profile;
 * directional: its area in the light's plane), `area` its surface area (flux d^2 / cos_i,
 * directional flux / cos_i). Texels with cos_i = -v.n_i <= LR_SH_MIN_COS are skipped. */
void lr_sh_env_add(lr_sh_env *env, lr_vec3 v, lr_vec3 n_i, double flux, double area, double eta);
/* E_lm /= area (all zero when nothing was lit). */
void lr_sh_env_finish(lr_sh_env *env);
/* max(0, sum A_l E_lm Y_lm(n)): seed 002 Eq. 10-11 (Ramamoorthi & Hanrahan's form). */
double lr_sh_env_irradiance(const lr_sh_env *env, lr_vec3 n);

/* Refracted travel direction of light travelling along unit v into a medium of relative index
 * eta through a surface of outward unit normal n (v.n < 0). Under total internal reflection
 * (eta < 1, grazing) returns v reflected, which the F_t = 0 weight then discards. */
lr_vec3 lr_sh_refract(lr_vec3 v, lr_vec3 n, double eta);

/* Eq. 12's thickness factor (sigma_tr d + 1) e^{-sigma_tr d} / (sigma_t' d^3), mm^-2, with d
 * clamped to >= 1 / sigma_t'. */
double lr_sh_eq12(double sigma_tr, double sigma_t_prime, double d);
/* The model's attenuation a(d) = e^{-sigma_tr max(d, 1/sigma_t')} = sigma_t' / (2 pi) times
 * Eq. 12's kernel, with z = d, integrated over the plane at distance d (see above). */
double lr_sh_atten(double sigma_tr, double sigma_t_prime, double d);

/* B_c = scale_c a_c(d) lr_sh_env_irradiance(env, n_out), per band (finished env). */
void lr_sh_translucency_B(const lr_coeffs *c, const double scale[3], const lr_sh_env *env,
                          lr_vec3 n_out, double d, double out[3]);
/* Whether x_o takes the direct term: n_i . n_o > 0 and d <= LR_SH_LIT_RADII radius + mfp
 * (mfp: the mean of the bands' 1/sigma_t'). */
bool lr_sh_lit(const lr_coeffs *c, double radius, double d, double ni_dot_no);
/* rho_c F_t(cos_i, eta) cos_i per band: the direct term for unit irradiance along the normal
 * (times 1/r^2 and the spot profile for point and spot lights); 0 for cos_i <= 0. */
void lr_sh_direct(const lr_coeffs *c, double cos_i, double out[3]);
/* The energy scale s_c = T_c(d_fit) / (LR_SH_DELTA_GAIN a_c(d_fit)) (T: lr_multipole_total). */
void lr_sh_fit_scale(const lr_coeffs *c, double d_fit, double out[3]);
/* The scale an object uses: the preset's when it has one (all three > 0), else fitted here. */
void lr_sh_object_scale(const lr_coeffs *c, const double preset[3], double out[3]);

/* Geometry of the light G-buffer's texel (i, j) of an n x n target drawn with world -> clip
 * matrix vp: its ray (origin and unit direction through the texel centre) and its weight, the
 * solid angle it covers seen from the eye (perspective: cube faces, point and spot maps) or
 * its area in the view plane, mm^2 (ortho: directional lights). Returns false when vp is
 * singular. */
bool lr_sh_texel_ray(const double vp[16], bool ortho, int n, int i, int j, lr_vec3 *org,
                     lr_vec3 *dir, double *weight);

#endif
