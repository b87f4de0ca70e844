#include "render/scene/dirty.h"

unsigned lr_dirty_passes(unsigned dirty)
{
    const unsigned all = LR_PASS_GBUFFER | LR_PASS_RADIOSITY | LR_PASS_VPL | LR_PASS_COMPOSE;
    unsigned p = 0;
    if (dirty & (LR_DIRTY_LIGHT_GEOMETRY | LR_DIRTY_GEOMETRY | LR_DIRTY_SETTINGS))
        p |= all;
    if (dirty & LR_DIRTY_MATERIAL)
        p |= LR_PASS_RADIOSITY | LR_PASS_VPL | LR_PASS_COMPOSE;
    if (dirty & (LR_DIRTY_INTENSITY | LR_DIRTY_CAMERA | LR_DIRTY_RECEIVERS | LR_DIRTY_DISPLAY))
        p |= LR_PASS_COMPOSE;
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
