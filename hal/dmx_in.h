/* lamprig hal — what the DMX receivers (sACN hal/sacn.h, Art-Net hal/artnet.h) share: channel
 * bindings, the loss setting, counters.
 *
 * A channel is a control: {control, universe, channel, fine}. An 8-bit channel's value v
 * (0..255) becomes the position v / 255; a 16-bit pair (coarse = channel, fine) becomes
 * (256 coarse + fine) / 65535. When the merged value of a universe changes a channel's
 * position, one LR_EV_ABSOLUTE event {source = device name, control, value 0..1} is emitted:
 * the control map binds it exactly as a fader ("control": "sacn/dimmer", curves, fades and
 * ranges as for any level binding). A channel a short universe does not carry keeps its value.
 *
 * Loss (every source of a universe gone: quiet for the loss time, or Stream_Terminated):
 * LR_DMX_HOLD keeps the look (the default: OLA sends only on change, so a lone OLA source
 * looks lost during every static look); LR_DMX_FADE moves each channel with a home position
 * to it over fade_ms (the rig passes the scene's own positions), channels without one hold. */
#ifndef LR_HAL_DMX_IN_H
#define LR_HAL_DMX_IN_H

#include <stdbool.h>
#include <stdint.h>

#include "hal/opt.h"

#define LR_DMX_MAX_CHANNELS 64
#define LR_DMX_MAX_UNIVERSES 16

typedef struct lr_dmx_channel {
    const char *control; /* event control name, required */
    int universe;        /* sACN 1..63999; Art-Net port-address 0..32767 */
    int channel;         /* 1..512 (the coarse byte of a 16-bit pair) */
    int fine;            /* 0: 8-bit; else 1..512, the fine byte's channel */
    double home;         /* LR_DMX_FADE: position 0..1 faded to on loss; NAN: hold */
} lr_dmx_channel;

typedef enum lr_dmx_loss {
    LR_DMX_HOLD = 0,
    LR_DMX_FADE,
} lr_dmx_loss;

/* A channel's options (hal/opt.h) as the rig config reads them. */
enum {
    LR_DMX_CH_CONTROL = 0,
    LR_DMX_CH_UNIVERSE,
    LR_DMX_CH_CHANNEL,
    LR_DMX_CH_FINE,
};
extern const lr_opt lr_sacn_channel_opts[];
extern const lr_opt lr_artnet_channel_opts[];

/* Packet results a receiver counts by kind (their names: lr_dmx_counters.bad_names). */
#define LR_DMX_MAX_KINDS 20

typedef struct lr_dmx_counters {
    uint64_t packets;      /* datagrams read */
    uint64_t taken;        /* level packets merged */
    uint64_t other;        /* well-formed but not for us: other universes, START codes, sync,
                            * discovery, other OpCodes */
    uint64_t sequence;     /* dropped by the sequence check */
    uint64_t full;         /* dropped: a source beyond max_sources */
    uint64_t preview;      /* dropped: preview data */
    uint64_t terminated;   /* Stream_Terminated packets */
    uint64_t losses;       /* universes that lost their last source */
    uint64_t polls;        /* Art-Net: ArtPoll answered */
    uint64_t replies;      /* Art-Net: ArtPollReply sent */
    uint64_t polls_limited;/* Art-Net: ArtPoll left unanswered by the reply limit (a poller
                            * answered under 1 s ago, or over 20 replies a second) */
    uint64_t bad;          /* malformed, all kinds */
    uint64_t bad_kind[LR_DMX_MAX_KINDS]; /* per parser result (lr_sacn_result, lr_artnet_result) */
    uint64_t events;       /* channel events emitted */
} lr_dmx_counters;

#endif
