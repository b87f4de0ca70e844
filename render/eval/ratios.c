/* Power ratios with the reference's standard error, and the median log ratio (eval.h). Sums in
 * double, in pixel order. */
#include "render/eval/eval.h"

#include <math.h>
#include <stdlib.h>

lr_eval_ratio lr_eval_power_ratio(const float *img, const float *ref, const float *var,
                                  const unsigned char *mask, size_t n, int band)
{
    int b0 = band < 0 ? 0 : band, b1 = band < 0 ? 3 : band + 1;
    double g = 0.0, r = 0.0, v = 0.0;
    for (size_t i = 0; i < n; i++)
        if (!mask || mask[i])
            for (int b = b0; b < b1; b++) {
                g += img[3 * i + b];
                r += ref[3 * i + b];
                v += var ? var[3 * i + b] : 0.0;
            }
    if (!(r > 0.0))
        return (lr_eval_ratio){NAN, NAN};
    double R = g / r;
    return (lr_eval_ratio){R, R * sqrt(v) / r};
}

bool lr_eval_ratio_differs(lr_eval_ratio r)
{
    return isfinite(r.ratio) && isfinite(r.se) && fabs(r.ratio - 1.0) > 2.0 * r.se;
}

double lr_eval_ratio_excess(lr_eval_ratio r)
{
    if (!isfinite(r.ratio) || !isfinite(r.se) || r.ratio < 0.0)
        return NAN;
    if (r.ratio == 0.0)
        return INFINITY;
    return fmax(fabs(log(r.ratio)) - 2.0 * r.se / r.ratio, 0.0);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double lr_eval_median_abs_log(const float *a, const float *b, const unsigned char *mask,
                              size_t n)
{
    double *v = malloc((n ? n : 1) * sizeof *v);
    if (!v)
        return NAN;
    size_t m = 0;
    for (size_t i = 0; i < n; i++) {
        if (mask && !mask[i])
            continue;
        double sa = (double)a[3 * i] + a[3 * i + 1] + a[3 * i + 2];
        double sb = (double)b[3 * i] + b[3 * i + 1] + b[3 * i + 2];
        if (!(sa > 0.0) && !(sb > 0.0))
            continue; /* both dark (or not finite): no ratio */
        v[m++] = sa > 0.0 && sb > 0.0 ? fabs(log(sa / sb)) : INFINITY;
    }
    double med = NAN;
    if (m) {
        qsort(v, m, sizeof *v, cmp_double);
        med = m % 2 ? v[m / 2] : 0.5 * (v[m / 2 - 1] + v[m / 2]);
    }
    free(v);
    return med;
}

void lr_eval_mean_references(float *mean, float *var, const float *mean2, const float *var2,
                             size_t n)
{
    for (size_t i = 0; i < 3 * n; i++) {
        mean[i] = 0.5f * (mean[i] + mean2[i]);
        if (var && var2)
            var[i] = 0.25f * (var[i] + var2[i]);
    }
}
