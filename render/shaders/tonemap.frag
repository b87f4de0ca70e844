// Exposure, tone curve and sRGB encoding of the HDR target (the GPU twin of
// lr_tonemap_apply + lr_srgb_encode, render/image/image.c).
in vec2 v_uv;
uniform highp sampler2D u_hdr;
uniform float u_exposure;
uniform int u_op; // 0 clamp, 1 Reinhard, 2 ACES (lr_tonemap_op)
layout(location = 0) out vec4 o_color;

float tone(float v)
{
    v *= u_exposure;
    if (!(v > 0.0))
        return 0.0;
    if (u_op == 1)
        v = v / (1.0 + v);
    else if (u_op == 2)
        v = (v * (2.51 * v + 0.03)) / (v * (2.43 * v + 0.59) + 0.14);
    return min(v, 1.0);
}

float srgb(float l)
{
    if (!(l > 0.0))
        return 0.0;
    if (l >= 1.0)
        return 1.0;
    return l <= 0.0031308 ? 12.92 * l : 1.055 * pow(l, 1.0 / 2.4) - 0.055;
}

void main()
{
    vec3 c = texelFetch(u_hdr, ivec2(gl_FragCoord.xy), 0).rgb;
    o_color = vec4(srgb(tone(c.r)), srgb(tone(c.g)), srgb(tone(c.b)), 1.0);
}
