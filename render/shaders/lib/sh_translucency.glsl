// Seed 002 (Banterle & Chalmers), the sh_translucency model's evaluation step per map texel
// (render/optics/sh_translucency.h is the C version and the derivation): B = s_c a_c(d) E(n_o)
// with E(n) = sum A_l E_lm Y_lm(n) (Eq. 10-11, Ramamoorthi & Hanrahan's constants), the light's
// E_lm projected from its G-buffer on the CPU (render/passes/sh.c), d the thickness from the
// G-buffer depth toward x_o (Sec. 2.2) and a_c(d) = exp(-sigma_tr max(d, mfp)) (Eq. 12
// integrated over the lit face). Needs gbuffer.glsl and material.glsl.

#include "near_light.glsl"

uniform vec3 u_sh_E[3 * LR_MAX_OBJECTS];  // 9 E_lm per object, light of this draw
uniform vec3 u_sh_scale[LR_MAX_OBJECTS];  // s_c per object
uniform vec4 u_sh_rho[LR_MAX_OBJECTS];    // rho_c (lr_dipole_rd_total), lit threshold in mm

// max(0, E(n)) of object obj (lr_sh_env_irradiance).
float lr_sh_irradiance(int obj, vec3 n)
{
    int b = 3 * clamp(obj, 0, LR_MAX_OBJECTS - 1);
    vec3 e0 = u_sh_E[b], e1 = u_sh_E[b + 1], e2 = u_sh_E[b + 2];
    // Y_lm (lr_sh9_basis) times A_l (pi, 2 pi / 3, pi / 4).
    float y00 = 0.28209479177 * LR_PI;
    float k1 = 0.48860251190 * (2.0 * LR_PI / 3.0);
    float k2 = 1.09254843059 * (0.25 * LR_PI);
    float k20 = 0.31539156525 * (0.25 * LR_PI);
    float k22 = 0.54627421529 * (0.25 * LR_PI);
    float e = e0.x * y00 + k1 * (e0.y * n.y + e0.z * n.z + e1.x * n.x) +
              k2 * (e1.y * n.x * n.y + e1.z * n.y * n.z + e2.y * n.x * n.z) +
              k20 * e2.x * (3.0 * n.z * n.z - 1.0) + k22 * e2.z * (n.x * n.x - n.y * n.y);
    return max(e, 0.0);
}

// The thickness the light crossed to reach x_o (lr_cpu_sh_thickness): false where another
// object holds the G-buffer texel (its shadow), d = 0 where the texel is empty; ni the texel's
// normal (0 when empty).
bool lr_sh_thickness(int obj, vec3 xo, out float d, out vec3 ni)
{
    vec3 xi;
    int id;
    d = 0.0;
    ni = vec3(0.0);
    bool directional = u_light_type == LR_LIGHT_DIRECTIONAL;
    vec3 v = directional ? xo : xo - u_light_pos;
    if (!lr_gbuffer_fetch(v, xi, ni, id)) {
        ni = vec3(0.0);
        return true;
    }
    if (id != obj)
        return false;
    d = directional ? max(dot(xo - xi, u_light_dir), 0.0)
                    : max(length(v) - length(xi - u_light_pos), 0.0);
    return true;
}

// B per band for a unit light at (x_o, n_o) of object obj.
vec3 lr_sh_translucency_B(int obj, lr_coeffs_gl mat, vec3 xo, vec3 no)
{
    float d;
    vec3 ni;
    int o = clamp(obj, 0, LR_MAX_OBJECTS - 1);
    if (!lr_sh_thickness(obj, xo, d, ni))
        return vec3(0.0);
    vec3 a = exp(-mat.sigma_tr * max(vec3(d), mat.mfp));
    vec3 B = u_sh_scale[o] * a * lr_sh_irradiance(obj, no);
    // The direct term where x_o is the light's first surface (lr_sh_lit, lr_sh_direct).
    if (!(dot(ni, no) > 0.0) || !(d <= u_sh_rho[o].w))
        return B;
    // A point light's irradiance over the square of side mfp about x_o (lr_cpu_sh_B: the
    // point sample diverges as the light nears the wall), F_t at the patch's mean cosine.
    if (u_light_type == LR_LIGHT_DIRECTIONAL) {
        float cos_i = -dot(no, u_light_dir);
        if (!(cos_i > 0.0))
            return B;
        return B + u_sh_rho[o].rgb * (lr_fresnel_transmittance(cos_i, mat.eta) * cos_i);
    }
    vec3 h = u_light_pos - xo;
    float r2 = dot(h, h);
    if (!(r2 > 0.0))
        return B;
    vec3 u = h * inversesqrt(r2);
    if (!(dot(no, u) > 0.0))
        return B;
    float mu;
    float side = (mat.mfp.x + mat.mfp.y + mat.mfp.z) / 3.0;
    float E = lr_patch_irradiance_far(u_light_pos, xo, no, side, mu) * light_shape(-u);
    if (!(mu > 0.0))
        return B;
    return B + u_sh_rho[o].rgb * (lr_fresnel_transmittance(mu, mat.eta) * E);
}
