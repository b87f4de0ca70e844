/* lamprig firmware — the control map: hal events in, scene parameters (and the lamp-driver
 * level) out. The bindings come from the rig config (firmware/rig/config.h).
 *
 * A level binding keeps a control *position* x in [0, 1]: an absolute event (dimmer, fader)
 * sets it, a delta event (encoder detent) moves it by value * step * acceleration
 * (firmware/control/accel.h). The curve (firmware/control/curve.h) turns x into a *level*
 * y = curve(x) in [0, 1]; this is the one place a curve is applied. y fades (fade.h) over
 * fade_s to its new target, and the faded level is what both the scene and the lamp driver get:
 * the parameter becomes min + (max - min) * y (or the colour c0 + (c1 - c0) * y) and, for the
 * binding marked "lamp", y itself goes to lr_modbus_write_level.
 * A light's level ("light.level", "lights[i].level") is relative: the parameter written is the
 * light's intensity (radiance for directional and area lights) = the scene's own value, read
 * when the scene is loaded or replaced, times min + (max - min) * y; so one dimmer means the
 * same in every scene a "scene" binding switches to.
 * Several level bindings on one parameter multiply (a translucency-scale knob and a shade
 * colour both on objects[0].material.scale give scale * colour).
 *
 * A cycle binding steps through its values: a press moves one on, a delta moves by its sign
 * and size, an absolute position picks value floor(x * n). Param "scene" switches the scene
 * file (the rig loads it, see lr_control_map_scene_request).
 *
 * Events with non-finite values, or kinds a binding does not take (releases), are ignored.
 */
#ifndef LR_RIG_CONTROL_MAP_H
#define LR_RIG_CONTROL_MAP_H

#include <stdbool.h>
#include <stdint.h>

#include "firmware/rig/config.h"
#include "hal/event.h"
#include "render/base/err.h"
#include "render/scene/scene.h"

typedef struct lr_control_map lr_control_map;

/* Builds the map over cfg's bindings (cfg must outlive the map) for `scene`: checks every
 * parameter exists in the scene and that the range ends and every cycle value are accepted
 * (on a scratch copy of the scene file when check_values; errors name the config file, line
 * and field), takes the starting positions (`initial`, else inverted from the scene's current
 * value), and leaves nothing applied yet: call lr_control_map_update. */
int lr_control_map_create(const lr_rig_config *cfg, lr_scene *scene, bool check_values,
                          int64_t now_ns, lr_control_map **out, lr_err *e);
void lr_control_map_destroy(lr_control_map *m);

/* Feeds one event at now_ns. Returns the index of the binding it moved, or -1 when no binding
 * took it (no match, a release, a non-finite value, a position that did not change). */
int lr_control_map_event(lr_control_map *m, const lr_event *ev, int64_t now_ns);

/* Writes every parameter whose value at now_ns differs from what was last written into the
 * scene (fades in progress move), ORing the LR_DIRTY_* flags into *dirty. A value the scene
 * rejects is reported in e (the other parameters are still written). */
int lr_control_map_update(lr_control_map *m, lr_scene *scene, int64_t now_ns, unsigned *dirty,
                          lr_err *e);
/* A reload's new map takes over where the old one's controls stand: every level binding of
 * `to` with a binding of `from` of the same name, source, control and parameter gets that
 * binding's position (a knob or dimmer is where the hardware left it, and a Modbus panel that
 * reads the same again sends no event), its level at now_ns recomputed with its own curve and
 * shown without a fade. Cycle bindings (material presets, the scene) start as the new config
 * says: a reload loads the config's scene. Writes nothing: call lr_control_map_update. */
void lr_control_map_carry(lr_control_map *to, const lr_control_map *from, int64_t now_ns);
/* The scene was replaced (scene switch or reload): the next update rewrites everything. */
void lr_control_map_scene_replaced(lr_control_map *m);

/* True while a fade runs at now_ns (the loop keeps updating and rendering frames). */
bool lr_control_map_fading(const lr_control_map *m, int64_t now_ns);

/* The lamp binding's faded level at now_ns (the same y its parameter is computed from);
 * false when no binding drives the lamp. */
bool lr_control_map_lamp_level(const lr_control_map *m, int64_t now_ns, double *level);

/* A scene switch waiting to be loaded (a path from the binding's values), or NULL. Clears it. */
const char *lr_control_map_scene_request(lr_control_map *m);

/* ---- the control space, for states built ahead (firmware/rig/ahead.h) ---- */
/* The scene key binding i writes: its param (a light's level: the light's intensity or
 * radiance key; "scene": "scene"). */
const char *lr_control_map_key(const lr_control_map *m, int binding);
bool lr_control_map_is_cycle(const lr_control_map *m, int binding);
/* A cycle binding's number of values (0 for a level binding). */
int lr_control_map_values(const lr_control_map *m, int binding);
/* Writes into `scene` (a copy of the one the map drives) what the map would write with
 * binding i at `pos` -- a level binding's position x in [0, 1], a cycle binding's value index
 * -- and every other binding where its fade ends, ORing the flags into *dirty. The map itself
 * is left as it is. Errors: the scene's refusal, i out of range. */
int lr_control_map_what_if(const lr_control_map *m, int binding, double pos, lr_scene *scene,
                           int64_t now_ns, unsigned *dirty, lr_err *e);

/* For tests and logs. */
int lr_control_map_count(const lr_control_map *m);
double lr_control_map_position(const lr_control_map *m, int binding);   /* level: x */
double lr_control_map_level(const lr_control_map *m, int binding, int64_t now_ns); /* y faded */
int lr_control_map_index(const lr_control_map *m, int binding);         /* cycle: index */
/* Events ignored for garbage (non-finite values). */
unsigned lr_control_map_garbage(const lr_control_map *m);

#endif
