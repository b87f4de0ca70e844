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
 *
 * Checking. The hot-path functions (no lr_err argument) do not validate: they assume what their
 * comment says and propagate NaN rather than hide it. Input from files, the CLI or the scene goes
 * through the *_checked / *_validate entry points, which reject NaN, Inf, negative and
 * out-of-range values with LR_EINVAL and a message naming the field (and band).
 */
#ifndef LR_OPTICS_H
#define LR_OPTICS_H

#include <stdbool.h>

#include "render/base/err.h"
#include "render/base/vec3.h"

/* Range of eta accepted for a medium: where the diffuse Fresnel fits below stay within 0.7% of
 * the exact moments (d'Eon & Irving 2011; Egan & Hilgeman for F_dr). The directional dipole also
 * evaluates them at 1/eta, which this symmetric-enough range keeps inside [0.4, 2.5]. */
#define LR_ETA_MIN 0.5
#define LR_ETA_MAX 2.5
/* Accepted range of sigma_t' = sigma_a + sigma_s' (mm^-1): a mean free path between one
 * nanometre and a kilometre. Outside it the dipole distances under/overflow in double. */
#define LR_SIGMA_T_PRIME_MIN 1e-9
#define LR_SIGMA_T_PRIME_MAX 1e9

/* ---- Fresnel (fresnel.c) --------------------------------------------------------------- */

/* Exact unpolarised dielectric reflectance for light arriving with cosine cos_i (taken from the
 * incident side, clamped to [0, 1]) at an interface where eta = n_transmitted / n_incident
 * (finite, > 0). Returns 1 under total internal reflection (eta < 1 and sin_t >= 1), 1 at
 * grazing incidence (cos_i = 0, eta != 1) and 0 for eta == 1 (index-matched: no interface). */
double lr_fresnel_reflectance(double cos_i, double eta);
/* 1 - reflectance. */
double lr_fresnel_transmittance(double cos_i, double eta);
/* Checked form: rejects NaN/Inf, cos_i outside [0, 1] and eta <= 0 (fields "cos_i", "eta").
 * Either output pointer may be NULL. */
int lr_fresnel_checked(double cos_i, double eta, double *reflectance, double *transmittance,
                       lr_err *e);
/* Diffuse Fresnel moments C_n(eta) = integral_0^1 R(mu; 1/eta) mu^n dmu, n = 1, 2: moments of
 * the reflectance of light hitting the boundary from *inside* a medium of relative index eta
 * (total internal reflection included for eta > 1). d'Eon & Irving 2011 give polynomial fits of
 * 2*C1 and 3*C2 (branches eta < 1 and eta > 1), as used by the directional dipole [14]; these
 * functions return C1 and C2 themselves. 2*C1 is the internal hemispherical (diffuse) Fresnel
 * reflectance. Fit error against the exact integrals on [LR_ETA_MIN, LR_ETA_MAX] (measured,
 * see tests/optics/test_optics_fresnel.c): |2C1| <= 4.4e-3 (worst just above eta = 1), |3C2| <= 7e-3. */
double lr_fresnel_moment1(double eta);
double lr_fresnel_moment2(double eta);
/* Internal diffuse reflectance F_dr(eta) of Egan & Hilgeman as used by Jensen et al. 2001
 * (-1.440/eta^2 + 0.710/eta + 0.668 + 0.0636 eta for eta >= 1; the companion fit
 * -0.4399 + 0.7099/eta - 0.3319/eta^2 + 0.0636/eta^3 for eta < 1). Approximates 2*C1(eta). */
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
    double z_r[3], z_v[3];   /* standard dipole source depths mfp and mfp + 4 A D (Jensen 2001) */
    double A;                /* standard dipole boundary constant (1 + F_dr) / (1 - F_dr) */
    /* directional dipole [14] */
    double de[3];            /* extrapolation distance 2.131 D / sqrt(albedo'); +INFINITY when
                              * albedo' == 0 (the virtual source then contributes nothing) */
    double sigma_t[3];       /* sigma_a + sigma_s (uses g) */
    double C_phi_norm;       /* 1 / (1 - 2 C1(1/eta)) = 1 / (4 C_phi(1/eta)) */
    double C_phi;            /* (1 - 2 C1(eta)) / 4 */
    double C_E;              /* (1 - 3 C2(eta)) / 2 */
    double A_dir;            /* (1 - C_E) / (2 C_phi) */
    double eta;
    /* Energy normalisation of the directional dipole per band (lr_dirpole_energy_norm): the
     * passes multiply S_d by it unless the object asks for the raw model. */
    double sd_norm[3];
    /* lr_hemi_transmittance(eta): composition emits L_o = F_t(w_o) B / pi, whose exitance is
     * t_hem B, so a model whose profile gives the exitance divides by it (PIPELINE.md
     * "Energy"; lr_scene_object_sd_norm). */
    double t_hem;
} lr_coeffs;

