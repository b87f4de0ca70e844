/* lamprig — what a scene change invalidates (docs/ARCHITECTURE.md, "Data flow" table).
 *
 * lr_scene_set() ORs one of these into the caller's mask for every parameter it changes. The
 * scene only reports what changed; which render passes that makes due is the renderer's
 * business (render/schedule.h).
 */
#ifndef LR_DIRTY_H
#define LR_DIRTY_H

enum lr_dirty {
    /* A light's intensity, colour or flicker (the dimmer). */
    LR_DIRTY_INTENSITY = 1u << 0,
    /* A light moved, turned or changed its cone (flicker fields are LR_DIRTY_INTENSITY). */
    LR_DIRTY_LIGHT_GEOMETRY = 1u << 1,
    /* Optical properties of an object (material, model, normalisation). */
    LR_DIRTY_MATERIAL = 1u << 2,
    /* View: camera or projector pose, field of view. */
    LR_DIRTY_CAMERA = 1u << 3,
    /* An object's mesh or transform. */
    LR_DIRTY_GEOMETRY = 1u << 4,
    /* Receivers (table, wall: albedo, placement). */
    LR_DIRTY_RECEIVERS = 1u << 5,
    /* Exposure (tone mapping). */
    LR_DIRTY_DISPLAY = 1u << 6,
    /* Render settings (K, N, map sizes, frames) or the quality budget. */
    LR_DIRTY_SETTINGS = 1u << 7,
};

/* "intensity", "light_geometry", ... for the lowest set bit; "none" for 0. */
const char *lr_dirty_name(unsigned flag);

#endif
