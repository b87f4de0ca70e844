// The blend pass (render/passes/blend.h): sum_k u_w[k] image_{u_layer[k]} over the per-light
// unit-intensity linear images whose weight is not zero (LR_BLEND_N of them, a compile-time
// count: no loop, no branch per pixel), then the output curve (exposure, tone curve, sRGB)
// through the lookup table of render/image/tonelut.h, or, with u_linear, the linear sum for
// readback. One fetch per active light and pixel and one per channel into the table.
uniform highp sampler2DArray u_images;
uniform highp sampler2D u_lut;   // LR_TONELUT_N x 1 RGBA32F: (f_i, f_{i+1} - f_i, 0, 0)
uniform vec3 u_w[4];
uniform int u_layer[4];
uniform int u_alpha_layer;       // layer 0 (its alpha: coverage, copied to the HDR sum)
uniform float u_lut_scale;       // LR_TONELUT_STEPS
uniform float u_lut_offset;      // lr_tonelut_offset(exposure)
uniform float u_lut_max;         // LR_TONELUT_N - 1
uniform bool u_linear;
layout(location = 0) out vec4 o_color;

float lr_lut(float u)
{
    // -inf (a zero value) clamps to texel 0 (tonelut.c lr_tonelut_apply is the CPU twin).
    u = clamp(u, 0.0, u_lut_max);
    int i = int(u);
    vec2 fd = texelFetch(u_lut, ivec2(i, 0), 0).xy;
    return fd.x + fd.y * (u - float(i));
}

void main()
{
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec3 c = vec3(0.0);
#if LR_BLEND_N >= 1
    c += u_w[0] * texelFetch(u_images, ivec3(p, u_layer[0]), 0).rgb;
#endif
#if LR_BLEND_N >= 2
    c += u_w[1] * texelFetch(u_images, ivec3(p, u_layer[1]), 0).rgb;
#endif
#if LR_BLEND_N >= 3
    c += u_w[2] * texelFetch(u_images, ivec3(p, u_layer[2]), 0).rgb;
#endif
#if LR_BLEND_N >= 4
    c += u_w[3] * texelFetch(u_images, ivec3(p, u_layer[3]), 0).rgb;
#endif
    if (u_linear) {
        o_color = vec4(c, texelFetch(u_images, ivec3(p, u_alpha_layer), 0).a);
        return;
    }
    // log2 of 0 or less is undefined in GLSL ES: 1e-30 is far below the table (texel 0: 0).
    vec3 u = log2(max(c, vec3(1e-30))) * u_lut_scale + u_lut_offset;
    o_color = vec4(lr_lut(u.r), lr_lut(u.g), lr_lut(u.b), 1.0);
}
