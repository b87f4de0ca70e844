// Pass 3 for the translucent objects, one image per light at unit intensity: B_l from light
// l's K maps (Algorithm 1 with the same taps for every light, lr_gather_each; each times this
// object's cavity gain for light l, PIPELINE.md "Energy": render/passes/compose.c sets
// u_light_w per object), then L_o,l = F_t(w_o) B_l / pi (seed 003 Eq. 5). The blend pass
// weights the images with the lights' intensities (render/passes/blend.h). render.lpv adds
// the volume's indirect light on the object to B_l (lib/lpv_object.glsl), and
// render.receiver_light_on_objects the receivers' light on it (lib/recv_light.glsl).
#include "lib/material.glsl"
#include "lib/gather.glsl"
#include "lib/lpv_object.glsl"
#include "lib/recv_light.glsl"

in vec3 v_pos;
in vec3 v_nrm;
uniform int u_object;
uniform bool u_two_sided;
uniform vec3 u_eye;          // camera position (perspective)
uniform vec3 u_view_dir;     // camera forward (orthographic)
uniform bool u_ortho;
// Output i is light i's image (colour attachment i; those beyond the scene's lights are not
// attached and their writes are dropped). GLSL ES indexes outputs by constants only, hence
// the unrolled writes for LR_MAX_LIGHTS = 4 (render/passes/passes.h).
layout(location = 0) out vec4 o_light[LR_MAX_LIGHTS];

void main()
{
    vec3 no = normalize(v_nrm);
    bool back = u_two_sided && !gl_FrontFacing;
    if (back)
        no = -no;
    vec3 wo = u_ortho ? -u_view_dir : normalize(u_eye - v_pos);
    float n;
    vec3 Bl[LR_MAX_LIGHTS];
    lr_gather_each(v_pos, no, n, Bl);
    float eta = lr_material(u_object).eta;
    float s = lr_fresnel_transmittance(abs(dot(no, wo)), eta) / LR_PI;
    float a = n > 0.0 ? 1.0 : 0.0;
    o_light[0] = vec4(s * (Bl[0] + lr_lpv_obj_B(0, v_pos, no) +
                        lr_rl_B(0, v_rlp[0], v_rlm[0], back)), a);
    o_light[1] = vec4(s * (Bl[1] + lr_lpv_obj_B(1, v_pos, no) +
                        lr_rl_B(1, v_rlp[1], v_rlm[1], back)), a);
    o_light[2] = vec4(s * (Bl[2] + lr_lpv_obj_B(2, v_pos, no) +
                        lr_rl_B(2, v_rlp[2], v_rlm[2], back)), a);
    o_light[3] = vec4(s * (Bl[3] + lr_lpv_obj_B(3, v_pos, no) +
                        lr_rl_B(3, v_rlp[3], v_rlm[3], back)), a);
}
