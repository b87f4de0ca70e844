// The surface cache pass (render/passes/surface.c): seed 003 Algorithm 1 (lib/gather.glsl,
// lr_gather_each) at one cache entry per texel, a refined object vertex x with its normal n
// (reversed for the back side of an open object), one layer per light at unit intensity.
// B does not depend on the view, so composition reads this instead of gathering per pixel.
#include "lib/gather.glsl"

uniform highp sampler2D u_entry_pos; // x, w 1 for an entry (0: padding)
uniform highp sampler2D u_entry_nrm; // n (the parent's interpolated normal, not unit)
layout(location = 0) out vec4 o_light[LR_MAX_LIGHTS];

void main()
{
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 x = texelFetch(u_entry_pos, p, 0);
    vec3 n = texelFetch(u_entry_nrm, p, 0).xyz;
    float len = length(n);
    vec3 Bl[LR_MAX_LIGHTS];
    float w = 0.0;
    if (x.w > 0.5 && len > 1e-12) {
        lr_gather_each(x.xyz, n / len, w, Bl);
    } else {
        for (int l = 0; l < LR_MAX_LIGHTS; l++)
            Bl[l] = vec3(0.0);
    }
    // a: a map saw the point (compose_object.frag's coverage), interpolated by composition.
    float a = w > 0.0 ? 1.0 : 0.0;
    o_light[0] = vec4(Bl[0], a);
    o_light[1] = vec4(Bl[1], a);
    o_light[2] = vec4(Bl[2], a);
    o_light[3] = vec4(Bl[3], a);
}
