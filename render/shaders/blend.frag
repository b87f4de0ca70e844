// The blend pass (render/passes/blend.h): sum_l u_w[l] image_l over the per-light
// unit-intensity linear images, then tone mapping (or, with u_linear, the linear sum for
// readback). One fetch per light and pixel; the images are in the same pixel grid.
#include "lib/tonemap.glsl"

uniform highp sampler2DArray u_images;
uniform vec3 u_w[LR_MAX_LIGHTS];
uniform int u_n;
uniform bool u_linear;
layout(location = 0) out vec4 o_color;

void main()
{
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 c0 = texelFetch(u_images, ivec3(p, 0), 0);
    vec3 c = u_w[0] * c0.rgb;
    for (int l = 1; l < LR_MAX_LIGHTS; l++) {
        if (l >= u_n)
            break;
        c += u_w[l] * texelFetch(u_images, ivec3(p, l), 0).rgb;
    }
    o_color = u_linear ? vec4(c, c0.a) : lr_tonemap_srgb(c);
}
