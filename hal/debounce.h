/* lamprig hal — push-button debouncing by event timestamps (pure: no I/O, no clock).
 *
 * Leading-edge debounce: the first edge that changes the debounced state is reported at once
 * (no added latency), then edges are ignored as bounce for `window`. If the contact has settled
 * in the other state by the end of the window (a tap shorter than the window, or bounce that
 * ended elsewhere), the change is reported when the caller ticks at lr_debounce_deadline() —
 * the timer a GPIO back end hands to the main loop as its next_deadline. So a press is never
 * reported twice and the final state always matches the contact.
 *
 * Levels are logical: 1 = pressed. (The gpio back end maps active-low wiring before.)
 */
#ifndef LR_HAL_DEBOUNCE_H
#define LR_HAL_DEBOUNCE_H

#include <stdbool.h>
#include <stdint.h>

typedef struct lr_debounce {
    int64_t window_ns;
    int64_t locked_until; /* edges before this time are bounce */
    int64_t raw_t;        /* time of the last raw edge */
    uint8_t stable;       /* debounced level */
    uint8_t raw;          /* last raw level */
    bool pending;         /* edges were ignored in the window: check the level at its end */
    uint32_t ignored;     /* edges ignored as bounce */
} lr_debounce;

/* window_ns 0 means 5 ms. level: the logical level at start. */
void lr_debounce_init(lr_debounce *d, int64_t window_ns, int level);

/* Feeds one edge: the logical level after it and its timestamp (non-decreasing).
 * Returns +1 for a press, -1 for a release, 0 when nothing changes; *t_out (may be NULL)
 * receives the change's time. */
int lr_debounce_edge(lr_debounce *d, int level, int64_t t_ns, int64_t *t_out);

/* When lr_debounce_tick must be called, or INT64_MAX when nothing is pending. */
int64_t lr_debounce_deadline(const lr_debounce *d);

/* Settles a pending window at now_ns (>= the deadline). Returns +1/-1/0 like lr_debounce_edge;
 * *t_out receives the time of the raw edge that ended in the settled level. */
int lr_debounce_tick(lr_debounce *d, int64_t now_ns, int64_t *t_out);

#endif
