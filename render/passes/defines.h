/* lamprig — the renderer's GLSL defines: the limits of the shaders' arrays and every enum
 * value a shader compares against (light types, G-buffer layouts, diffusion models, tone
 * curves), generated from the C enums so that a shader never compares against a bare 0/1/2
 * (issue 15). Every program of the renderer is built with them; a test program that includes
 * render/shaders/lib/ files needs them too. */
#ifndef LR_DEFINES_H
#define LR_DEFINES_H

#include <stdbool.h>

#include "render/models/model.h"

#define LR_DEFINES_MAX 24

typedef struct lr_shader_defines {
    char text[LR_DEFINES_MAX][48];
    char models[1536]; /* the models' dispatch (lr_models_glsl_defines) */
    const char *list[LR_DEFINES_MAX + LR_MODELS_GLSL_DEFINES + 1]; /* "NAME VALUE", NULL-ended */
    int n;
} lr_shader_defines;

/* Fills d (caller-owned: no shared state) and returns d->list, for lr_program_desc.defines:
 * LR_MAX_OBJECTS, LR_MAX_K, LR_MAX_LIGHTS; LR_LIGHT_POINT, LR_LIGHT_SPOT,
 * LR_LIGHT_DIRECTIONAL (enum lr_light_type); LR_GB_CUBE, LR_GB_PERSPECTIVE, LR_GB_ORTHO
 * (enum lr_gb_mode); the per-object models' dispatch LR_MODEL_SD_BAND, LR_MODEL_HAS_B and
 * LR_MODEL_B, generated from their registry (render/models/model.h: no shader names a model);
 * LR_TONEMAP_CLAMP, LR_TONEMAP_REINHARD, LR_TONEMAP_ACES (lr_tonemap_op) and LR_BLEND_LINEAR
 * (the blend's linear sum). */
const char *const *lr_passes_defines(lr_shader_defines *d);

/* A copy of from whose list points into its own text (a plain struct copy would point into
 * from's). */
void lr_shader_defines_copy(lr_shader_defines *to, const lr_shader_defines *from);

/* Appends "name value"; false when d is full or the text does not fit. */
bool lr_shader_defines_add(lr_shader_defines *d, const char *name, int value);

#endif
