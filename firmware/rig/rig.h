/* lamprig firmware — the rig: config → devices → control map → scene → view → output, driven
 * by one poll loop (`lamprig run`).
 *
 * The loop waits in poll(2) on: a signalfd (SIGINT, SIGTERM, SIGHUP), every device's
 * descriptors (hal/dev.h), the DRM page-flip fd while a flip is pending (KMS), with a timeout
 * that is the earliest of: a device deadline (retry, debounce, Modbus poll, sim script), the
 * next frame when one is due (the view needs a frame, or a fade is running; headless frames
 * are spaced by 1/fps, KMS frames by the flip), the next periodic stats write, the end of
 * --duration. Nothing to do means an infinite timeout: no busy waiting.
 *
 * Every wake: dispatch devices, feed their events to the control map, write the changed scene
 * parameters (their dirty flags go to the view) and the lamp-driver level (the control map's
 * curved level, written as is), then render when a frame is due and needed; headless frames go
 * to out_dir/frame_NNNNNN.png when given. Stats record each event's latency to the first
 * frame after it.
 *
 * SIGINT/SIGTERM end the loop (lr_rig_run returns LR_OK); lr_rig_destroy then writes the safe
 * level to the lamp driver and flushes it, closes every device, writes the stats. SIGHUP
 * reloads the config file: the new config, scene, control map and devices are built first
 * and swapped in only when all succeed; otherwise the error (file, line, field) is logged and
 * the old rig runs on. The output (KMS or headless) is kept across reloads.
 */
#ifndef LR_RIG_H
#define LR_RIG_H

#include <stdbool.h>
#include <stdint.h>

#include "hal/log.h"
#include "render/base/err.h"

typedef struct lr_rig lr_rig;

typedef struct lr_rig_opts {
    const char *config;     /* required: the rig config file */
    bool headless;          /* force headless whatever output.mode says */
    const char *out_dir;    /* headless: write every frame as a PNG here (created) */
    double duration_s;      /* > 0: clean exit this long after the devices start (the end of
                             * lr_rig_create, when a sim script's time 0 is) */
    const char *stats_path; /* overrides the config's stats.path */
    const char *modbus_url; /* overrides every modbus device's url */
    lr_log log;             /* default: stderr */
    bool no_signals;        /* do not block signals or open the signalfd (in-process tests) */
    bool no_plan;           /* keep the scene's render settings despite a quality budget */
    const char *plan_table; /* the planner's measured table; NULL: lr_plan_default_table */
} lr_rig_opts;

typedef struct lr_rig_info {
    uint64_t frames;
    uint64_t events;          /* events that changed something */
    uint64_t reloads, reload_failures;
    double lamp_level;        /* last level written to the lamp driver, -1 none */
    const char *output;       /* "headless" or "kms" */
    const char *view;         /* "passes" or "preview" */
    bool idle;                /* no frame wanted: converged, no fade running */
} lr_rig_info;

int lr_rig_create(const lr_rig_opts *opts, lr_rig **out, lr_err *e);
/* Runs the loop until a stop signal, lr_rig_stop or the duration. */
int lr_rig_run(lr_rig *r, lr_err *e);
/* Runs the loop until now >= until_ns (or a stop); for tests that drive it in steps. */
int lr_rig_run_until(lr_rig *r, int64_t until_ns, lr_err *e);
/* What SIGTERM / SIGHUP do, for in-process callers. lr_rig_reload loads the config here and
 * now and returns its result: the loop waits for it. */
void lr_rig_stop(lr_rig *r);
int lr_rig_reload(lr_rig *r, lr_err *e);

/* The answer to lr_rig_reload_async: rc LR_OK when the new config runs, else the reason
 * (e: file, line, field) while the old one runs on. Called on the loop. */
typedef void (*lr_rig_reload_fn)(void *ctx, int rc, const lr_err *e);
#define LR_RIG_RELOAD_WAITERS 8
/* What SIGHUP does, answered: the config loads and plans in a job off the loop (after the one
 * running, if any: the answer is a reload that started after this call), and `done` is called
 * on the loop once it has been committed or has failed -- inside this call when no job could
 * be started. LR_EUNSUPPORTED when LR_RIG_RELOAD_WAITERS answers are already awaited. A rig
 * destroyed first never calls it: lr_rig_reload_forget is the caller's way out before that. */
int lr_rig_reload_async(lr_rig *r, lr_rig_reload_fn done, void *ctx, lr_err *e);
/* Drops the answers awaited with ctx (its connection closed). */
void lr_rig_reload_forget(lr_rig *r, void *ctx);
/* Safe level, device close, stats: the clean shutdown. NULL is a no-op. */
void lr_rig_destroy(lr_rig *r);

void lr_rig_get_info(const lr_rig *r, lr_rig_info *out);
/* The current scene (for tests: lr_scene_get on it). */
struct lr_scene *lr_rig_scene(lr_rig *r);

/* ---- for the HTTP endpoint (firmware/rig/http.h) and other publishers of the state ---- */

struct lr_rig_status;
/* The rig's status (firmware/rig/status_json.h); its pointers stay valid until the loop runs
 * again or the rig is reloaded. */
void lr_rig_get_status(lr_rig *r, struct lr_rig_status *out);
/* Moves control NAME (a binding's name) to position x in 0..1: an absolute event from the
 * binding's source (or "http" for a binding of any source) into the event ring, taken by
 * the control map at the loop's next drain like a device's event. LR_ENODEV: no binding of
 * that name; LR_EINVAL: x not in 0..1. */
int lr_rig_post_control(lr_rig *r, const char *name, double x, lr_err *e);
/* Switches to scene NAME: a value of the config's "scene" binding (by file name, with or
 * without ".json"; as an event through the control map, so the binding's index follows) or
 * else a shipped scene, configs/scenes/NAME.json (NAME: letters, digits, '_', '-'), loaded
 * on the loop. LR_ENODEV: neither. */
int lr_rig_post_scene(lr_rig *r, const char *name, lr_err *e);
/* The latest frame as RGBA8, rows top to bottom, read back from the view (valid until the
 * next call); *frame its number. NULL (e set) before the first frame. */
const unsigned char *lr_rig_frame_rgba(lr_rig *r, int *w, int *h, uint64_t *frame, lr_err *e);
/* The HTTP endpoint's port, 0 without one. */
int lr_rig_http_port(const lr_rig *r);

#endif
