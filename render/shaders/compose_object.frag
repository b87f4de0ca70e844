// Pass 3 for the translucent objects: B from the K maps (Algorithm 1), then
// L_o = I F_t(w_o) B / pi (seed 003 Eq. 5); I = intensity * colour of the light.
#include "lib/material.glsl"
#include "lib/gather.glsl"

in vec3 v_pos;
in vec3 v_nrm;
uniform int u_object;
uniform bool u_two_sided;
uniform vec3 u_eye;          // camera position (perspective)
uniform vec3 u_view_dir;     // camera forward (orthographic)
uniform bool u_ortho;
uniform vec3 u_intensity;    // I per band
// Per object: light sent back into a cavity around the light (PIPELINE.md "Energy").
uniform vec3 u_cavity_gain[LR_MAX_OBJECTS];
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
    vec3 g = u_cavity_gain[clamp(u_object, 0, LR_MAX_OBJECTS - 1)];
    o_color = vec4(u_intensity * g * Ft * B / LR_PI, n > 0.0 ? 1.0 : 0.0);
}
