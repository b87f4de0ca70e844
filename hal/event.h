/* lamprig hal — the one normalized control event every back end emits.
 *
 *   {source, control, kind, value, t_ns}
 *
 * source   the device's name from the config ("gpio", "panel", "powermate"); a sim script may
 *          speak for any source ("modbus/dimmer") so that control maps can be tested headless.
 * control  the control on that device ("knob1", "dimmer", "jog", "button3").
 * kind     LR_EV_DELTA     relative steps: encoder detents, PowerMate ticks, jog counts (signed)
 *          LR_EV_ABSOLUTE  a position: dimmer 0..1, shuttle ring -1..1, usb "present" 0/1
 *          LR_EV_PRESS     value 1
 *          LR_EV_RELEASE   value 0
 * t_ns     CLOCK_MONOTONIC nanoseconds of the physical event where the device says (kernel GPIO
 *          edge timestamps, script times), else of the moment it was read.
 *
 * Acceleration, curves and ranges are not applied here: that is the control map's job
 * (firmware/), in one place.
 */
#ifndef LR_HAL_EVENT_H
#define LR_HAL_EVENT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "render/base/err.h"

#define LR_EVENT_NAME_MAX 32 /* bytes including the terminating NUL */

typedef enum lr_event_kind {
    LR_EV_DELTA = 0,
    LR_EV_ABSOLUTE,
    LR_EV_PRESS,
    LR_EV_RELEASE,
} lr_event_kind;

typedef struct lr_event {
    char source[LR_EVENT_NAME_MAX];
    char control[LR_EVENT_NAME_MAX];
    lr_event_kind kind;
    double value;
    int64_t t_ns;
} lr_event;

/* Called synchronously from lr_dev_dispatch (never from another thread). ev is only valid
 * during the call. */
typedef void (*lr_event_fn)(void *user, const lr_event *ev);

typedef struct lr_event_sink {
    lr_event_fn fn;
    void *user;
} lr_event_sink;

/* "delta", "absolute", "press", "release". */
const char *lr_event_kind_name(lr_event_kind kind);
/* Parses one of the names above; LR_EPARSE otherwise. */
int lr_event_kind_parse(const char *name, lr_event_kind *out);

/* Fills an event; names longer than LR_EVENT_NAME_MAX - 1 are truncated. */
void lr_event_set(lr_event *ev, const char *source, const char *control, lr_event_kind kind,
                  double value, int64_t t_ns);

/* A fixed-size FIFO of events, for callers that prefer to drain events after dispatch rather
 * than handle them in a callback. When full, the oldest event is dropped and counted. */
typedef struct lr_event_ring lr_event_ring;

/* capacity 0 means 256. */
int lr_event_ring_create(size_t capacity, lr_event_ring **out, lr_err *e);
void lr_event_ring_destroy(lr_event_ring *ring);
/* An lr_event_fn: user is the lr_event_ring. */
void lr_event_ring_push(void *ring, const lr_event *ev);
/* A sink that pushes into ring; put it in a device descriptor. */
lr_event_sink lr_event_ring_sink(lr_event_ring *ring);
/* Takes the oldest event; false when empty. */
bool lr_event_ring_pop(lr_event_ring *ring, lr_event *out);
size_t lr_event_ring_count(const lr_event_ring *ring);
uint64_t lr_event_ring_dropped(const lr_event_ring *ring);

#endif
