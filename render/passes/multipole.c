/* The multipole's per-object uniforms (render/shaders/lib/material.glsl u_sss, issue 12): the
 * slab thickness and the pole-pair count that render/optics/multipole.c chose for the material,
 * so the GLSL S_d sums the same poles as the CPU twin (lr_sss_sd_fresnel). */
#include "render/passes/material_pack.h"

void lr_passes_pack_multipole(const lr_coeffs *c, enum lr_sss_model model, double thickness_mm,
                              float b[12])
{
    bool on = lr_sss_model_props_of(model)->slab && thickness_mm > 0.0;
    b[7] = on ? (float)thickness_mm : 0.0f;
    b[11] = on ? (float)lr_multipole_pairs(c, thickness_mm) : 0.0f;
}
