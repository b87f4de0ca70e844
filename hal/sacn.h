/* lamprig hal — sACN (ANSI E1.31) receiver: console channels in as control events.
 *
 * One UDP socket on port 5568 (bind 0.0.0.0 by default): unicast packets to this host are
 * taken, and the socket joins the multicast group 239.255.hi.lo of every configured universe
 * (on `interface`, an IPv4 address of the NIC; default: the kernel's choice). A host with no
 * multicast route (a bare loopback, a network not up yet) cannot join: logged once, unicast
 * still works, and the join is tried again every 5 s until it succeeds (logged once).
 *
 * Each datagram is parsed (hal/sacn_packet.h); a malformed one is counted by kind and the first
 * of each kind logged with its sender. Data for configured universes is merged per universe
 * (hal/dmx_merge.h: priority, HTP, sequence, max_sources, loss after loss_ms, Stream_Terminated)
 * and the channels it moves are emitted (hal/dmx_in.h). Preview packets are dropped unless
 * `preview` is set (E1.31 6.2.6: not for live output). START codes other than 0 (0xDD
 * per-address priority ...) are ignored. At most max_packets datagrams are read per dispatch, so
 * a flood cannot hold the loop: the rest wait for the next turn (deadline: now). */
#ifndef LR_HAL_SACN_H
#define LR_HAL_SACN_H

#include <stdbool.h>

#include "hal/dev.h"
#include "hal/dmx_in.h"
#include "hal/opt.h"
#include "render/base/err.h"

typedef struct lr_sacn_desc {
    lr_dev_desc dev;          /* name default "sacn" */
    const char *bind;         /* IPv4 address to bind; NULL/"": 0.0.0.0 */
    const char *interface;    /* multicast interface address; NULL/"": the kernel's choice */
    bool unicast_only;        /* do not join the multicast groups */
    const lr_dmx_channel *channels;
    int n_channels;           /* 1..LR_DMX_MAX_CHANNELS */
    lr_dmx_loss loss;
    bool preview;             /* take preview data too */
    /* 0: the default (lr_sacn_opts) */
    int port, max_sources, loss_ms, fade_ms, max_packets;
} lr_sacn_desc;

enum {
    LR_SACN_OPT_BIND = 0,
    LR_SACN_OPT_PORT,
    LR_SACN_OPT_INTERFACE,
    LR_SACN_OPT_UNICAST_ONLY,
    LR_SACN_OPT_MAX_SOURCES,
    LR_SACN_OPT_LOSS_MS,
    LR_SACN_OPT_LOSS,
    LR_SACN_OPT_FADE_MS,
    LR_SACN_OPT_PREVIEW,
    LR_SACN_OPT_MAX_PACKETS,
    LR_SACN_OPT_CHANNELS,
};
extern const lr_opt lr_sacn_opts[];

typedef struct lr_sacn lr_sacn;

int lr_sacn_create(const lr_sacn_desc *desc, lr_sacn **out, lr_err *e);
void lr_sacn_destroy(lr_sacn *s);
lr_dev *lr_sacn_dev(lr_sacn *s);
/* bad_kind[] is indexed by lr_sacn_result. */
void lr_sacn_get_counters(const lr_sacn *s, lr_dmx_counters *out);
/* The UDP port the open socket is bound to; 0 while closed. */
int lr_sacn_port(const lr_sacn *s);

#endif
