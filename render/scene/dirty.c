#include "render/scene/dirty.h"

unsigned lr_dirty_passes(unsigned dirty)
{
    const unsigned all =
        LR_PASS_GBUFFER | LR_PASS_RADIOSITY | LR_PASS_VPL | LR_PASS_IRRADIANCE | LR_PASS_COMPOSE |
        LR_PASS_BLEND;
    unsigned p = 0;
    if (dirty & (LR_DIRTY_LIGHT_GEOMETRY | LR_DIRTY_GEOMETRY | LR_DIRTY_SETTINGS))
        p |= all;
    if (dirty & LR_DIRTY_MATERIAL)
        p |= LR_PASS_RADIOSITY | LR_PASS_VPL | LR_PASS_IRRADIANCE | LR_PASS_COMPOSE | LR_PASS_BLEND;
    /* New receivers: their irradiance grids; a new view: the per-light images again (the grids
     * are view-independent), then the blend. */
    if (dirty & LR_DIRTY_RECEIVERS)
        p |= LR_PASS_IRRADIANCE;
    if (dirty & (LR_DIRTY_CAMERA | LR_DIRTY_RECEIVERS))
        p |= LR_PASS_COMPOSE | LR_PASS_BLEND;
    /* Intensity, colour, flicker, exposure: the per-light images hold unit-intensity linear
     * radiance, so one weighted sum with tone mapping (issue 11). */
    if (dirty & (LR_DIRTY_INTENSITY | LR_DIRTY_DISPLAY))
        p |= LR_PASS_BLEND;
    return p;
}

const char *lr_dirty_name(unsigned flag)
{
    static const char *const names[] = {"intensity", "light_geometry", "material", "camera",
                                        "geometry",  "receivers",      "display",  "settings"};
    for (unsigned i = 0; i < sizeof names / sizeof names[0]; i++)
        if (flag & (1u << i))
            return names[i];
    return "none";
}