/* Rejects NaN, Inf, negative coefficients, sigma_t' outside [LR_SIGMA_T_PRIME_MIN,
 * LR_SIGMA_T_PRIME_MAX] (this includes sigma_t' == 0), eta outside [LR_ETA_MIN, LR_ETA_MAX] and
 * g outside (-1, 1) with LR_EINVAL and a message naming the field and band. */
int lr_medium_validate(const lr_medium *m, lr_err *e);
/* Validates m, then fills *out. On error *out is left untouched. */
int lr_coeffs_derive(const lr_medium *m, lr_coeffs *out, lr_err *e);

/* ---- Standard dipole, Jensen et al. 2001 (dipole.c) ------------------------------------ */

/* Diffuse reflectance profile R_d(r) per band, mm^-2, for r >= 0; finite as r -> 0
 * (R_d(0) uses d_r = z_r, d_v = z_v) and 0 (not NaN) when it underflows. */
void lr_dipole_rd(const lr_coeffs *c, double r, double out[3]);
/* Checked form: rejects r that is NaN, Inf or negative (field "r"). */
int lr_dipole_rd_checked(const lr_coeffs *c, double r, double out[3], lr_err *e);
/* Closed-form total diffuse reflectance integral_0^inf 2 pi r R_d(r) dr per band:
 * (alpha'/2) (1 + exp(-(4/3) A sqrt(3 (1 - alpha')))) exp(-sqrt(3 (1 - alpha'))), with
 * sqrt(3 (1 - alpha')) evaluated as sqrt(3 sigma_a / sigma_t') (no cancellation as alpha' -> 1). */
void lr_dipole_rd_total(const lr_coeffs *c, double out[3]);

/* The standard dipole as a BSSRDF's diffusion term (Jensen et al. 2001, Eq. 5):
 * S_d(x_i, x_o) = R_d(|x_o - x_i|) / pi per band, mm^-2 sr^-1, without the two Fresnel
 * transmission factors (Jensen's S_d = F_t(w_i) R_d F_t(w_o) / pi; composition applies F_t(w_o),
 * seed 003 Eq. 5). Depends on the distance alone: no normals, no incident direction. */
void lr_dipole_sd(const lr_coeffs *c, lr_vec3 xi, lr_vec3 xo, double out[3]);
/* The same times F_t(w_i) = 1 - R(w_i . n_i, eta); 0 when w_i . n_i <= 0. */
void lr_dipole_sd_fresnel(const lr_coeffs *c, lr_vec3 xi, lr_vec3 ni, lr_vec3 wi, lr_vec3 xo,
                          double out[3]);

/* ---- Multipole for a slab, Donner & Jensen 2005 (multipole.c) -------------------------- */

