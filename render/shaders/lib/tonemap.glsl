// Exposure, tone curve and sRGB encoding (the GPU twin of lr_tonemap_apply + lr_srgb_encode,
// render/image/image.c). Shared by tonemap.frag and blend.frag.
uniform float u_exposure;
uniform int u_op; // 0 clamp, 1 Reinhard, 2 ACES (lr_tonemap_op)

float lr_tone(float v)
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

float lr_srgb(float l)
{
    if (!(l > 0.0))
        return 0.0;
    if (l >= 1.0)
        return 1.0;
    return l <= 0.0031308 ? 12.92 * l : 1.055 * pow(l, 1.0 / 2.4) - 0.055;
}

vec4 lr_tonemap_srgb(vec3 c)
{
    return vec4(lr_srgb(lr_tone(c.r)), lr_srgb(lr_tone(c.g)), lr_srgb(lr_tone(c.b)), 1.0);
}
