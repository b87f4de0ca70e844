/* The output curve as a lookup table (render/image/tonelut.h). */
#include "render/image/tonelut.h"

#include <math.h>

void lr_tonelut_build(lr_tonemap_op op, float *lut)
{
    lr_tonemap tm = {op, 1.0f};
    float f[LR_TONELUT_N];
    /* Texel 0 is 0, not curve(2^-16): black stays exactly black, and below the range the
     * table gives 0 (the curve there is < 2.1e-4, under half an 8-bit step). */
    f[0] = 0.0f;
    for (int i = 1; i < LR_TONELUT_N; i++)
        f[i] = lr_srgb_encode(lr_tonemap_apply(
            &tm, exp2f(LR_TONELUT_LO + (float)i / (float)LR_TONELUT_STEPS)));
    for (int i = 0; i < LR_TONELUT_N; i++) {
        lut[4 * i + 0] = f[i];
        lut[4 * i + 1] = i + 1 < LR_TONELUT_N ? f[i + 1] - f[i] : 0.0f;
        lut[4 * i + 2] = 0.0f;
        lut[4 * i + 3] = 0.0f;
    }
}

float lr_tonelut_offset(float exposure)
{
    float ex = exposure > 0.0f ? exposure : 1.0f;
    return (log2f(ex) - LR_TONELUT_LO) * (float)LR_TONELUT_STEPS;
}

float lr_tonelut_apply(const float *lut, float offset, float v)
{
    /* The shader's arithmetic: u clamped to the grid, i = floor(u), t = u - i. log2(0) = -inf
     * clamps to texel 0; NaN too (fmaxf/fminf return the number). */
    float u = v > 0.0f ? log2f(v) * (float)LR_TONELUT_STEPS + offset : -INFINITY;
    u = fminf(fmaxf(u, 0.0f), (float)(LR_TONELUT_N - 1));
    int i = (int)u;
    float t = u - (float)i;
    return lut[4 * i] + lut[4 * i + 1] * t;
}