/* A slab of thickness d (mm) with the medium's index on both faces: the standard dipole
 * mirrored about both extrapolated boundaries (z_b = 2 A D, the dipole's own), pole pairs
 * i = -n..n (derivation in multipole.c). The real source sits at min(1/sigma_t', d/2).
 * n = 0 is the standard dipole; d -> inf tends to it (the pairs i != 0 decay as
 * e^{-2 sigma_tr |i| (d + 2 z_b)}).
 *
 * Truncation. n is chosen per material and thickness (lr_multipole_pairs) so that the bound
 * lr_multipole_tail on the poles left out is <= LR_MULTIPOLE_TAIL = 1e-4 of the light that
 * entered, in R_total and in T_total, for every band; at most LR_MULTIPOLE_MAX_PAIRS. Shipped
 * materials: porcelain 1.5 mm n = 2, candle_wax 7 mm n = 8, 14 mm n = 5. Where the cap binds
 * (sigma_tr (d + 2 z_b) below about 0.3: thick, almost non-absorbing slabs; sigma_tr = 0 has no
 * bound at all) the truncated series misses the slab's far field; lr_multipole_tail says by
 * how much at most. */
#define LR_MULTIPOLE_MAX_PAIRS 16
#define LR_MULTIPOLE_TAIL 1e-4
/* Accepted thickness range (mm) for the checked entry points and the scene: a micrometre to
 * ten metres. */
#define LR_MULTIPOLE_D_MIN 1e-3
#define LR_MULTIPOLE_D_MAX 1e4

/* Upper bound on |R_total error| and |T_total error| of band `band` with n pairs:
 * 2 alpha' e^{sigma_tr (L + l)} q^{n+1} / (1 - q), q = e^{-2 sigma_tr L}, L = d + 2 z_b,
 * l = 1/sigma_t'. INFINITY when sigma_tr == 0. */
double lr_multipole_tail(const lr_coeffs *c, int band, double d, int n);
/* The pair count used by the functions below: the smallest n whose tail bound is
 * <= LR_MULTIPOLE_TAIL in every band, capped at LR_MULTIPOLE_MAX_PAIRS. */
int lr_multipole_pairs(const lr_coeffs *c, double d);
/* Diffuse reflectance R(r) (lit face) and transmittance T(r) (far face, r measured from the
 * point below the entry) per band, mm^-2, clamped >= 0. _n: with n pairs given. */
void lr_multipole_profile(const lr_coeffs *c, double d, double r, double R[3], double T[3]);
void lr_multipole_profile_n(const lr_coeffs *c, double d, int n, double r, double R[3],
                            double T[3]);
/* Checked form: rejects NULL, d outside [LR_MULTIPOLE_D_MIN, LR_MULTIPOLE_D_MAX] or not
 * finite (field "thickness_mm") and r NaN, Inf or negative (field "r"). */
int lr_multipole_profile_checked(const lr_coeffs *c, double d, double r, double R[3],
                                 double T[3], lr_err *e);
int lr_multipole_thickness_validate(double d, lr_err *e);
/* Plane totals int 2 pi r R(r) dr and int 2 pi r T(r) dr of the infinite series, in closed
 * form (the slab's 1-D diffusion problem, multipole.c): exact, no truncation; R + T <= alpha'
 * (= 1 at sigma_tr = 0), R -> lr_dipole_rd_total as d -> inf. _n: of the (unclamped) series
 * truncated to n pairs, alpha'/2 sum_i sgn(z) e^{-sigma_tr |z|} over the poles; n = 0 gives
 * lr_dipole_rd_total and T = 0; within lr_multipole_tail(n) of the exact totals. */
void lr_multipole_total(const lr_coeffs *c, double d, double R[3], double T[3]);
void lr_multipole_total_n(const lr_coeffs *c, double d, int n, double R[3], double T[3]);
/* T_total e^{sigma_tr d} per band: the slab's diffuse transmission over the attenuation
 * e^{-sigma_tr d}, evaluated without forming either (both underflow to 0 for an optically thick
 * slab, sigma_tr d beyond about 745, where T / e^{-sigma_tr d} is 0/0). Finite for every
 * coefficient set lr_coeffs_derive accepts: at most alpha' e^{sqrt 3} (e^{sigma_tr l} <=
 * e^{sqrt 3}, l the source depth; the other two factors <= 1); as sigma_tr d -> inf it tends
 * to alpha' e^{sigma_tr l} (1 + e^{-2 sigma_tr z_b}) / 2. */
