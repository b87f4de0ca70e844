#include "render/scene/dirty.h"

const char *lr_dirty_name(unsigned flag)
{
    static const char *const names[] = {"intensity", "light_geometry", "material", "camera",
                                        "geometry",  "receivers",      "display",  "settings"};
    for (unsigned i = 0; i < sizeof names / sizeof names[0]; i++)
        if (flag & (1u << i))
            return names[i];
    return "none";
}
