/* lamprig — the per-object material blocks the shaders read (render/shaders/lib/material.glsl:
 * u_coef, u_sss), packed from the optics coefficients. Public so that tests can drive the
 * GLSL optics with exactly the renderer's packing (tests/render/test_render_optics_glsl.c). */
#ifndef LR_MATERIAL_PACK_H
#define LR_MATERIAL_PACK_H

#include "render/models/model.h"
#include "render/optics/optics.h"

/* Objects per scene the shaders' uniform arrays hold (material.glsl, gather.glsl). */
#define LR_MAX_OBJECTS 8

/* One object's block of material.glsl's u_coef (20 floats). */
void lr_passes_pack_coeffs(const lr_coeffs *c, float out[20]);
/* One object's block of material.glsl's u_sss (12 floats): the model switch and the standard
 * dipole's albedo', z_r, z_v. */
void lr_passes_pack_sss(const lr_coeffs *c, enum lr_sss_model model, float out[12]);
/* The multipole's slab into that block (multipole.c): out[7] = thickness_mm, out[11] =
 * lr_multipole_pairs; both 0 unless model is LR_SSS_MULTIPOLE. */
void lr_passes_pack_multipole(const lr_coeffs *c, enum lr_sss_model model, double thickness_mm,
                              float out[12]);

#endif
