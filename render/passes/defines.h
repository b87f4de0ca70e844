/* lamprig — the renderer's GLSL defines: the limits of the shaders' arrays and every enum
 * value a shader compares against (light types, G-buffer layouts, diffusion models, tone
 * curves), generated from the C enums so that a shader never compares against a bare 0/1/2
 * (issue 15). Every program of the renderer is built with them; a test program that includes
 * render/shaders/lib/ files needs them too. */
#ifndef LR_DEFINES_H
#define LR_DEFINES_H

#include <stdbool.h>

#define LR_DEFINES_MAX 24

typedef struct lr_shader_defines {
    char text[LR_DEFINES_MAX][48];
    const char *list[LR_DEFINES_MAX + 1]; /* "NAME VALUE", NULL-terminated */
    int n;
} lr_shader_defines;

/* Fills d (caller-owned: no shared state) and returns d->list, for lr_program_desc.defines:
 * LR_MAX_OBJECTS, LR_MAX_K, LR_MAX_LIGHTS; LR_LIGHT_POINT, LR_LIGHT_SPOT,
 * LR_LIGHT_DIRECTIONAL (enum lr_light_type); LR_GB_CUBE, LR_GB_PERSPECTIVE, LR_GB_ORTHO
 * (enum lr_gb_mode); LR_SSS_DIRECTIONAL_DIPOLE, LR_SSS_STANDARD_DIPOLE (enum lr_sss_model);
 * LR_TONEMAP_CLAMP, LR_TONEMAP_REINHARD, LR_TONEMAP_ACES (lr_tonemap_op) and LR_BLEND_LINEAR
 * (the blend's linear sum). */
const char *const *lr_passes_defines(lr_shader_defines *d);

/* Appends "name value"; false when d is full or the text does not fit. */
bool lr_shader_defines_add(lr_shader_defines *d, const char *name, int value);

#endif
