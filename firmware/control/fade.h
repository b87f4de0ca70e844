/* lamprig — timed fades of a control value, so that a dimmer change never jumps.
 *
 * A plain value type (no allocation): the control map keeps one per faded parameter. Times are
 * CLOCK_MONOTONIC nanoseconds. A new target during a fade starts from the value shown at that
 * instant, so the output stays continuous however often the knob moves.
 */
#ifndef LR_FADE_H
#define LR_FADE_H

#include <stdbool.h>
#include <stdint.h>

typedef struct lr_fade {
    double from, to;
    int64_t t0_ns;
    int64_t duration_ns;
} lr_fade;

/* A fade already at `value` (nothing running). */
void lr_fade_init(lr_fade *f, double value);
/* Fade from the current value (at now_ns) to target over `seconds` (<= 0: jump). */
void lr_fade_to(lr_fade *f, double target, int64_t now_ns, double seconds);
/* Value at now_ns: linear in time, clamped to the end points; a clock earlier than the
 * start (should never happen with CLOCK_MONOTONIC) gives the start value. */
double lr_fade_value(const lr_fade *f, int64_t now_ns);
bool lr_fade_active(const lr_fade *f, int64_t now_ns);
/* When the fade ends (for the main loop's next wake-up). */
int64_t lr_fade_end_ns(const lr_fade *f);

#endif
