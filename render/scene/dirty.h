/* lamprig — what a scene change invalidates (DESIGN.md, "Data flow" table).
 *
 * lr_scene_set() ORs one of these into the caller's mask for every parameter it changes; the
 * renderer's scheduler turns the mask into the passes to re-run with lr_dirty_passes().
 */
#ifndef LR_DIRTY_H
#define LR_DIRTY_H

enum lr_dirty {
    /* Light intensity, colour or flicker (the dimmer): light transport is linear in it, so
     * only the blend of the per-light unit-intensity images runs. */
    LR_DIRTY_INTENSITY = 1u << 0,
    /* A light moved, turned or changed its cone: everything. (Flicker fields are
     * LR_DIRTY_INTENSITY: the renderer applies flicker at composition.) */
    LR_DIRTY_LIGHT_GEOMETRY = 1u << 1,
    /* Optical properties of an object: scattered-radiosity maps, VPLs, composition. */
    LR_DIRTY_MATERIAL = 1u << 2,
    /* View (camera or projector pose, field of view): composition only; the radiosity maps
     * are view-independent. */
    LR_DIRTY_CAMERA = 1u << 3,
    /* An object's mesh or transform: everything. */
    LR_DIRTY_GEOMETRY = 1u << 4,
    /* Receivers (table, wall: albedo, placement): composition only. They are lit by the VPLs
     * and the light at composition time and take no part in the transport through the
     * object. */
    LR_DIRTY_RECEIVERS = 1u << 5,
    /* Exposure (tone mapping): the blend only. */
    LR_DIRTY_DISPLAY = 1u << 6,
    /* Render settings (K, N, map sizes, frames) or the quality budget: the renderer
     * reallocates and restarts accumulation; everything. */
    LR_DIRTY_SETTINGS = 1u << 7,
};

/* The render passes of issue 3, as bits. */
enum lr_pass {
    LR_PASS_GBUFFER = 1u << 0,   /* light G-buffer */
    LR_PASS_RADIOSITY = 1u << 1, /* K scattered-radiosity maps (restart accumulation) */
    LR_PASS_VPL = 1u << 2,       /* virtual point lights on the outer surface */
    LR_PASS_COMPOSE = 1u << 3,   /* composition: one unit-intensity linear image per light */
    LR_PASS_BLEND = 1u << 4,     /* sum_l I_l image_l, tone mapping, output (passes/blend.h) */
    LR_PASS_IRRADIANCE = 1u << 5, /* receiver irradiance grids from the VPLs (before compose) */
};

/* The passes a dirty mask requires (0 for an empty mask: keep accumulating). */
unsigned lr_dirty_passes(unsigned dirty);

/* "intensity", "light_geometry", ... for the lowest set bit; "none" for 0. */
const char *lr_dirty_name(unsigned flag);

#endif
