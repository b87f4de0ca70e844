/* Discovery replies, limited per poller and overall (reply_limit.h). */
#include <string.h>

#include "hal/reply_limit.h"

void lr_reply_limit_init(lr_reply_limit *l, int interval_ms, double rate, double burst)
{
    memset(l, 0, sizeof *l);
    l->interval_ns = (int64_t)interval_ms * 1000000;
    l->rate = rate;
    l->burst = burst;
    l->tokens = burst;
}

bool lr_reply_limit_take(lr_reply_limit *l, const uint8_t key[LR_REPLY_LIMIT_KEY], int64_t now_ns)
{
    if (l->filled_ns && now_ns > l->filled_ns) {
        l->tokens += (double)(now_ns - l->filled_ns) * 1e-9 * l->rate;
        if (l->tokens > l->burst)
            l->tokens = l->burst;
    }
    l->filled_ns = now_ns;
    int slot = -1, oldest = 0;
    for (int i = 0; i < LR_REPLY_LIMIT_POLLERS; i++) {
        if (l->seen[i].used && !memcmp(l->seen[i].key, key, LR_REPLY_LIMIT_KEY))
            slot = i;
        bool older = l->seen[oldest].used && l->seen[i].last_ns < l->seen[oldest].last_ns;
        if (!l->seen[i].used || older)
            oldest = i;
    }
    if (slot >= 0 && now_ns - l->seen[slot].last_ns < l->interval_ns)
        return false;
    if (l->tokens < 1.0)
        return false;
    l->tokens -= 1.0;
    if (slot < 0) {
        slot = oldest;
        memcpy(l->seen[slot].key, key, LR_REPLY_LIMIT_KEY);
        l->seen[slot].used = true;
    }
    l->seen[slot].last_ns = now_ns;
    return true;
}
