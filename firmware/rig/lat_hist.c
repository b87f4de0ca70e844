/* lamprig firmware — fixed-size latency histogram (see lat_hist.h). */
#include "firmware/rig/lat_hist.h"

#include <math.h>
#include <stdlib.h>

/* ln(1e5 / 0.01) / ln(1.01) = 1619.9: 1620 log buckets, then one below and one above. */
#define N_LOG 1620
#define UNDER 0
#define OVER (N_LOG + 1)
#define N_BUCKETS (N_LOG + 2)

struct lr_lat_hist {
    uint64_t count[N_BUCKETS];
    uint64_t n;
    double min, max, sum;
};

lr_lat_hist *lr_lat_hist_create(void)
{
    lr_lat_hist *h = calloc(1, sizeof *h);
    if (h) {
        h->min = INFINITY;
        h->max = -INFINITY;
    }
    return h;
}

void lr_lat_hist_destroy(lr_lat_hist *h) { free(h); }

static int bucket_of(double ms)
{
    if (ms < LR_LAT_HIST_LO_MS)
        return UNDER;
    double k = floor(log(ms / LR_LAT_HIST_LO_MS) / log(LR_LAT_HIST_RATIO));
    if (k >= N_LOG || ms >= LR_LAT_HIST_HI_MS)
        return OVER;
    return 1 + (int)k;
}

void lr_lat_hist_add(lr_lat_hist *h, double ms)
{
    if (!(ms >= 0))
        return;
    h->count[bucket_of(ms)]++;
    h->n++;
    h->sum += ms;
    h->min = fmin(h->min, ms);
    h->max = fmax(h->max, ms);
}

uint64_t lr_lat_hist_n(const lr_lat_hist *h) { return h->n; }
double lr_lat_hist_min(const lr_lat_hist *h) { return h->n ? h->min : NAN; }
double lr_lat_hist_max(const lr_lat_hist *h) { return h->n ? h->max : NAN; }
double lr_lat_hist_mean(const lr_lat_hist *h) { return h->n ? h->sum / (double)h->n : NAN; }

/* The representative of bucket b: its geometric middle; the range's middle below it, the
 * maximum above it (the caller clamps to [min, max]). */
static double bucket_value(const lr_lat_hist *h, int b)
{
    if (b == UNDER)
        return 0.5 * LR_LAT_HIST_LO_MS;
    if (b == OVER)
        return h->max;
    return LR_LAT_HIST_LO_MS * pow(LR_LAT_HIST_RATIO, (double)(b - 1) + 0.5);
}

/* The order statistic of 0-based rank r (r < n), from its bucket. */
static double rank_value(const lr_lat_hist *h, uint64_t r)
{
    uint64_t seen = 0;
    for (int b = 0; b < N_BUCKETS; b++) {
        seen += h->count[b];
        if (seen > r)
            return bucket_value(h, b);
    }
    return h->max;
}

double lr_lat_hist_quantile(const lr_lat_hist *h, double q)
{
    if (!h->n)
        return NAN;
    q = q < 0 ? 0 : q > 1 ? 1 : q;
    double pos = q * (double)(h->n - 1);
    uint64_t i = (uint64_t)floor(pos);
    double v = rank_value(h, i);
    if (i + 1 < h->n) {
        double f = pos - (double)i;
        if (f > 0)
            v = v * (1 - f) + rank_value(h, i + 1) * f;
    }
    return fmin(fmax(v, h->min), h->max);
}
