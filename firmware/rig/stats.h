/* lamprig firmware — run statistics: per control event, the time from the event's timestamp
 * to the end of the frame that first shows it; per frame, the passes that ran and their
 * times. Written as JSON, atomically (render/base/atomic_file.h), periodically and at exit.
 *
 * {
 *   "config": "configs/rig/sim.json", "duration_s": 12.5,
 *   "frames": 321, "events": 40, "events_unmatched": 3, "garbage": 0,
 *   "devices": [{"name": "panel", "kind": "modbus", "state": "open",
 *                "modbus": {"requests": 812, "responses": 806, "timeouts": 2, "stale": 4, ...}},
 *               {"name": "sacn", "kind": "sacn", "state": "open",
 *                "input": {"packets": 9120, "taken": 9100, "bad": 3, "bad_acn-id": 3, ...}}],
 *               (OSC, "input": {"messages": .., "events": .., "bad": .., "bad_address": ..})
 *   "latency_ms": {"n": 40, "min": 0.8, "median": 2.1, "p99": 7.9, "max": 8.3, "mean": 2.4},
 *   "converge_ms": {"n": 40, "median": 310, "p99": 2100, "max": 2300},
 *   "settle_ms": {"n": 6, "median": 1200, "p99": 1900, "max": 1900},
 *   "event_log": [{"source": "sim", "control": "dimmer", "kind": "absolute", "value": 0.5,
 *                  "t_s": 1.25, "frame": 38, "latency_ms": 2.1, "stage": "final",
 *                  "converge_ms": 310, "rested": true}, ...],
 *                                                                            (last 4096)
 *   "frame_log": [{"index": 38, "t_s": 1.252, "passes": ["compose"], "ms": [0,0,0,0.4],
 *                  "total_ms": 0.4, "samples": 64, "converged": true,
 *                  "stage": "final", "batch": 12}, ...]                       (last 4096)
 * }
 * latency_ms: event -> the end of the first frame that shows it, at whatever stage
 * (render/async/async.h: a preview, refining or final image); converge_ms: event -> the first
 * frame that shows it converged (the renderer's own settings, accumulation done). An event's
 * "stage" is that of the frame that first showed it. settle_ms: the same for the newest event
 * each converged frame shows (its "rested" is true): from the controls' last change to the
 * converged image, what a designer waits after letting go of a control (an event that a
 * later one supersedes before convergence waits for that one as well: converge_ms counts it,
 * settle_ms does not).
 * t_s are seconds since the stats were created (CLOCK_MONOTONIC). The summary covers every
 * event in constant memory: n, min, max, mean exact, median and p99 from a histogram within
 * 0.5 % (firmware/rig/lat_hist.h). Nothing here grows with the number of events or frames.
 */
#ifndef LR_RIG_STATS_H
#define LR_RIG_STATS_H

#include <stdint.h>

#include "hal/event.h"
#include "hal/modbus.h"
#include "render/base/err.h"
#include "render/async/async.h"
#include "render/renderer.h"

typedef struct lr_rig_stats lr_rig_stats;

int lr_rig_stats_create(int64_t start_ns, lr_rig_stats **out, lr_err *e);
void lr_rig_stats_destroy(lr_rig_stats *s);

/* A control event that changed something: pending until the next frame. */
void lr_rig_stats_event(lr_rig_stats *s, const lr_event *ev);
/* An event no binding took. */
void lr_rig_stats_unmatched(lr_rig_stats *s);
/* The loop applied the pending events: the change is batch `batch` of render/async (0: it
 * needs no new images, the next blend shows it). */
void lr_rig_stats_tag(lr_rig_stats *s, uint64_t batch);

/* What a frame shows: images that include every change up to `batch`, at `stage`. */
typedef struct lr_rig_frame_info {
    uint64_t batch;
    lr_async_stage stage;
    bool converged;
} lr_rig_frame_info;

/* A frame finished (presented or written) at done_ns: if it ran at least one pass, every
 * pending event its images include gets its latency (and, when converged, its convergence
 * time); a frame with no pass (the previous image again) shows none. */
void lr_rig_stats_frame_shown(lr_rig_stats *s, const lr_frame_stats *f,
                              const lr_rig_frame_info *info, int64_t done_ns);
/* The same for a renderer on the loop: every frame shows every event before it. */
void lr_rig_stats_frame(lr_rig_stats *s, const lr_frame_stats *f, int64_t done_ns);
/* Event -> converged image quantile, ms; NaN when none. */
double lr_rig_stats_converge_ms(const lr_rig_stats *s, double q);
/* Controls' rest -> converged image quantile, ms (settle_ms above); NaN when none. */
double lr_rig_stats_settle_ms(const lr_rig_stats *s, double q);

/* A spatial-AR projector frame (calib/ar_frame.h): its clipping, kept for the stats file
 * ("ar": frames, last and worst clipped fraction of pixels and of the light). */
void lr_rig_stats_ar(lr_rig_stats *s, double clipped_pixels, double clipped_light);

int lr_rig_stats_pending(const lr_rig_stats *s);
uint64_t lr_rig_stats_frames(const lr_rig_stats *s);
uint64_t lr_rig_stats_events(const lr_rig_stats *s); /* with a latency */
/* Latency quantile q in [0, 1] over every event so far, ms, within lat_hist.h's bound; NaN
 * when none. */
double lr_rig_stats_latency_ms(const lr_rig_stats *s, double q);

/* One device as the stats file shows it ("devices"): its state and, for a Modbus link, every
 * counter of lr_modbus_counters (stale answers, timeouts, ...). */
typedef struct lr_rig_stats_counter {
    const char *prefix, *name; /* the key is prefix + name ("bad_" "acn-id") */
    uint64_t value;
} lr_rig_stats_counter;

typedef struct lr_rig_stats_dev {
    const char *name, *kind, *state;
    const lr_modbus_counters *modbus; /* NULL: not a Modbus device */
    /* A console input (sacn, artnet, osc): its counters as "input": {name: value}, the bad
     * packets by kind among them ("bad_acn-id"); n_input 0: none. */
    const lr_rig_stats_counter *input;
    int n_input;
} lr_rig_stats_dev;

/* Writes the JSON above to path atomically. config may be NULL; garbage counts events with
 * non-finite values; devs[0..n_devs) the devices. */
int lr_rig_stats_write(const lr_rig_stats *s, const char *path, const char *config,
                       int64_t now_ns, unsigned garbage, const lr_rig_stats_dev *devs,
                       int n_devs, lr_err *e);

#endif
