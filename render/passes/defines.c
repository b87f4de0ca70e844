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

void lr_shader_defines_copy(lr_shader_defines *to, const lr_shader_defines *from)
{
    *to = *from;
    const char *t0 = (const char *)from->text, *m0 = from->models;
    for (int i = 0; i < from->n; i++) {
        const char *p = from->list[i];
        if (p >= t0 && p < t0 + sizeof from->text)
            to->list[i] = (const char *)to->text + (p - t0);
        else if (p >= m0 && p < m0 + sizeof from->models)
            to->list[i] = to->models + (p - m0);
    }
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
        DEF(LR_PROFILE_NG),
        DEF(LR_PROFILE_NC),
        DEF(LR_GB_CUBE),
        DEF(LR_GB_PERSPECTIVE),
        DEF(LR_GB_ORTHO),
        DEF(LR_TONEMAP_CLAMP),
        DEF(LR_TONEMAP_REINHARD),
        DEF(LR_TONEMAP_ACES),
        {"LR_BLEND_LINEAR", LR_BLEND_OPS},
    };
    _Static_assert(sizeof defs / sizeof defs[0] <= LR_DEFINES_MAX, "LR_DEFINES_MAX too small");
    memset(d, 0, sizeof *d);
    for (size_t i = 0; i < sizeof defs / sizeof defs[0]; i++)
        lr_shader_defines_add(d, defs[i].name, defs[i].value); /* fits: asserted above */
    /* The models' dispatch after the constants; the buffer holds the registry's text, which
     * tests/optics/test_models.c checks fits (a shorter list here would fail every shader). */
    int n = lr_models_glsl_defines(d->models, sizeof d->models, d->list + d->n,
                                   LR_MODELS_GLSL_DEFINES);
    if (n > 0)
        d->n += n;
    d->list[d->n] = NULL;
    return d->list;
}
