/* Relative errors in linear light (eval.h). Sums in double, in pixel order. */
#include "render/eval/eval.h"

#include <math.h>

double lr_eval_rel_rmse(const float *img, const float *ref, const unsigned char *mask, size_t n)
{
    double num = 0.0, den = 0.0;
    for (size_t i = 0; i < n; i++)
        if (!mask || mask[i])
            for (int c = 0; c < 3; c++) {
                double d = (double)img[3 * i + c] - (double)ref[3 * i + c];
                num += d * d;
                den += (double)ref[3 * i + c] * ref[3 * i + c];
            }
    return den > 0.0 ? sqrt(num / den) : NAN;
}

double lr_eval_rel_stderr(const float *var, const float *ref, const unsigned char *mask,
                          size_t n)
{
    double num = 0.0, den = 0.0;
    for (size_t i = 0; i < n; i++)
        if (!mask || mask[i])
            for (int c = 0; c < 3; c++) {
                num += var[3 * i + c];
                den += (double)ref[3 * i + c] * ref[3 * i + c];
            }
    return den > 0.0 ? sqrt(num / den) : NAN;
}

double lr_eval_sum_ratio(const float *img, const float *ref, const unsigned char *mask,
                         size_t n)
{
    double a = 0.0, b = 0.0;
    for (size_t i = 0; i < n; i++)
        if (!mask || mask[i])
            for (int c = 0; c < 3; c++) {
                a += img[3 * i + c];
                b += ref[3 * i + c];
            }
    return b != 0.0 ? a / b : NAN;
}
