// Pass 4: the virtual point lights, one per texel of an N_vpl x 1 target. VPL v sits where the
// fixed Halton direction u_v (from the bounding-box centre c) meets the outermost surface
// (a cube map rendered with the farthest depth kept), so positions move only with the
// geometry; it stands for the area A_v = |x_v - c|^2 (4 pi / N_vpl) / max(|n_v . u_v|, 0.05)
// and carries B(x_v) from Algorithm 1 (render/passes/PIPELINE.md, pass 4).
#include "lib/material.glsl"
#include "lib/gather.glsl"

uniform highp samplerCube u_outer_pos;
uniform highp samplerCube u_outer_nrm;
uniform highp sampler2D u_vpl_dirs; // N_vpl x 1: u_v
uniform vec3 u_center;
uniform int u_n_vpl;
layout(location = 0) out vec4 o_pos; // x_v, A_v (0: no surface in that direction)
layout(location = 1) out vec4 o_nrm; // n_v, object id (-1: none)
layout(location = 2) out vec4 o_B;   // B(x_v) for unit intensity of this row's light, weight

void main()
{
    int v = int(gl_FragCoord.x); // row gl_FragCoord.y: the light whose maps the gather weighs
    vec3 u = texelFetch(u_vpl_dirs, ivec2(v, 0), 0).xyz;
    vec4 p = texture(u_outer_pos, u);
    if (!(p.w > 0.5)) {
        o_pos = vec4(0.0);
        o_nrm = vec4(0.0, 0.0, 0.0, -1.0);
        o_B = vec4(0.0);
        return;
    }
    vec3 x = p.xyz;
    vec3 n = normalize(texture(u_outer_nrm, u).xyz);
    vec3 rc = x - u_center;
    float area = dot(rc, rc) * (4.0 * LR_PI / float(u_n_vpl)) / max(abs(dot(n, u)), 0.05);
    float w;
    vec3 B = lr_gather(x, n, w);
    o_pos = vec4(x, area);
    o_nrm = vec4(n, p.w - 1.0);
    o_B = vec4(B, w);
}
