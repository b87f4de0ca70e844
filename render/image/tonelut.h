/* lamprig — the output curve as a lookup table: exposure, tone curve and sRGB encoding
 * (lr_tonemap_apply then lr_srgb_encode, render/image/image.h) sampled on a grid in log2 of
 * the exposed value, for the blend pass (render/passes/blend.h, issue 11).
 *
 * Why: the blend pass is the whole of a dimmer or flicker frame, and on llvmpipe its per-pixel
 * cost was dominated by the analytic curve (a division, pow = log2 + exp2, branches, per
 * channel). The table costs one log2 and one texel fetch per channel. Indexing by log2 makes
 * exposure an offset (log2(e v) = log2 e + log2 v), so the table depends on the tone curve
 * alone and is built once per renderer.
 *
 * Grid: texel i holds x_i = LR_TONELUT_LO + i / LR_TONELUT_STEPS (stops), f_i = curve(2^x_i)
 * and the step d_i = f_{i+1} - f_i (0 for the last texel), so one fetch gives the linear
 * interpolation f_i + d_i t. 64 steps per stop puts x = 0 (the clamp curve's knee at 1) on a
 * grid point; the range [-16, 16) stops covers every value that is not 0 or 1 in 8 bits (at
 * 2^-16 the steepest curve, clamp, gives 2.0e-4 of full scale = 0.05 of a step; above 2^8
 * every curve gives 255). Texel 0 holds 0 rather than the curve (black stays black); outside
 * the range the end texels hold: 0, negatives and NaN give 0. The
 * interpolation error of this grid is bounded in tests/test_image.c (< 0.5 / 255: the 8-bit
 * code is the analytic curve's or one step from it).
 */
#ifndef LR_TONELUT_H
#define LR_TONELUT_H

#include "render/image/image.h"

#define LR_TONELUT_N 2048     /* texels: the minimum GL_MAX_TEXTURE_SIZE of GLES 3.1 */
#define LR_TONELUT_STEPS 64   /* texels per stop */
#define LR_TONELUT_LO (-16.0f) /* log2 of the first texel's exposed value */

/* Fills lut[4 * LR_TONELUT_N] (RGBA per texel: f_i, d_i, 0, 0) for tone curve op at exposure
 * 1; the layout of the GPU texture. */
void lr_tonelut_build(lr_tonemap_op op, float *lut);

/* Texel coordinate offset for an exposure (<= 0 means 1): u = log2(v) * LR_TONELUT_STEPS +
 * offset. The blend pass's uniform. */
float lr_tonelut_offset(float exposure);

/* The CPU twin of the blend pass's lookup: the sRGB-encoded display value in [0, 1] of linear
 * value v at the offset from lr_tonelut_offset. */
float lr_tonelut_apply(const float *lut, float offset, float v);

#endif