void lr_multipole_transmission_gain(const lr_coeffs *c, double d, double out[3]);
/* As a BSSRDF diffusion term, mm^-2 sr^-1, without Fresnel factors (like lr_dipole_sd):
 * n_i . n_o < 0 (entry and exit on opposite faces of the wall): T(r_perp) / pi with
 * r_perp = sqrt(|x_o - x_i|^2 - d^2), on a flat slab the distance from x_o to x_i's
 * projection on x_o's tangent plane, and about |x_o - x_i| between the two sides of a shade
 * across its inside; otherwise (same face) R(|x_o - x_i|) / pi. n_i, n_o unit, pointing out
 * of the medium. */
void lr_multipole_sd(const lr_coeffs *c, double d, lr_vec3 xi, lr_vec3 ni, lr_vec3 xo,
                     lr_vec3 no, double out[3]);
/* The same times F_t(w_i); 0 when w_i . n_i <= 0. */
void lr_multipole_sd_fresnel(const lr_coeffs *c, double d, lr_vec3 xi, lr_vec3 ni, lr_vec3 wi,
                             lr_vec3 xo, lr_vec3 no, double out[3]);
/* The two above with the pole-pair count n given (n = lr_multipole_pairs(c, d), which costs an
 * exp, a log and a pow per band): for callers that evaluate one wall many times, as the CPU
 * twin's estimator does per texel. */
void lr_multipole_sd_n(const lr_coeffs *c, double d, int n, lr_vec3 xi, lr_vec3 ni, lr_vec3 xo,
                       lr_vec3 no, double out[3]);
void lr_multipole_sd_fresnel_n(const lr_coeffs *c, double d, int n, lr_vec3 xi, lr_vec3 ni,
                               lr_vec3 wi, lr_vec3 xo, lr_vec3 no, double out[3]);

/* ---- Directional dipole, Frisvad, Hachisuka, Kjeldsen 2014 (dirpole.c) ----------------- */

/* S_d(x_i, n_i, w_i; x_o, n_o) per band, mm^-2 sr^-1, without boundary Fresnel transmission.
 * Clamped to >= 0 as in [14]. n_i, w_i, n_o must be unit vectors. Where [14]'s modified
 * tangent-plane normal n_i* = x^ x (n_i x x) / |n_i x x| is undefined (x_o == x_i, or x_o - x_i
 * parallel to n_i, e.g. straight through a thin shell) it falls back to n_i. A refracted w_i
 * under total internal reflection (eta < 1) is taken as grazing; a w_i below the surface
 * (w_i . n_i < 0) goes through the same formulas (lr_dirpole_sd_fresnel gives 0 for it).
 * Finite for every finite input, including albedo' == 0 (de = Inf) and albedo' == 1
 * (sigma_tr = 0). Note: the published S_d has no albedo' factor, so unlike R_d it tends to a
 * nonzero limit (the real source alone) as albedo' -> 0. */
void lr_dirpole_sd(const lr_coeffs *c, lr_vec3 xi, lr_vec3 ni, lr_vec3 wi, lr_vec3 xo,
                   lr_vec3 no, double out[3]);
/* The same times the incident boundary transmission F_t(w_i) = 1 - R(w_i . n_i, eta) (the
 * integrand of seed 003 Eq. 4); 0 when w_i . n_i <= 0 (light from behind the surface) and under
 * total internal reflection on entry (eta < 1, grazing light). */
void lr_dirpole_sd_fresnel(const lr_coeffs *c, lr_vec3 xi, lr_vec3 ni, lr_vec3 wi, lr_vec3 xo,
                           lr_vec3 no, double out[3]);
/* Checked form of lr_dirpole_sd (with_fresnel != 0: of lr_dirpole_sd_fresnel): rejects
 * non-finite positions (fields "x_i", "x_o") and non-finite or zero-length directions ("n_i",
 * "w_i", "n_o"); directions need not be unit length, they are normalised here. */
int lr_dirpole_sd_checked(const lr_coeffs *c, lr_vec3 xi, lr_vec3 ni, lr_vec3 wi, lr_vec3 xo,
                          lr_vec3 no, int with_fresnel, double out[3], lr_err *e);

/* ---- Energy normalisation of the directional dipole (dirpole_norm.c) ------------------ */

