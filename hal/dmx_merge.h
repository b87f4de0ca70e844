/* lamprig hal — merging the DMX sources of one universe, pure (explicit times, no clock).
 *
 * sACN (E1.31-2018):
 *   - the sources with the highest priority (0..200) win; among sources of that priority each
 *     slot takes the highest value (HTP); a slot a short universe lacks does not contribute;
 *   - sequence check (6.7.2): a packet is taken when (new - last) as a signed 8-bit number is
 *     > 0 or <= -20 (a source restarted); others are late or duplicate and are dropped;
 *   - a source that sent nothing for timeout_ns (E1.31 6.7.1: 2.5 s) is lost and leaves the
 *     merge; a packet with Stream_Terminated removes its source at once (6.2.6);
 *   - at most max_sources sources: a further one is refused (counted) until one leaves.
 * Art-Net 4: at most two sources per port-address, HTP or LTP (the latest packet wins every
 * slot), a source leaving the merge after 10 s without packets; no priority, no sequence.
 *
 * Loss: when the last source leaves, lr_dmx_merge_get returns 0 slots; what the lamp does then
 * (hold the look, or fade to the scene's values) is the receiver's setting (hal/sacn.h). OLA
 * sends only when a value changes (gaps of many seconds on a static look; OLA issue #1288: no
 * keep-alives by design), so a lone OLA source is "lost" on every pause: harmless under hold,
 * the default. */
#ifndef LR_HAL_DMX_MERGE_H
#define LR_HAL_DMX_MERGE_H

#include <stdbool.h>
#include <stdint.h>

#define LR_DMX_SLOTS 512
#define LR_DMX_MAX_SOURCES 16
#define LR_DMX_KEY_LEN 16 /* an sACN CID, or an Art-Net sender's IPv4 address and port */

typedef enum lr_dmx_merge_mode {
    LR_DMX_HTP = 0, /* highest takes precedence, slot by slot */
    LR_DMX_LTP,     /* latest takes precedence: the newest packet's slots */
} lr_dmx_merge_mode;

typedef struct lr_dmx_merge_cfg {
    int max_sources;      /* 1..LR_DMX_MAX_SOURCES */
    int64_t timeout_ns;   /* a source quiet this long leaves the merge */
    lr_dmx_merge_mode mode;
    bool check_sequence;  /* sACN */
} lr_dmx_merge_cfg;

typedef enum lr_dmx_take {
    LR_DMX_TAKEN = 0,     /* the source's slots were updated */
    LR_DMX_SEQUENCE,      /* out of order or duplicate: dropped */
    LR_DMX_FULL,          /* a new source while max_sources are in the merge: dropped */
} lr_dmx_take;

typedef struct lr_dmx_source {
    uint8_t key[LR_DMX_KEY_LEN];
    int priority;
    int last_seq;
    int64_t last_ns;
    uint64_t order;       /* LTP: arrival order of the last packet taken */
    int n_slots;
    uint8_t slots[LR_DMX_SLOTS];
} lr_dmx_source;

typedef struct lr_dmx_merge {
    lr_dmx_merge_cfg cfg;
    lr_dmx_source src[LR_DMX_MAX_SOURCES];
    int n;
    uint64_t order;
    uint8_t out[LR_DMX_SLOTS];
    int n_out;
    int priority;         /* of the winning sources; -1 when none */
} lr_dmx_merge;

/* cfg is copied; max_sources is clamped to 1..LR_DMX_MAX_SOURCES. */
void lr_dmx_merge_init(lr_dmx_merge *m, const lr_dmx_merge_cfg *cfg);
/* One packet's slots from source key. seq < 0: no sequence number. n 0..512. */
lr_dmx_take lr_dmx_merge_put(lr_dmx_merge *m, const uint8_t key[LR_DMX_KEY_LEN], int priority,
                             int seq, const uint8_t *slots, int n, int64_t now_ns);
/* Stream_Terminated: removes the source now. true when it was in the merge. */
bool lr_dmx_merge_terminate(lr_dmx_merge *m, const uint8_t key[LR_DMX_KEY_LEN]);
/* Removes the sources quiet for timeout_ns or longer at now_ns; returns how many. */
int lr_dmx_merge_expire(lr_dmx_merge *m, int64_t now_ns);
/* When the next source will time out, INT64_MAX when there is none. */
int64_t lr_dmx_merge_next_expiry(const lr_dmx_merge *m);
int lr_dmx_merge_count(const lr_dmx_merge *m);
/* The merged universe: *slots (LR_DMX_SLOTS bytes, valid until the next call that changes m)
 * and the number of slots some winning source sent; 0 when no source is in the merge. */
int lr_dmx_merge_get(const lr_dmx_merge *m, const uint8_t **slots);
/* Priority of the winning sources, -1 when none. */
int lr_dmx_merge_priority(const lr_dmx_merge *m);

#endif
