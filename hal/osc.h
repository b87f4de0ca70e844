/* lamprig hal — OSC input (liblo): tablets, mapping tools and consoles as control events.
 *
 * Addresses (prefix default "/lamprig"), over UDP on `port` (all interfaces: liblo 0.31
 * cannot bind one address):
 *   PREFIX/dimmer f              absolute event "dimmer" with the value (i, h, d also taken)
 *   PREFIX/control/NAME f        absolute event NAME (1..31 of A-Z a-z 0-9 _ . -)
 *   PREFIX/scene s               absolute event `scene_control` (default "scene") at
 *                                (k + 0.5) / n for the k-th of the n configured `scenes`: a
 *                                cycle binding on that control whose values list the same
 *                                scenes in the same order picks floor(x n) = k
 *   PREFIX/scene i               the same by index k
 * Anything else is counted (unknown address, wrong argument types, unknown scene, non-finite
 * values, packets liblo could not parse) and the first of each kind logged. TCP is not offered:
 * liblo reads its TCP connections on descriptors it does not expose, so they cannot join the
 * rig's poll loop.
 *
 * Loop: liblo's server is polled through lo_server_get_socket_fd and read with
 * lo_server_recv_noblock(s, 0), at most max_packets messages per dispatch; no liblo thread.
 * Timetagged bundles are dispatched at once (liblo's queue is off): there is no hidden timer. */
#ifndef LR_HAL_OSC_H
#define LR_HAL_OSC_H

#include <stdint.h>

#include "hal/dev.h"
#include "hal/opt.h"
#include "render/base/err.h"

#define LR_OSC_MAX_SCENES 32

typedef struct lr_osc_desc {
    lr_dev_desc dev;            /* name default "osc" */
    const char *prefix;         /* NULL: "/lamprig" */
    const char *scene_control;  /* NULL: "scene" */
    const char *const *scenes;  /* names for PREFIX/scene s */
    int n_scenes;
    int port, max_packets;      /* 0: the default (lr_osc_opts) */
} lr_osc_desc;

enum {
    LR_OSC_OPT_PORT = 0,
    LR_OSC_OPT_PREFIX,
    LR_OSC_OPT_SCENES,
    LR_OSC_OPT_SCENE_CONTROL,
    LR_OSC_OPT_MAX_PACKETS,
};
extern const lr_opt lr_osc_opts[];

typedef enum lr_osc_bad {
    LR_OSC_BAD_ADDRESS = 0, /* not one of ours */
    LR_OSC_BAD_TYPES,       /* wrong argument count or types */
    LR_OSC_BAD_VALUE,       /* non-finite number, bad control name */
    LR_OSC_BAD_SCENE,       /* a scene name or index not configured */
    LR_OSC_BAD_PACKET,      /* liblo could not parse it */
    LR_OSC_N_BAD
} lr_osc_bad;

typedef struct lr_osc_counters {
    uint64_t messages;      /* received */
    uint64_t events;        /* emitted */
    uint64_t bad;
    uint64_t bad_kind[LR_OSC_N_BAD];
} lr_osc_counters;

typedef struct lr_osc lr_osc;

int lr_osc_create(const lr_osc_desc *desc, lr_osc **out, lr_err *e);
void lr_osc_destroy(lr_osc *o);
lr_dev *lr_osc_dev(lr_osc *o);
void lr_osc_get_counters(const lr_osc *o, lr_osc_counters *out);
const char *lr_osc_bad_name(lr_osc_bad k);

#endif
