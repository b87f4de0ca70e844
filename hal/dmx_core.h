/* lamprig hal — PRIVATE: the part of the sACN and Art-Net receivers that is not sockets:
 * universes with their merge, channel bindings, loss and fade, bad-packet counting and its
 * one log line per kind. Pure apart from emitting through the device. */
#ifndef LR_HAL_DMX_CORE_H
#define LR_HAL_DMX_CORE_H

#include "hal/dev_impl.h"
#include "hal/dmx_in.h"
#include "hal/dmx_merge.h"

typedef struct dmx_universe {
    int number;
    lr_dmx_merge merge;
    bool live; /* has had a source since the last loss */
    bool was_lost; /* lost its sources at least once: the next source is logged */
} dmx_universe;

typedef struct dmx_chan {
    char control[LR_EVENT_NAME_MAX];
    int uni;           /* index into universes */
    int coarse, fine;  /* 0-based slots; fine -1: 8-bit */
    double home;
    bool have;
    double last;       /* the position last emitted */
    bool fading;
    double fade_from;
    int64_t fade_start;
} dmx_chan;

typedef struct dmx_core {
    lr_dev *dev;
    dmx_universe uni[LR_DMX_MAX_UNIVERSES];
    int n_uni;
    dmx_chan ch[LR_DMX_MAX_CHANNELS];
    int n_ch;
    lr_dmx_loss loss;
    int64_t fade_ns;
    int64_t fade_next; /* the next step of a loss fade */
    const char *const *kind_names; /* per bad kind, for the log line */
    bool kind_logged[LR_DMX_MAX_KINDS];
    lr_log_limit loss_limit; /* loss and recovery lines */
    lr_dmx_counters c;
} dmx_core;

typedef struct dmx_core_cfg {
    const lr_dmx_channel *channels;
    int n_channels;
    const lr_opt *channel_opts; /* ranges of universe, channel, fine */
    lr_dmx_merge_cfg merge;
    lr_dmx_loss loss;
    int fade_ms;
    const char *const *kind_names;
} dmx_core_cfg;

/* Checks and copies the channels (the universes are those the channels name). */
int dmx_core_init(dmx_core *k, lr_dev *dev, const dmx_core_cfg *cfg, lr_err *e);
/* Index of universe number, -1 when no channel is on it. */
int dmx_core_universe(const dmx_core *k, int number);
/* One level packet from a source; emits the channels it moved. */
lr_dmx_take dmx_core_put(dmx_core *k, int uni, const uint8_t key[LR_DMX_KEY_LEN], int priority,
                         int seq, const uint8_t *slots, int n, int64_t now_ns);
void dmx_core_terminate(dmx_core *k, int uni, const uint8_t key[LR_DMX_KEY_LEN], int64_t now_ns);
/* Timeouts and fades due at now_ns. */
void dmx_core_tick(dmx_core *k, int64_t now_ns);
int64_t dmx_core_deadline(const dmx_core *k);
/* A malformed packet of kind (an index into kind_names): counted; the first of each kind is
 * logged (with the sender), later ones only counted. */
void dmx_core_bad(dmx_core *k, int kind, const char *from, int64_t now_ns);
/* The universes as text for the device's ident: "1, 2, 7". */
void dmx_core_universes_text(const dmx_core *k, char *buf, size_t n);

/* A non-blocking UDP socket bound to bind_addr (an IPv4 address; NULL or "" any) and port,
 * SO_REUSEADDR (a console on the same host may share the port, as OLA does). */
int dmx_udp_open(const char *bind_addr, int port, bool broadcast, int *fd, lr_err *e);
/* "192.0.2.7:5568" */
void dmx_addr_text(const void *sockaddr_in, char *buf, size_t n);

#endif
