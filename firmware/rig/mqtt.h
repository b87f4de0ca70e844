/* lamprig firmware — several rigs in step over MQTT (libmosquitto), on the rig's poll loop.
 *
 * Each rig (config "mqtt": {"broker": "HOST:PORT", "rig": "NAME", "role": "follower"}):
 *   - publishes its status, retained, on lamprig/NAME/status (JSON, mqtt_status.c) when it
 *     connects, every status_period_s and after each change it applied has shown in a frame;
 *     its last will (retained) is "offline", and a clean shutdown publishes "offline" too;
 *   - follower: subscribes to lamprig/all/control/+ and lamprig/all/scene (QoS 1) and applies
 *     each command (mqtt_payload.h) at the first frame after its apply_at on the rig's own
 *     CLOCK_REALTIME (chrony-synced in production, so two rigs agree to the clocks' offset); a
 *     rig that joins late, restarts or reconnects gets the current state from the retained
 *     messages and applies it at once (apply_at in the past). A retained message already
 *     applied (the broker sends it again after a reconnect) is not applied twice, so a local
 *     knob moved since is not overridden. A scene command ahead of its apply_at is loaded in
 *     advance by the rig (lr_mqtt_pending_scene), so its switch is a swap.
 *   - leader: a follower whose own devices' controls go to every rig (lr_mqtt_publish_cmd,
 *     apply_at = now + lead_ms) and are applied on it when they come back (rig.c).
 *
 * Nothing blocks the loop: the client's socket is in the poll set (mosquitto_socket, read,
 * write when mosquitto_want_write, mosquitto_loop_misc for the keepalive), the connect is
 * non-blocking (mosquitto_connect_async / mosquitto_reconnect_async) and a lost or refused
 * connection is retried with hal/backoff.h's schedule (retry_min_ms .. retry_max_ms), logged
 * once per outage. The broker's host should be a numeric address: libmosquitto resolves a name
 * with getaddrinfo, which blocks (an /etc/hosts name answers at once). Bad payloads are logged
 * with their topic and counted (status "mqtt.bad"), never applied.
 *
 * No thread: libmosquitto's own thread (mosquitto_loop_start) is not used.
 */
#ifndef LR_RIG_MQTT_H
#define LR_RIG_MQTT_H

#include <poll.h>
#include <stdbool.h>
#include <stdint.h>

#include "firmware/rig/config.h"
#include "firmware/rig/mqtt_payload.h"
#include "firmware/rig/stats.h"
#include "firmware/rig/status_json.h"
#include "hal/log.h"
#include "render/base/err.h"

typedef struct lr_mqtt lr_mqtt;

/* The rig's figures for a status document (mqtt_status.c); strings may be NULL. */

typedef struct lr_mqtt_counters {
    uint64_t received; /* command messages */
    uint64_t applied;  /* commands taken by the rig (lr_mqtt_take) */
    uint64_t bad;      /* payloads refused (parse errors, unknown controls or scenes) */
    uint64_t connects; /* successful connections */
} lr_mqtt_counters;

typedef struct lr_mqtt_desc {
    const lr_rig_config *cfg; /* its "mqtt" block and the binding names; outlives the client
                               * or is replaced with lr_mqtt_set_config */
    lr_log log;
    /* Fills the rig's figures when a status is to be published. */
    void (*status)(void *user, lr_rig_status *st); /* lr_rig_get_status */
    void *user;
} lr_mqtt_desc;

/* Starts the first (non-blocking) connect at once. Fails only for a bad descriptor or an
 * out-of-memory client: an unreachable broker is retried. */
int lr_mqtt_create(const lr_mqtt_desc *d, int64_t now_ns, lr_mqtt **out, lr_err *e);
/* Publishes "offline" (retained) when connected, disconnects, waiting at most 200 ms for the
 * socket to take it. NULL is a no-op. */
void lr_mqtt_destroy(lr_mqtt *m);
/* A reload's new config with the same "mqtt" block (the binding names may differ). */
void lr_mqtt_set_config(lr_mqtt *m, const lr_rig_config *cfg);
/* Whether two configs' "mqtt" blocks are the same connection (else: a new client). */
bool lr_mqtt_same(const lr_rig_mqtt *a, const lr_rig_mqtt *b);

/* The socket to poll (0 or 1 entries written). */
int lr_mqtt_pollfd(const lr_mqtt *m, struct pollfd *fd);
/* The next time (CLOCK_MONOTONIC ns) dispatch wants to run: a reconnect, the keepalive, a
 * status, or a pending command's apply_at (converted from CLOCK_REALTIME at now). */
int64_t lr_mqtt_deadline(const lr_mqtt *m, int64_t now_ns, int64_t now_rt_ns);
/* Reads, writes, keepalive, reconnects and status; revents of the polled socket (0: none). */
void lr_mqtt_dispatch(lr_mqtt *m, short revents, int64_t now_ns);
/* The next command due at now_rt_ns (apply_at <= now, or none given): a scene first, then by
 * apply_at. false when none is due. The command counts as applied; its frame is recorded by
 * the next lr_mqtt_frame. */
bool lr_mqtt_take(lr_mqtt *m, int64_t now_rt_ns, lr_mqtt_cmd *out);
/* The scene command waiting for its apply_at, if any (not taken: the rig loads that scene
 * ahead, so the switch at apply_at is a swap). */
bool lr_mqtt_pending_scene(const lr_mqtt *m, lr_mqtt_cmd *out);
/* The rig could not apply a command it took (a scene that does not load): logged, counted. */
void lr_mqtt_refuse(lr_mqtt *m, const lr_mqtt_cmd *c, const char *why);
/* A frame was drawn (index as in --out-dir's frame_NNNNNN, CLOCK_REALTIME at its end). */
void lr_mqtt_frame(lr_mqtt *m, uint64_t index, int64_t now_rt_ns);

bool lr_mqtt_connected(const lr_mqtt *m);
/* Publishes a command to every rig (retained, QoS 1), this one included; false when not
 * connected or the publish failed (logged). The leader role's devices (rig.c). */
bool lr_mqtt_publish_cmd(lr_mqtt *m, const lr_mqtt_cmd *c);
void lr_mqtt_get_counters(const lr_mqtt *m, lr_mqtt_counters *out);

int64_t lr_mqtt_realtime_ns(void);

/* The status document (mqtt_status.c): the rig's status (firmware/rig/status_json.h, the
 * same members as GET /api/status) with the rig's name, its state, the time, the link's
 * counters and the last command applied with its first frame. Returns a malloc'd string, NULL
 * when out of memory. */
typedef struct lr_mqtt_last {
    bool valid;
    lr_mqtt_cmd cmd;
    int64_t applied_rt_ns; /* when the rig took it */
    bool framed;
    uint64_t frame;        /* the first frame after it */
    int64_t frame_rt_ns;   /* that frame's end */
} lr_mqtt_last;
char *lr_mqtt_status_json(const char *rig, const lr_rig_status *st, int64_t now_rt_ns,
                          const lr_mqtt_counters *c, const lr_mqtt_last *last);

#endif
