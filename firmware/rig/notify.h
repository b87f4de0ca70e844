/* lamprig firmware — the service manager's side channel (systemd's sd_notify protocol).
 *
 * Under a `Type=notify` unit systemd passes NOTIFY_SOCKET (a unix datagram socket) and, with
 * `WatchdogSec=`, WATCHDOG_USEC. The rig loop tells it READY=1 once the rig is built, pings
 * WATCHDOG=1 from the loop itself (so a hung loop stops the pings and systemd restarts the
 * service), RELOADING=1 ... READY=1 around a SIGHUP reload, STOPPING=1 on shutdown, and a
 * STATUS= line `systemctl status` shows. Without NOTIFY_SOCKET every call is a no-op; without
 * WATCHDOG_USEC there is no ping deadline. Messages are sent with libsystemd's sd_notify.
 */
#ifndef LR_NOTIFY_H
#define LR_NOTIFY_H

#include <stdint.h>

#include "render/base/err.h"

typedef struct lr_notify lr_notify;

/* Reads the environment once (WATCHDOG_USEC, and WATCHDOG_PID when set, must be for this
 * process). `now_ns` is CLOCK_MONOTONIC (lr_now_ns). */
int lr_notify_create(int64_t now_ns, lr_notify **out, lr_err *e);
void lr_notify_destroy(lr_notify *n);

/* The ping period: half of WATCHDOG_USEC, as sd_watchdog_enabled(3) advises; 0 without. */
int64_t lr_notify_interval_ns(const lr_notify *n);
/* When the loop must next wake to ping; INT64_MAX without a watchdog. */
int64_t lr_notify_deadline(const lr_notify *n);
/* Sends WATCHDOG=1 (with STATUS=status when not NULL) when the deadline has passed, and
 * moves the deadline one period past now. Call on every wake of the loop. */
void lr_notify_tick(lr_notify *n, int64_t now_ns, const char *status);

void lr_notify_ready(lr_notify *n, const char *status);
/* RELOADING=1 with MONOTONIC_USEC (what systemd >= 253 needs for Type=notify-reload). */
void lr_notify_reloading(lr_notify *n, int64_t now_ns);
void lr_notify_stopping(lr_notify *n);

/* Messages sent so far (for the rig's log and tests). */
uint64_t lr_notify_pings(const lr_notify *n);

#endif
