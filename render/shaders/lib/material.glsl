// Material coefficients of every translucent object, indexed by object id (the G-buffer's
// material id minus one). Five vec4 per object, filled by render/passes/common.c:
//   [0] sigma_tr.rgb, eta   [1] D.rgb, C_phi_norm   [2] de.rgb (< 0: infinite), C_phi
//   [3] sigma_t.rgb, C_E    [4] mfp.rgb, A_dir
#include "optics.glsl"

#ifndef LR_MAX_OBJECTS
#define LR_MAX_OBJECTS 8
#endif

uniform vec4 u_coef[5 * LR_MAX_OBJECTS];
// The diffusion model and standard-dipole coefficients, three vec4 per object (common.c
// lr_passes_pack_sss): [0] albedo'.rgb, model   [1] z_r.rgb, multipole thickness (mm)
// [2] z_v.rgb, multipole pole pairs (lr_passes_pack_multipole; 0 for the other models)
uniform vec4 u_sss[3 * LR_MAX_OBJECTS];

lr_coeffs_gl lr_material(int id)
{
    int b = 5 * clamp(id, 0, LR_MAX_OBJECTS - 1);
    lr_coeffs_gl c;
    c.sigma_tr = u_coef[b].xyz;
    c.eta = u_coef[b].w;
    c.D = u_coef[b + 1].xyz;
    c.C_phi_norm = u_coef[b + 1].w;
    c.de = u_coef[b + 2].xyz;
    c.C_phi = u_coef[b + 2].w;
    c.sigma_t = u_coef[b + 3].xyz;
    c.C_E = u_coef[b + 3].w;
    c.mfp = u_coef[b + 4].xyz;
    c.A_dir = u_coef[b + 4].w;
    return c;
}

lr_sss_gl lr_material_sss(int id)
{
    int b = 3 * clamp(id, 0, LR_MAX_OBJECTS - 1);
    lr_sss_gl s;
    s.model = int(u_sss[b].w + 0.5);
    s.albedo_prime = u_sss[b].xyz;
    s.z_r = u_sss[b + 1].xyz;
    s.z_v = u_sss[b + 2].xyz;
    s.thickness = u_sss[b + 1].w;
    s.pairs = clamp(int(u_sss[b + 2].w + 0.5), 0, 16); // LR_MULTIPOLE_MAX_PAIRS
    return s;
}
