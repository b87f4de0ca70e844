/* lamprig firmware — a latency histogram of fixed size: quantiles of any number of samples in
 * constant memory (the rig's stats see an event per knob detent, thousands a second).
 *
 * Buckets are LR_LAT_HIST_RATIO (1 %) wide on a log scale from LR_LAT_HIST_LO_MS (0.01 ms) to
 * LR_LAT_HIST_HI_MS (100 s), plus one bucket below and one above. A sample in a log bucket
 * [a, a·r) is represented by the bucket's geometric middle a·√r, within a relative
 * LR_LAT_HIST_REL_ERR = √r − 1 (0.499 %) of it. A quantile is the linear interpolation between
 * the order statistics at ranks ⌊q(n−1)⌋ and ⌊q(n−1)⌋+1 (the exact definition the stats had),
 * each read from its bucket, then clamped to the exact [min, max]. So it is within
 * LR_LAT_HIST_REL_ERR of the exact quantile x when both samples lie in [0.01 ms, 100 s]; a
 * sample below 0.01 ms is read as 0.005 ms, which adds up to 0.005 ms absolute; above 100 s the
 * bucket is read as the maximum. n, min, max and mean are exact. 13 KB, whatever the count.
 */
#ifndef LR_LAT_HIST_H
#define LR_LAT_HIST_H

#include <stdint.h>

#define LR_LAT_HIST_LO_MS 0.01
#define LR_LAT_HIST_HI_MS 1e5
#define LR_LAT_HIST_RATIO 1.01
#define LR_LAT_HIST_REL_ERR 0.0049875621120889 /* sqrt(1.01) - 1 */

typedef struct lr_lat_hist lr_lat_hist;

lr_lat_hist *lr_lat_hist_create(void); /* NULL when out of memory */
void lr_lat_hist_destroy(lr_lat_hist *h);

/* A sample in ms; negative or NaN ones are not counted (latencies are >= 0 by construction). */
void lr_lat_hist_add(lr_lat_hist *h, double ms);

uint64_t lr_lat_hist_n(const lr_lat_hist *h);
/* q in [0, 1]; NaN when empty. */
double lr_lat_hist_quantile(const lr_lat_hist *h, double q);
double lr_lat_hist_min(const lr_lat_hist *h); /* NaN when empty */
double lr_lat_hist_max(const lr_lat_hist *h); /* NaN when empty */
double lr_lat_hist_mean(const lr_lat_hist *h); /* NaN when empty */

#endif
