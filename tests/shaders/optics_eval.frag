// Evaluates the GLSL optics (render/shaders/lib/optics.glsl) on test cases: one row per case,
// inputs from u_cases (6 texels per row: x_i + material, n_i, w_i, x_o, n_o,
// (cos_i, eta, xi, r_max)), outputs per row: texel 0 S_d, 1 S_d F_t(w_i),
// 2 (R(cos_i; eta), exp radius sample(sigma_tr[0], r_max, xi), its pdf, 0), 3 the model
// switch's S_d F_t(w_i) for the object's u_sss model, 4 the standard dipole's S_d.
#include "../../render/shaders/lib/material.glsl"

uniform highp sampler2D u_cases;
layout(location = 0) out vec4 o;

void main()
{
    ivec2 t = ivec2(gl_FragCoord.xy);
    vec4 a = texelFetch(u_cases, ivec2(0, t.y), 0);
    vec3 ni = texelFetch(u_cases, ivec2(1, t.y), 0).xyz;
    vec3 wi = texelFetch(u_cases, ivec2(2, t.y), 0).xyz;
    vec3 xo = texelFetch(u_cases, ivec2(3, t.y), 0).xyz;
    vec3 no = texelFetch(u_cases, ivec2(4, t.y), 0).xyz;
    vec4 s = texelFetch(u_cases, ivec2(5, t.y), 0);
    lr_coeffs_gl c = lr_material(int(a.w));
    if (t.x == 0)
        o = vec4(lr_dirpole_sd(c, a.xyz, ni, wi, xo, no), 0.0);
    else if (t.x == 1)
        o = vec4(lr_dirpole_sd_fresnel(c, a.xyz, ni, wi, xo, no), 0.0);
    else if (t.x == 3) {
        lr_sss_gl m = lr_material_sss(int(a.w));
        float cos_i = dot(wi, ni);
        float ft = cos_i > 0.0 ? lr_fresnel_transmittance(cos_i, c.eta) : 0.0;
        o = vec4(ft * lr_sss_sd_band(c, m, 0, a.xyz, ni, wi, xo, no),
                 ft * lr_sss_sd_band(c, m, 1, a.xyz, ni, wi, xo, no),
                 ft * lr_sss_sd_band(c, m, 2, a.xyz, ni, wi, xo, no), 0.0);
    } else if (t.x == 4) {
        lr_sss_gl m = lr_material_sss(int(a.w));
        o = vec4(lr_dipole_sd_band(c, m, 0, a.xyz, xo), lr_dipole_sd_band(c, m, 1, a.xyz, xo),
                 lr_dipole_sd_band(c, m, 2, a.xyz, xo), 0.0);
    } else {
        float r = lr_exp_radius_sample(c.sigma_tr.x, s.w, s.z);
        o = vec4(lr_fresnel_reflectance(s.x, s.y), r, lr_exp_radius_pdf(c.sigma_tr.x, s.w, r), 0.0);
    }
}
