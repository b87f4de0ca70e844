/* lamprig hal — the device interface every back end (gpio, hid, usb, modbus, sim) offers to
 * the firmware's single poll/epoll loop.
 *
 * The loop, per iteration:
 *     n = lr_dev_pollfds(d, fds, max);          // descriptors to watch (may change, see below)
 *     t = lr_dev_next_deadline(d);               // earliest timer: retry, debounce, poll, script
 *     poll(all fds, timeout = min over devices of (t - now), or -1 when every t is LR_NO_DEADLINE)
 *     lr_dev_dispatch(d, now) for every device whose fd is ready or whose deadline has passed
 *
 * dispatch never blocks for long: descriptors are non-blocking and reads take only what is
 * ready (libmodbus only connects; the Modbus frames are read without waiting, see
 * hal/modbus.h). Calling dispatch when nothing is ready is harmless, so an epoll
 * loop may simply dispatch every device it was woken for. No threads are created by hal/
 * (hidapi's libusb back end runs its own reader thread internally; see hal/hid.h).
 *
 * State: a device is OPEN, MISSING (not there: no chip, no device node, connection refused),
 * RETRYING (there but failing: I/O errors, timeouts, garbage) or DONE (a sim script that has
 * played out). MISSING and RETRYING devices are reopened with exponential backoff; each state
 * change (and only a change) is logged once through the descriptor's log hook, and
 * lr_dev_status() keeps the last such line. A missing device never stops the others.
 *
 * The set of descriptors changes when a device is (re)opened or lost; lr_dev_fd_generation()
 * changes with it, so an epoll loop knows when to re-register. A poll loop can simply ask
 * lr_dev_pollfds every iteration.
 */
#ifndef LR_HAL_DEV_H
#define LR_HAL_DEV_H

#include <poll.h>
#include <stdbool.h>
#include <stdint.h>

#include "hal/event.h"
#include "hal/log.h"
#include "hal/opt.h"

#define LR_NO_DEADLINE INT64_MAX

typedef enum lr_dev_state {
    LR_DEV_OPEN = 0,
    LR_DEV_MISSING,
    LR_DEV_RETRYING,
    LR_DEV_DONE,
} lr_dev_state;

/* What every back-end descriptor starts with (as its `dev` member). */
typedef struct lr_dev_desc {
    const char *name;    /* source name in events and log lines; default: the back end ("gpio") */
    lr_event_sink sink;  /* required: where events go (a callback, or lr_event_ring_sink()) */
    lr_log log;          /* default: stderr (see hal/log.h) */
    int retry_min_ms;    /* first reopen delay after a failure; default 250 ms */
    int retry_max_ms;    /* backoff cap; default 10000 ms */
    bool required;       /* create fails with LR_ENODEV (and the message) when the device cannot
                          * be opened at start; default false: log, keep retrying, keep running */
} lr_dev_desc;

/* The lr_dev_desc fields a configuration sets, for every back end (hal/opt.h). */
enum {
    LR_DEV_OPT_NAME = 0,
    LR_DEV_OPT_REQUIRED,
    LR_DEV_OPT_RETRY_MIN_MS,
    LR_DEV_OPT_RETRY_MAX_MS,
};
extern const lr_opt lr_dev_opts[];

typedef struct lr_dev lr_dev;

/* CLOCK_MONOTONIC now, in nanoseconds: the clock of every t_ns and deadline in hal/. */
int64_t lr_now_ns(void);

/* Writes up to max pollfds (fd, events) and returns how many the device has now (which may be
 * more than max: call again with a larger array). 0 while the device is not open. */
int lr_dev_pollfds(lr_dev *d, struct pollfd *fds, int max);
/* Reads whatever is ready, runs due timers (retries, debounce, polls, script events) and emits
 * events to the sink. Returns the number of events emitted. Errors never escape: they change
 * the state (and are logged once). */
int lr_dev_dispatch(lr_dev *d, int64_t now_ns);
/* Earliest time dispatch has work to do without an fd becoming ready, or LR_NO_DEADLINE. A
 * deadline in the past means "dispatch now". */
int64_t lr_dev_next_deadline(lr_dev *d);
/* Drops the backoff and makes the next dispatch try to reopen the device now, e.g. when the usb
 * back end reports that a matching device arrived. No effect on an open device. */
void lr_dev_retry_now(lr_dev *d, int64_t now_ns);

lr_dev_state lr_dev_get_state(const lr_dev *d);
const char *lr_dev_state_name(lr_dev_state s); /* "open", "missing", "retrying", "done" */
const char *lr_dev_name(const lr_dev *d);
/* "gpio", "hid", "usb", "modbus", "sim", "sacn", "artnet", "osc" */
const char *lr_dev_kind(const lr_dev *d);
/* The last state line logged, e.g. "gpio: gpiochip0: cannot open chip: No such file or
 * directory; retrying with backoff". Owned by the device, valid until the next dispatch. */
const char *lr_dev_status(const lr_dev *d);
unsigned lr_dev_fd_generation(const lr_dev *d);
/* Consecutive failed (re)open attempts since the device last worked: since it was last open,
 * or for a device whose open proves nothing (Modbus over TCP: a peer that accepts and closes
 * at once), since its last good answer; a loss after an unproven open counts as a failure. */
unsigned lr_dev_failures(const lr_dev *d);

/* Destroys the back end behind d (same as lr_gpio_destroy(...) etc.); NULL is a no-op. */
void lr_dev_destroy(lr_dev *d);

#endif
