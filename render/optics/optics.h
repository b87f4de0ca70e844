/* lamprig — optics: the formulas every renderer, CPU twin, bench and fit evaluates.
 *
 * Pure C, double precision, no GL. The GLSL versions under render/ are tested against these.
 * Units: millimetres; sigma_* in mm^-1; radiometry linear. Colour is three bands (R, G, B),
 * each carried independently as in seed 003 Sec. 3.1.
 *
 * Conventions
 *   eta          relative index of refraction n_inside / n_outside of the medium (1.3 skin,
 *                1.5 marble); eta < 1 is allowed (a medium optically thinner than outside).
 *   directions   unit vectors; w_i points from x_i toward the light (as in seed 003 Eq. 1),
 *                normals point out of the medium.
 */
#ifndef LR_OPTICS_H
#define LR_OPTICS_H

#include "render/base/err.h"
#include "render/base/vec3.h"

/* ---- Fresnel (fresnel.c) --------------------------------------------------------------- */

/* Exact unpolarised dielectric reflectance for light arriving with cosine cos_i (>= 0, taken
 * from the incident side) at an interface where eta = n_transmitted / n_incident. Returns 1
 * under total internal reflection (eta < 1 and sin_t > 1). */
double lr_fresnel_reflectance(double cos_i, double eta);
/* 1 - reflectance. */
double lr_fresnel_transmittance(double cos_i, double eta);
/* Diffuse Fresnel moments C_n(eta) = integral_0^{pi/2} of R(cos) cos^n sin, times 2 and 3 for
 * n = 1, 2 (d'Eon & Irving 2011 polynomial fits, as used by the directional dipole [14]);
 * 2*C1 is the hemispherical (diffuse) Fresnel reflectance. */
double lr_fresnel_moment1(double eta);
double lr_fresnel_moment2(double eta);
/* Diffuse reflectance F_dr(eta) of Egan & Hilgeman as used by Jensen et al. 2001 (Eq. 8 there). */
double lr_fresnel_diffuse_reflectance(double eta);

/* ---- Medium and derived coefficients (medium.c) ---------------------------------------- */

typedef struct lr_medium {
    double sigma_a[3];       /* absorption, mm^-1 */
    double sigma_s_prime[3]; /* reduced scattering sigma_s (1 - g), mm^-1 */
    double eta;              /* relative index of refraction, inside / outside */
    double g;                /* Henyey-Greenstein mean cosine; sigma_s = sigma_s' / (1 - g) */
} lr_medium;

/* Per-band coefficients derived once per material (seed 003 Eq. 10; Jensen 2001; [14]). */
typedef struct lr_coeffs {
    double sigma_t_prime[3]; /* sigma_a + sigma_s' */
    double albedo_prime[3];  /* sigma_s' / sigma_t' */
    double sigma_tr[3];      /* sqrt(3 sigma_a sigma_t'), seed 003 Eq. 10 */
    double D[3];             /* diffusion coefficient 1 / (3 sigma_t') */
    double mfp[3];           /* reduced mean free path 1 / sigma_t' */
    double z_r[3], z_v[3];   /* standard dipole source depths (Jensen 2001) */
    double A;                /* standard dipole boundary constant (1 + F_dr) / (1 - F_dr) */
    /* directional dipole [14] */
    double de[3];            /* extrapolation distance 2.131 D / sqrt(albedo') */
    double sigma_t[3];       /* sigma_a + sigma_s (uses g) */
    double C_phi_norm, C_phi, C_E, A_dir;
    double eta;
} lr_coeffs;

/* Rejects NaN, Inf, negative coefficients, sigma_t' == 0, eta <= 0 and g outside (-1, 1)
 * with LR_EINVAL and a message naming the field and band. */
int lr_medium_validate(const lr_medium *m, lr_err *e);
int lr_coeffs_derive(const lr_medium *m, lr_coeffs *out, lr_err *e);

/* ---- Standard dipole, Jensen et al. 2001 (dipole.c) ------------------------------------ */

/* Diffuse reflectance profile R_d(r) per band, mm^-2; finite as r -> 0. */
void lr_dipole_rd(const lr_coeffs *c, double r, double out[3]);
/* Closed-form total diffuse reflectance integral_0^inf 2 pi r R_d(r) dr per band. */
void lr_dipole_rd_total(const lr_coeffs *c, double out[3]);

/* ---- Directional dipole, Frisvad, Hachisuka, Kjeldsen 2014 (dirpole.c) ----------------- */

/* S_d(x_i, n_i, w_i; x_o, n_o) per band, mm^-2 sr^-1, without boundary Fresnel transmission.
 * Clamped to >= 0 as in [14]; finite for x_i == x_o. */
void lr_dirpole_sd(const lr_coeffs *c, lr_vec3 xi, lr_vec3 ni, lr_vec3 wi, lr_vec3 xo,
                   lr_vec3 no, double out[3]);
/* The same times the incident boundary transmission F_t(w_i) (the integrand of seed 003 Eq. 4). */
void lr_dirpole_sd_fresnel(const lr_coeffs *c, lr_vec3 xi, lr_vec3 ni, lr_vec3 wi, lr_vec3 xo,
                           lr_vec3 no, double out[3]);

/* ---- Sampling (sampling.c) ------------------------------------------------------------- */

/* Exponential radius sampling of seed 003 Eq. 11-12, truncated to [0, r_max] so that
 * sigma_tr -> 0 (albedo -> 1) stays finite: r_max = INFINITY gives Eq. 12 exactly, and
 * sigma_tr == 0 gives the uniform density on [0, r_max]. xi in [0, 1). */
double lr_exp_radius_sample(double sigma_tr, double r_max, double xi);
/* Its density p(r); the joint density of Eq. 11 is p(r) / (2 pi). */
double lr_exp_radius_pdf(double sigma_tr, double r_max, double r);
/* Radical inverse of index in the given prime base (Halton sequence). */
double lr_halton(unsigned index, unsigned base);
/* Quasi-random unit direction on the sphere from Halton bases 2 and 3 (map directions). */
lr_vec3 lr_halton_sphere(unsigned index);

/* ---- Spherical harmonics, l <= 2 (sh.c) ------------------------------------------------ */

/* The 9 real SH basis functions Y_lm(dir), ordered (0,0),(1,-1),(1,0),(1,1),(2,-2)..(2,2). */
void lr_sh9_basis(lr_vec3 dir, double out[9]);
/* Irradiance E(n) from radiance SH coefficients L_lm (seed 002 Eq. 10-11, after Ramamoorthi
 * & Hanrahan 2001): sum of A_l L_lm Y_lm(n), A_0 = pi, A_1 = 2pi/3, A_2 = pi/4. */
double lr_sh9_irradiance(const double coeffs[9], lr_vec3 n);

#endif