/* Hemispherical cosine-weighted boundary transmittance 2 int_0^1 F_t(mu, eta) mu d(mu): the
 * fraction of radiosity B that leaves as L_o = F_t B / pi (1 for eta 1, 0.908 for eta 1.5). */
double lr_hemi_transmittance(double eta);
/* The directional dipole's half-space total at normal incidence, per band: power out / power
 * that entered = T_hem pi int S_d dA (1.340 / 1.240 / 1.197 at albedo' 1 for eta 1 / 1.3 /
 * 1.5), by quadrature in log r (relative error < 1e-5). */
void lr_dirpole_halfspace_albedo(const lr_coeffs *c, double out[3]);
/* Per-band factor lr_dipole_rd_total / lr_dirpole_halfspace_albedo (1 where both vanish):
 * times it, S_d's half-space total equals the standard dipole's (exactly 1 at albedo' 1).
 * lr_coeffs_derive stores it in sd_norm (a few thousand S_d evaluations, once per material). */
void lr_dirpole_energy_norm(const lr_coeffs *c, double out[3]);

/* ---- Sampling (sampling.c) ------------------------------------------------------------- */

/* Exponential radius sampling of seed 003 Eq. 11-12, truncated to [0, r_max] so that
 * sigma_tr -> 0 (albedo -> 1) stays finite: r_max = INFINITY gives Eq. 12 exactly, and
 * sigma_tr == 0 gives the uniform density on [0, r_max]. xi in [0, 1). Preconditions (see
 * lr_exp_radius_validate): sigma_tr finite >= 0, r_max > 0, r_max finite when sigma_tr == 0;
 * otherwise NaN is returned.
 * Density p(r) = sigma_tr e^{-sigma_tr r} / (1 - e^{-sigma_tr r_max}). */
double lr_exp_radius_sample(double sigma_tr, double r_max, double xi);
/* Its density p(r) (0 outside [0, r_max]); the joint density of Eq. 11 is p(r) / (2 pi). */
double lr_exp_radius_pdf(double sigma_tr, double r_max, double r);
/* Rejects sigma_tr NaN/Inf/negative, r_max NaN/<= 0, and sigma_tr == 0 with r_max = Inf (an
 * improper density), naming "sigma_tr" or "r_max". */
int lr_exp_radius_validate(double sigma_tr, double r_max, lr_err *e);
/* Radical inverse of index in the given base >= 2 (Halton sequence): base 2 maps 1, 2, 3 to
 * 0.5, 0.25, 0.75; index 0 maps to 0. Returns NaN for base < 2. */
double lr_halton(unsigned index, unsigned base);
/* Quasi-random unit direction on the sphere from Halton bases 2 and 3 (map directions):
 * z = 1 - 2 h2(index), phi = 2 pi h3(index). Index 0 is the pole (0, 0, 1). */
lr_vec3 lr_halton_sphere(unsigned index);

/* ---- Spherical harmonics, l <= 2 (sh.c) ------------------------------------------------ */

/* The 9 real SH basis functions Y_lm(dir), ordered (0,0),(1,-1),(1,0),(1,1),(2,-2)..(2,2),
 * with Ramamoorthi & Hanrahan's signs (no Condon-Shortley phase): Y_1-1 ~ y, Y_10 ~ z,
 * Y_11 ~ x, Y_2-2 ~ xy, Y_2-1 ~ yz, Y_20 ~ 3z^2 - 1, Y_21 ~ xz, Y_22 ~ x^2 - y^2.
 * dir must be a unit vector. Orthonormal over the sphere. */
void lr_sh9_basis(lr_vec3 dir, double out[9]);
/* Irradiance E(n) from radiance SH coefficients L_lm (seed 002 Eq. 10-11, after Ramamoorthi
 * & Hanrahan 2001): sum of A_l L_lm Y_lm(n), A_0 = pi, A_1 = 2pi/3, A_2 = pi/4. Exact for
 * radiance band-limited to l <= 2. */
double lr_sh9_irradiance(const double coeffs[9], lr_vec3 n);

#endif
