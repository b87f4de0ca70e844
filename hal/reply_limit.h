/* lamprig — how often a node answers discovery: one reply per poller per interval, and a
 * bucket over all pollers, so that a flood of ArtPolls (or of spoofed sources) costs bounded
 * work and bounded outgoing traffic per second. Art-Net 4 asks a node to answer a poll
 * within 3 s and controllers poll every 2.5-3 s, so one reply per poller per second loses
 * nothing a controller needs. Pure: times are the caller's (ns, monotonic). */
#ifndef LR_REPLY_LIMIT_H
#define LR_REPLY_LIMIT_H

#include <stdbool.h>
#include <stdint.h>

#define LR_REPLY_LIMIT_POLLERS 16 /* pollers remembered (least recently answered replaced) */
#define LR_REPLY_LIMIT_KEY 6      /* IPv4 address and port */

typedef struct lr_reply_limit {
    int64_t interval_ns; /* one reply per poller per interval */
    double rate, burst;  /* replies per second over all pollers, and the bucket's size */
    double tokens;
    int64_t filled_ns;   /* when tokens was last topped up; 0: never */
    struct {
        uint8_t key[LR_REPLY_LIMIT_KEY];
        int64_t last_ns;
        bool used;
    } seen[LR_REPLY_LIMIT_POLLERS];
} lr_reply_limit;

/* interval_ms >= 0, rate > 0, burst >= 1. */
void lr_reply_limit_init(lr_reply_limit *l, int interval_ms, double rate, double burst);
/* Whether to answer the poller `key` at now_ns; records the answer when true. */
bool lr_reply_limit_take(lr_reply_limit *l, const uint8_t key[LR_REPLY_LIMIT_KEY], int64_t now_ns);

#endif
