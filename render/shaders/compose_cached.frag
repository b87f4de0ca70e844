// Pass 3 for the translucent objects from the surface cache (render/passes/surface.h), one
// image per light at unit intensity: B_l interpolated from the refined triangle's vertices
// (compose_cached.vert), times this object's cavity gain for light l (u_gain, PIPELINE.md
// "Energy"), then L_o,l = F_t(w_o) B_l / pi (seed 003 Eq. 5), the view-dependent factor,
// per pixel. compose_object.frag is the per-pixel gather this replaces (render.surface_cache).
// render.lpv adds the volume's indirect light on the object per pixel (lib/lpv_object.glsl).
#include "lib/material.glsl"
#include "lib/lpv_object.glsl"
#ifndef LR_CACHE_LIGHTS
#define LR_CACHE_LIGHTS LR_MAX_LIGHTS
#endif

in vec3 v_pos;
in vec3 v_nrm;
in vec4 v_front[LR_CACHE_LIGHTS]; // the scene's lights (compose_cached.vert)
in vec4 v_back[LR_CACHE_LIGHTS];
uniform int u_object;
uniform bool u_two_sided;
uniform vec3 u_eye;      // camera position (perspective)
uniform vec3 u_view_dir; // camera forward (orthographic)
uniform bool u_ortho;
uniform vec3 u_gain[LR_MAX_LIGHTS];
layout(location = 0) out vec4 o_light[LR_MAX_LIGHTS];

void main()
{
    vec3 no = normalize(v_nrm);
    bool back = u_two_sided && !gl_FrontFacing;
    if (back)
        no = -no;
    vec3 wo = u_ortho ? -u_view_dir : normalize(u_eye - v_pos);
    float s = lr_fresnel_transmittance(abs(dot(no, wo)), lr_material(u_object).eta) / LR_PI;
    // Lights beyond the scene's have no image attached: their writes are dropped.
    vec4 b0 = back ? v_back[0] : v_front[0];
    vec4 b1 = vec4(0.0), b2 = vec4(0.0), b3 = vec4(0.0);
#if LR_CACHE_LIGHTS >= 2
    b1 = back ? v_back[1] : v_front[1];
#endif
#if LR_CACHE_LIGHTS >= 3
    b2 = back ? v_back[2] : v_front[2];
#endif
#if LR_CACHE_LIGHTS >= 4
    b3 = back ? v_back[3] : v_front[3];
#endif
    // Coverage as compose_object.frag's: 0 where the vertices mostly took the fallback.
    float a = b0.a >= 0.5 ? 1.0 : 0.0;
    o_light[0] = vec4(s * (u_gain[0] * b0.rgb + lr_lpv_obj_B(0, v_pos, no)), a);
    o_light[1] = vec4(s * (u_gain[1] * b1.rgb + lr_lpv_obj_B(1, v_pos, no)), a);
    o_light[2] = vec4(s * (u_gain[2] * b2.rgb + lr_lpv_obj_B(2, v_pos, no)), a);
    o_light[3] = vec4(s * (u_gain[3] * b3.rgb + lr_lpv_obj_B(3, v_pos, no)), a);
}
