#include "render/base/median.h"

#include <math.h>
#include <stdlib.h>

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double lr_median_finite(const double *v, int n)
{
    if (n <= 0)
        return NAN;
    double *s = malloc((size_t)n * sizeof *s);
    if (!s)
        return NAN;
    int m = 0;
    for (int i = 0; i < n; i++)
        if (isfinite(v[i]))
            s[m++] = v[i];
    double med = NAN;
    if (m) {
        qsort(s, (size_t)m, sizeof s[0], cmp_double);
        med = m % 2 ? s[m / 2] : 0.5 * (s[m / 2 - 1] + s[m / 2]);
    }
    free(s);
    return med;
}
