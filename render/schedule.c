/* The scheduler's mapping from scene changes to passes (render/schedule.h). */
#include "render/schedule.h"

/* What each change invalidates (docs/ARCHITECTURE.md, "Data flow"; the `dirty` column of the pass
 * table in render/renderer.c):
 *  - intensity, colour, flicker (flicker is applied at composition's blend) and exposure:
 *    light transport is linear in intensity, so only the blend of the per-light
 *    unit-intensity images runs (issue 11);
 *  - a light's pose or cone, an object's geometry, the render settings: everything (settings
 *    also reallocate and restart accumulation);
 *  - material: the scattered-radiosity maps, VPLs, receiver grids, composition, blend;
 *  - view: composition and blend (the radiosity maps, the grids and the objects' surface
 *    cache are view-independent);
 *  - receivers: their irradiance grids, composition and blend (receivers are lit at
 *    composition and take no part in the transport through the object);
 *  - the light-propagation volume (render.lpv): the light geometry, the objects, their
 *    material, the receivers and the settings (it injects the receivers' and the objects'
 *    reflection and propagates between them), never the camera or a dimmer; it feeds
 *    composition (the objects' term) and, through the area pass, the receivers' grids, which
 *    restart with the maps on every one of those changes. */

unsigned lr_dirty_passes(unsigned dirty)
{
    const lr_pass_desc *t = lr_pass_table();
    unsigned p = 0;
    for (int i = 0; i < LR_PASS_COUNT; i++)
        if (dirty & t[i].dirty)
            p |= t[i].bit;
    return p;
}

const char *lr_pass_name(int index)
{
    const lr_pass_desc *t = lr_pass_table();
    for (int i = 0; i < LR_PASS_COUNT && index >= 0; i++)
        if (t[i].bit == 1u << index)
            return t[i].name;
    return "?";
}

unsigned lr_schedule_close(const lr_renderer *r, unsigned passes, bool no_emergent)
{
    /* In table order, so that a pass's own `due` and every earlier pass's `feeds` are in
     * before it passes its output on. */
    const lr_pass_desc *t = lr_pass_table();
    for (int i = 0; i < LR_PASS_COUNT; i++) {
        /* A pass switched off is neither due nor does it make its readers due. */
        if (t[i].on && !t[i].on(r)) {
            passes &= ~t[i].bit;
            continue;
        }
        if (t[i].due && t[i].due(r))
            passes |= t[i].bit;
        if (passes & t[i].bit)
            passes |= t[i].feeds;
    }
    if (no_emergent)
        for (int i = 0; i < LR_PASS_COUNT; i++)
            if (t[i].emergent)
                passes &= ~t[i].bit;
    return passes;
}
