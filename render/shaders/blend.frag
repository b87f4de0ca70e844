// The blend pass (render/passes/blend.h): sum_k w[k] image_{layer[k]} over the per-light
// unit-intensity linear images whose weight is not zero (LR_BLEND_N of them, a compile-time
// count: no loop, no branch per pixel), then the tone curve (LR_BLEND_OP, an lr_tonemap_op,
// compile-time) and the sRGB encode, or, with LR_BLEND_LINEAR, the linear sum for readback (a
// define, not a uniform: llvmpipe runs both sides of a uniform branch under a mask, and the
// other side's fetch would cost as much as the image's). The exposure is in the weights
// (blend.c). This pass is the whole of a dimmer or flicker frame, so it does no more per pixel
// than the tone curve needs:
// * LR_BLEND_SRGB_STORE 1: the target is SRGB8_ALPHA8, whose store clamps to [0, 1] and
//   encodes (IEC 61966-2-1 in the driver), so the shader writes the tone-mapped linear value;
// * LR_BLEND_SRGB_STORE 0 (no EXT_texture_sRGB_decode): an RGBA8 target, clipped and encoded
//   here with lr_srgb_encode_fast (render/image/image.h: three square roots instead of pow,
//   within a quarter of an 8-bit step of the exact curve).
#if !defined(LR_BLEND_OP) || !defined(LR_BLEND_N) || !defined(LR_BLEND_LINEAR) || \
    !defined(LR_BLEND_SRGB_STORE)
#error blend.frag needs the renderer defines (render/passes/defines.h) and LR_BLEND_OP, LR_BLEND_N, LR_BLEND_SRGB_STORE
#endif
uniform highp sampler2DArray u_images;
flat in vec3 v_w[4];    // u_w, u_layer through blend.vert: see there why
flat in ivec4 v_layer;
layout(location = 0) out vec4 o_color;

void main()
{
    ivec2 p = ivec2(gl_FragCoord.xy);
    // The sum starts from its first term, not from 0 + term (x + 0.0 is not x in IEEE: -0.0,
    // so a compiler keeps that add). N = 0: every light is off.
#if LR_BLEND_N == 0
    vec3 c = vec3(0.0);
#else
    vec3 c = v_w[0] * texelFetch(u_images, ivec3(p, v_layer[0]), 0).rgb;
#endif
#if LR_BLEND_N >= 2
    c += v_w[1] * texelFetch(u_images, ivec3(p, v_layer[1]), 0).rgb;
#endif
#if LR_BLEND_N >= 3
    c += v_w[2] * texelFetch(u_images, ivec3(p, v_layer[2]), 0).rgb;
#endif
#if LR_BLEND_N >= 4
    c += v_w[3] * texelFetch(u_images, ivec3(p, v_layer[3]), 0).rgb;
#endif
#if LR_BLEND_OP == LR_BLEND_LINEAR
    // Alpha of layer 0: coverage (compose_object.frag), whichever lights are lit.
    o_color = vec4(c, texelFetch(u_images, ivec3(p, 0), 0).a);
#else
    // lr_tonemap_apply (render/image/image.c): curve of the exposed value, clip to [0, 1]. The
    // max stays: ACES of a value below -0.012 is positive. The clip to 1 is the store's with
    // LR_BLEND_SRGB_STORE (the curves end at or above 1 only where the clip makes them 1).
#if LR_BLEND_OP == LR_TONEMAP_CLAMP && LR_BLEND_SRGB_STORE
    // The clip is the SRGB8_ALPHA8 store's (a unorm conversion clamps to [0, 1]).
    vec3 v = c;
#else
    vec3 v = max(c, vec3(0.0));
#endif
#if LR_BLEND_OP == LR_TONEMAP_REINHARD
    v = v / (1.0 + v);
#elif LR_BLEND_OP == LR_TONEMAP_ACES
    v = (v * (2.51 * v + 0.03)) / (v * (2.43 * v + 0.59) + 0.14); // Narkowicz 2015
#endif
#if LR_BLEND_SRGB_STORE
    o_color = vec4(v, 1.0);
#else
    v = min(v, vec3(1.0));
    // lr_srgb_encode_fast: the linear segment below 0.0031308, else Taylor's fit in
    // l^(1/2), l^(1/4), l^(1/8).
    vec3 s1 = sqrt(v), s2 = sqrt(s1), s3 = sqrt(s2);
    vec3 fit = 0.662002687 * s1 + 0.684122060 * s2 - 0.323583601 * s3 - 0.0225411470 * v;
    o_color = vec4(mix(fit, 12.92 * v, lessThanEqual(v, vec3(0.0031308))), 1.0);
#endif
#endif
}
