/* The renderer's GLSL defines (render/passes/defines.h). */
#include "render/passes/defines.h"

#include <stdio.h>
#include <string.h>

#include "render/image/image.h"
#include "render/passes/blend.h"
#include "render/passes/gbuffer.h"
#include "render/passes/passes.h"

bool lr_shader_defines_add(lr_shader_defines *d, const char *name, int value)
{
    if (d->n >= LR_DEFINES_MAX)
        return false;
    int w = snprintf(d->text[d->n], sizeof d->text[d->n], "%s %d", name, value);
    if (w < 0 || (size_t)w >= sizeof d->text[d->n])
        return false;
    d->list[d->n] = d->text[d->n];
    d->list[++d->n] = NULL;
    return true;
}

/* One entry: the constant's name as written in C, and its value. */
#define DEF(x) {#x, (int)(x)}

const char *const *lr_passes_defines(lr_shader_defines *d)
{
    static const struct {
        const char *name;
        int value;
    } defs[] = {
        DEF(LR_MAX_OBJECTS),
        DEF(LR_MAX_K),
        DEF(LR_MAX_LIGHTS),
        DEF(LR_LIGHT_POINT),
        DEF(LR_LIGHT_SPOT),
        DEF(LR_LIGHT_DIRECTIONAL),
        DEF(LR_LIGHT_QUAD),
        DEF(LR_LIGHT_DISK),
        DEF(LR_GB_CUBE),
        DEF(LR_GB_PERSPECTIVE),
        DEF(LR_GB_ORTHO),
        DEF(LR_SSS_DIRECTIONAL_DIPOLE),
        DEF(LR_SSS_STANDARD_DIPOLE),
        DEF(LR_SSS_MULTIPOLE),
        DEF(LR_SSS_TRANSLUCENT_RADIOSITY),
        DEF(LR_SSS_DIFFUSION_GRID),
        DEF(LR_SSS_SH_TRANSLUCENCY),
        DEF(LR_TONEMAP_CLAMP),
        DEF(LR_TONEMAP_REINHARD),
        DEF(LR_TONEMAP_ACES),
        {"LR_BLEND_LINEAR", LR_BLEND_OPS},
    };
    _Static_assert(sizeof defs / sizeof defs[0] <= LR_DEFINES_MAX, "LR_DEFINES_MAX too small");
    memset(d, 0, sizeof *d);
    for (size_t i = 0; i < sizeof defs / sizeof defs[0]; i++)
        lr_shader_defines_add(d, defs[i].name, defs[i].value); /* fits: asserted above */
    return d->list;
}
