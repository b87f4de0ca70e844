/* lamprig firmware — the rig's status as one JSON document, for every way it leaves the rig:
 * GET /api/status and the Server-Sent Events of the HTTP endpoint (firmware/rig/http.h), and
 * whatever else publishes it (an MQTT status topic) — one producer, so they never disagree.
 *
 * Interface: fill an lr_rig_status with lr_rig_get_status (firmware/rig/rig.h; plain values
 * and pointers into the rig, valid until the loop runs again), then write it with
 * lr_status_json_write / lr_status_json_controls into an lr_jw (render/base/json_write.h), or
 * get a malloc'd string from lr_status_json_string. Nothing here touches the rig itself.
 *
 * The status document:
 * {"version": "0.1.0", "config": "configs/rig/sim.json", "scene": "candle.json",
 *  "output": "headless", "view": "passes", "uptime_s": 12.5, "idle": false,
 *  "frames": 321, "events": 40, "events_unmatched": 3, "garbage": 0,
 *  "reloads": 0, "reload_failures": 0, "lamp_level": 0.64 | null,
 *  "fps": 29.8 | 0,                       frames started in the last 2 s over their span
 *                                         (0: idle; at most output.fps headless)
 *  "frame_interval_p99_ms": 35.1 | null,  nearest-rank p99 of the last 63 start-to-start
 *                                         frame intervals
 *  "latency_ms": {"n": 40, "median": 2.1 | null, "p99": 7.9 | null},  control event ->
 *                                         the first frame showing it (firmware/rig/stats.h)
 *  "devices": [{"name": "sim", "kind": "sim", "state": "open"}, ...],
 *  "plan": {"planned": true, "text": "...", "predicted_error": 0.031 | null,
 *           "predicted_frame_ms": 12.4 | null},
 *  "warnings": [{"t_s": 3.2, "msg": "..."}, ...], "errors": [...]   the last few log lines
 *                                         of that level (LR_STATUS_LOG_KEEP each)
 *  "controls": [CONTROL, ...]}
 * CONTROL (also GET /api/controls, alone):
 * {"name": "dimmer", "source": "" | "panel", "control": "dimmer", "param": "light.level",
 *  "kind": "level" | "cycle", "position": 0.5, "level": 0.25,      position x 0..1 and the
 *                                         faded curved level y (firmware/rig/control_map.h)
 *  cycle only: "index": 2, "values": ["candle_wax", "marble", ...]}  (scene files: their
 *                                         base names)
 */
#ifndef LR_RIG_STATUS_JSON_H
#define LR_RIG_STATUS_JSON_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "firmware/rig/config.h"
#include "render/base/json_write.h"

#define LR_STATUS_LOG_KEEP 8
#define LR_STATUS_MSG_MAX 256

typedef struct lr_rig_status_dev {
    const char *name, *kind, *state;
} lr_rig_status_dev;

typedef struct lr_rig_status_control {
    const char *name, *source, *control, *param;
    bool cycle;
    double position, level; /* level bindings */
    int index, n_values;    /* cycle bindings */
    const char *values[LR_RIG_MAX_VALUES];
} lr_rig_status_control;

typedef struct lr_rig_status_line {
    double t_s; /* seconds since the rig started */
    char msg[LR_STATUS_MSG_MAX];
} lr_rig_status_line;

typedef struct lr_rig_status {
    const char *version, *config, *scene, *output, *view;
    double uptime_s;
    bool idle;
    uint64_t frames, events, events_unmatched, reloads, reload_failures;
    unsigned garbage;
    double lamp_level; /* < 0: none written */
    double fps, frame_interval_p99_ms; /* NaN: not measured */
    uint64_t latency_n;
    double latency_median_ms, latency_p99_ms; /* NaN: no event yet */
    int n_devices;
    lr_rig_status_dev devices[LR_RIG_MAX_DEVICES];
    bool planned;
    const char *plan_text; /* "" when not planned */
    double plan_error, plan_frame_ms; /* NaN when not planned */
    int n_warnings, n_errors; /* oldest first */
    const lr_rig_status_line *warnings, *errors;
    int n_controls;
    lr_rig_status_control controls[LR_RIG_MAX_BINDINGS];
} lr_rig_status;

/* The status object (with its controls) as member `key` (NULL at the top level or in an
 * array). */
void lr_status_json_write(lr_jw *w, const char *key, const lr_rig_status *st);
/* Its members alone, into an object the caller opened (the MQTT status adds its own:
 * firmware/rig/mqtt.h). */
void lr_status_json_members(lr_jw *w, const lr_rig_status *st);
/* The controls array alone. */
void lr_status_json_controls(lr_jw *w, const char *key, const lr_rig_status *st);
/* Either document as a malloc'd NUL-terminated string (*len its length, may be NULL);
 * NULL when out of memory. */
char *lr_status_json_string(const lr_rig_status *st, bool controls_only, size_t *len);

#endif
