/* lamprig hal — Art-Net 4 receiver (a node): console channels in as control events.
 *
 * One UDP socket on port 6454 (bind 0.0.0.0 by default, broadcasts received). ArtDmx for the
 * configured port-addresses (Net << 8 | Sub-Net << 4 | Universe, 0..32767) is merged per
 * port-address from at most two senders (Art-Net's merge: HTP or LTP; a sender quiet for
 * merge_timeout_ms, 10 s in the standard, leaves the merge; a third is refused), and the
 * channels it moves are emitted (hal/dmx_in.h). An ArtPoll is answered with ArtPollReply
 * packets (to the poller's address and port) listing the port-addresses taken, four per reply
 * per Net/Sub-Net; one is broadcast to `announce` when the socket opens, since some
 * controllers (OLA) send nothing to a node that has not answered their poll. Malformed
 * packets are counted by kind (bad_kind[] by lr_artnet_result) and the first of each kind is
 * logged; at most max_packets datagrams are read per dispatch. */
#ifndef LR_HAL_ARTNET_H
#define LR_HAL_ARTNET_H

#include <stdbool.h>

#include "hal/dev.h"
#include "hal/dmx_in.h"
#include "hal/dmx_merge.h"
#include "hal/opt.h"
#include "render/base/err.h"

typedef struct lr_artnet_desc {
    lr_dev_desc dev;          /* name default "artnet" */
    const char *bind;         /* NULL/"": 0.0.0.0 */
    const char *announce;     /* where the ArtPollReply at start goes; NULL: 255.255.255.255,
                               * "" or "none": nowhere */
    const char *short_name;   /* in ArtPollReply; NULL: "lamprig" */
    const lr_dmx_channel *channels;
    int n_channels;
    lr_dmx_merge_mode merge;
    lr_dmx_loss loss;
    /* 0: the default (lr_artnet_opts) */
    int port, merge_timeout_ms, fade_ms, max_packets;
} lr_artnet_desc;

enum {
    LR_ARTNET_OPT_BIND = 0,
    LR_ARTNET_OPT_PORT,
    LR_ARTNET_OPT_ANNOUNCE,
    LR_ARTNET_OPT_SHORT_NAME,
    LR_ARTNET_OPT_MERGE,
    LR_ARTNET_OPT_MERGE_TIMEOUT_MS,
    LR_ARTNET_OPT_LOSS,
    LR_ARTNET_OPT_FADE_MS,
    LR_ARTNET_OPT_MAX_PACKETS,
    LR_ARTNET_OPT_CHANNELS,
};
extern const lr_opt lr_artnet_opts[];

typedef struct lr_artnet lr_artnet;

int lr_artnet_create(const lr_artnet_desc *desc, lr_artnet **out, lr_err *e);
void lr_artnet_destroy(lr_artnet *a);
lr_dev *lr_artnet_dev(lr_artnet *a);
void lr_artnet_get_counters(const lr_artnet *a, lr_dmx_counters *out);

#endif
