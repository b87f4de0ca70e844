/* lamprig — the light-propagation volume's irradiance on the objects (issue 14 item 2,
 * issue 12 part 3 second half): what the volume delivers to the objects' surfaces, per light
 * at unit radiance or intensity, kept as a field that composition reads per pixel
 * (render/shaders/lib/lpv_object.glsl) and the CPU twin per camera hit (render/cpu/frame.c).
 *
 * The field. lr_lpv_irradiance (lpv.h) gives a surface of normal n at x the flux absorbed at
 * the interfaces nearest x, per axis a with n_a != 0 and travelling against n_a, per covered
 * area min(1, B_a) h^2, bilinear across the interface plane over the covered interfaces,
 * weighted by |n_a|. That is a function of six scalar fields per channel, one per axis and
 * direction of travel, E_{a,s}(interface) = absorbed / (min(1, B) h^2), defined where the
 * interface is covered (B > 0). The field holds them summed over the volumes it is given
 * (every receiver's group, scene_lpv.c), as floats with a coverage mask, in the layout the
 * GPU samples; lr_lpv_objfield_irradiance evaluates it from those floats exactly as the
 * shader does (the parity test compares the two), and equals lr_lpv_irradiance over the summed
 * record up to float rounding (tests/cpu/test_lpv_objects.c).
 *
 * Texels: RGBA (E_r, E_g, E_b, covered 0/1) at index ((k * 6 + 2 a + s) * (n+1) + j) * (n+1) + i
 * for interface (i, j, k) of axis a, s = 1 for travel toward -axis (lpv.h's convention): one
 * light's block is n+1 layers (k) of (n+1) x 6 (n+1) texels (i; j + (2 a + s)(n+1)).
 *
 * From irradiance to the image (lr_lpv_object_factors). The volume's light arrives spread over
 * a cell (its E is bilinear at the scale h, 9-20 mm here), while the dipole's profile R_d(r)
 * falls off over the diffusion length 1/sigma_tr. The subsurface convolution
 *     B(x) = int R_d(|x - y|) <F_t> E(y) dA_y           (seed 003 Eq. 4 with S_d of Jensen
 *                                                       et al. 2001 Eq. 5, diffuse incidence)
 * of a field linear across the surface is exactly R_total <F_t> E(x) (the profile is radially
 * symmetric, so the linear term integrates to 0), and the error of a curved E is second order:
 *     |B - R_total <F_t> E| <= (1/4) <r^2>_R |lap E| R_total <F_t>,
 * <r^2>_R the profile's second moment per unit R_total (lr_lpv_profile_r2). R_total is Jensen
 * et al. 2001's closed-form total diffuse reflectance (lr_dipole_rd_total) or, for objects with
 * thickness_mm, the Donner-Jensen multipole's R and T (lr_multipole_total: light entering one
 * face of a thin wall leaves the other with T), the totals the volume's own injection uses
 * (scene_lpv.c). <F_t> = 2 int_0^1 F_t(mu) mu dmu is the entry Fresnel transmittance averaged
 * over diffuse incidence (the maps' estimator weighs each sample with F_t(n_i . w_i)); the
 * exit F_t(w_o) / pi is composition's, as for the maps' B. So per light
 *     B_ind(x, n) = <F_t> (R E(x, n) + T E(x, -n)),    L_o = F_t(w_o) B_ind / pi,
 * linear in the light (no cavity gain: that closure is the direct light's). */
#ifndef LR_LPV_OBJFIELD_H
#define LR_LPV_OBJFIELD_H

#include "render/base/err.h"
#include "render/base/vec3.h"
#include "render/lpv/lpv.h"
#include "render/scene/scene.h"

typedef struct lr_lpv_objfield lr_lpv_objfield;

/* A zero field (no box yet: irradiance 0). LR_ENOMEM. */
int lr_lpv_objfield_create(lr_lpv_objfield **out, lr_err *e);
void lr_lpv_objfield_destroy(lr_lpv_objfield *f);

/* Takes v's box (n, origin, h) and zeroes the field. LR_ENOMEM. */
int lr_lpv_objfield_reset(lr_lpv_objfield *f, const lr_lpv *v, lr_err *e);
/* Back to no box (irradiance 0 everywhere; a light that injects nothing). */
void lr_lpv_objfield_clear(lr_lpv_objfield *f);
/* Adds the irradiance of v's absorbed record (v must have the box of the last reset; a volume
 * of another box is ignored). The coverage is v's blocking. */
void lr_lpv_objfield_add(lr_lpv_objfield *f, const lr_lpv *v);
/* Whether anything was added with light in it. */
bool lr_lpv_objfield_lit(const lr_lpv_objfield *f);

int lr_lpv_objfield_n(const lr_lpv_objfield *f); /* 0 before a reset */
lr_vec3 lr_lpv_objfield_origin(const lr_lpv_objfield *f);
double lr_lpv_objfield_h(const lr_lpv_objfield *f);
/* The texels (layout above), (n+1)^3 * 6 * 4 floats; NULL before a reset. */
const float *lr_lpv_objfield_texels(const lr_lpv_objfield *f);

/* E[3] at x for a surface of unit normal n, from the texels (as the shader). */
void lr_lpv_objfield_irradiance(const lr_lpv_objfield *f, lr_vec3 x, lr_vec3 n, double E[3]);
/* The same from raw texels of a field of n cells, box origin and cell h. */
void lr_lpv_objfield_eval(const float *texels, int n, lr_vec3 origin, double h, lr_vec3 x,
                          lr_vec3 nrm, double E[3]);

/* Object o's factors kR, kT (above): B_ind = kR E(x, n) + kT E(x, -n). */
void lr_lpv_object_factors(const lr_scene_object *o, double kR[3], double kT[3]);
/* The totals the volume uses for an object: the multipole's R, T with thickness_mm, else the
 * dipole's R_d total and T = 0. */
void lr_lpv_object_totals(const lr_scene_object *o, double R[3], double T[3]);
/* <F_t> = 2 int_0^1 F_t(mu, eta) mu dmu (midpoint rule in mu^2, 1024 points). */
double lr_lpv_fresnel_diffuse(double eta);
/* <r^2> = int R_d(r) r^2 dA / int R_d(r) dA of the standard dipole for channel c, mm^2
 * (closed form, the bound above). */
double lr_lpv_profile_r2(const lr_coeffs *c, int ch);

#endif
