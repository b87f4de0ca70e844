// Pass 3 for the translucent objects: I B = sum_l I_l B_l from every light's K maps (Algorithm
// 1, the gather weighted by the intensities I_l = intensity * colour, each times this object's
// cavity gain for light l, PIPELINE.md "Energy": render/passes/compose.c sets u_light_w per
// object), then L_o = F_t(w_o) I B / pi (seed 003 Eq. 5).
#include "lib/material.glsl"
#include "lib/gather.glsl"

in vec3 v_pos;
in vec3 v_nrm;
uniform int u_object;
uniform bool u_two_sided;
uniform vec3 u_eye;          // camera position (perspective)
uniform vec3 u_view_dir;     // camera forward (orthographic)
uniform bool u_ortho;
layout(location = 0) out vec4 o_color;

void main()
{
    vec3 no = normalize(v_nrm);
    if (u_two_sided && !gl_FrontFacing)
        no = -no;
    vec3 wo = u_ortho ? -u_view_dir : normalize(u_eye - v_pos);
    float n;
    vec3 B = lr_gather(v_pos, no, n);
    float eta = lr_material(u_object).eta;
    float Ft = lr_fresnel_transmittance(abs(dot(no, wo)), eta);
    o_color = vec4(Ft * B / LR_PI, n > 0.0 ? 1.0 : 0.0);
}
