/* lamprig — rotary-encoder acceleration: a fast spin covers the range in one turn, a slow
 * one moves a single step per detent.
 *
 * The turning rate is estimated from the time between delta events (detents per second,
 * smoothed over a few events); below `rate0` the factor is 1, above it grows linearly with
 * `gain` and is capped at `max_factor`. A pause longer than 250 ms resets the estimate, so
 * the first detent after a pause is never accelerated.
 */
#ifndef LR_ACCEL_H
#define LR_ACCEL_H

#include <stdint.h>

typedef struct lr_accel {
    double gain;       /* extra factor per rate0 of speed above rate0; 0 = no acceleration */
    double rate0;      /* detents/s under which nothing is accelerated (default 5) */
    double max_factor; /* cap (default 10) */
    int64_t last_ns;
    double rate;       /* smoothed detents/s */
} lr_accel;

void lr_accel_init(lr_accel *a, double gain, double rate0, double max_factor);
/* Returns delta times the current factor; the sign is kept. */
double lr_accel_apply(lr_accel *a, double delta, int64_t now_ns);

#endif
