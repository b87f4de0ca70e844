#include "calib/isotonic.h"

#include <stdlib.h>

int lr_isotonic(double *y, const double *w, int n, lr_err *e)
{
    if (n <= 1)
        return LR_OK;
    if (n > 65536)
        return lr_err_set(e, LR_EINVAL, "isotonic fit: %d points (at most 65536)", n);
    /* Blocks: mean value, total weight, first index. */
    double *val = malloc(sizeof *val * (size_t)n), *wt = malloc(sizeof *wt * (size_t)n);
    int *start = malloc(sizeof *start * (size_t)n);
    if (!val || !wt || !start) {
        free(val);
        free(wt);
        free(start);
        return lr_err_set(e, LR_ENOMEM, "isotonic fit: out of memory");
    }
    int nb = 0;
    for (int i = 0; i < n; i++) {
        val[nb] = y[i];
        wt[nb] = w ? w[i] : 1.0;
        start[nb] = i;
        nb++;
        while (nb > 1 && val[nb - 2] > val[nb - 1]) {
            double tw = wt[nb - 2] + wt[nb - 1];
            val[nb - 2] = (val[nb - 2] * wt[nb - 2] + val[nb - 1] * wt[nb - 1]) / tw;
            wt[nb - 2] = tw;
            nb--;
        }
    }
    for (int b = 0; b < nb; b++) {
        int end = b + 1 < nb ? start[b + 1] : n;
        for (int i = start[b]; i < end; i++)
            y[i] = val[b];
    }
    free(val);
    free(wt);
    free(start);
    return LR_OK;
}
