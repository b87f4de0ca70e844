/* The slab multipole of Donner and Jensen 2005 for thin walls: the dipole mirrored across both
 * faces of a slab of the object's thickness_mm, truncated at lr_multipole_pairs pole pairs. */
#include "render/models/model.h"

static void sd_fresnel(const lr_coeffs *c, double thickness_mm, int pairs, lr_vec3 xi, lr_vec3 ni,
                       lr_vec3 wi, lr_vec3 xo, lr_vec3 no, double out[3])
{
    lr_multipole_sd_fresnel_n(c, thickness_mm, pairs, xi, ni, wi, xo, no, out);
}

static int pairs(const lr_coeffs *c, double thickness_mm)
{
    return lr_multipole_pairs(c, thickness_mm);
}

/* What entered and was not absorbed: the slab's R + T totals (a thin wall absorbs less than a
 * half-space). */
static void total(const lr_coeffs *c, double thickness_mm, double out[3])
{
    double R[3], T[3];
    lr_multipole_total(c, thickness_mm, R, T);
    for (int j = 0; j < 3; j++)
        out[j] = R[j] + T[j];
}

static double sd_norm(const lr_coeffs *c, int band)
{
    (void)band;
    return 1.0 / c->t_hem; /* as the standard dipole it reduces to for a thick wall */
}

const lr_model_ops lr_model_multipole = {
    .name = "multipole",
    .props = {.needs_thickness = "needs thickness_mm (the wall the multipole models)",
              .slab = true},
    .sd_fresnel = sd_fresnel,
    .pairs = pairs,
    .total = total,
    .sd_norm = sd_norm,
    .glsl_sd = "lr_multipole_sd_band(c, s, j, xi, ni, xo, no)",
};
