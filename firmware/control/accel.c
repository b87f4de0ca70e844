#include "firmware/control/accel.h"

#include <math.h>

#define LR_ACCEL_RESET_NS 250000000LL

void lr_accel_init(lr_accel *a, double gain, double rate0, double max_factor)
{
    a->gain = gain > 0.0 ? gain : 0.0;
    a->rate0 = rate0 > 0.0 ? rate0 : 5.0;
    a->max_factor = max_factor >= 1.0 ? max_factor : 10.0;
    a->last_ns = -1;
    a->rate = 0.0;
}

double lr_accel_apply(lr_accel *a, double delta, int64_t now_ns)
{
    if (!isfinite(delta))
        return 0.0;
    int64_t dt = a->last_ns < 0 ? -1 : now_ns - a->last_ns;
    a->last_ns = now_ns;
    if (dt < 0 || dt > LR_ACCEL_RESET_NS) {
        a->rate = 0.0;
        return delta;
    }
    /* Events closer than 1 ms (several detents in one report) count as 1 ms apart. */
    double seconds = dt < 1000000 ? 1e-3 : (double)dt * 1e-9;
    double instant = fabs(delta) / seconds;
    /* Exponential smoothing over ~3 events keeps one jittery timestamp from spiking. */
    a->rate = a->rate > 0.0 ? 0.5 * a->rate + 0.5 * instant : instant;
    double factor = 1.0;
    if (a->rate > a->rate0)
        factor = 1.0 + a->gain * (a->rate - a->rate0) / a->rate0;
    if (factor > a->max_factor)
        factor = a->max_factor;
    return delta * factor;
}
