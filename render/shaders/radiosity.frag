// Pass 2: one frame's estimate of scattered radiosity B(x_o) per colour band for a light of
// unit intensity (render/passes/PIPELINE.md, seed 003 Eq. 4/9 with the exact Jacobian),
// written to attachment 0 and blended into the running mean by the caller (constant blend
// colour 1/F). Attachments 1 and 2 keep x_o (coverage in .w) and n_o (object id in .w).
#include "lib/material.glsl"
#include "lib/random.glsl"
#include "lib/gbuffer.glsl"
#include "lib/profile.glsl"
#include "lib/dgrid.glsl"

in vec3 v_pos;
in vec3 v_nrm;
in vec3 v_trB;              // translucent radiosity: the vertices' solved B (radiosity.vert)
uniform bool u_tr_on;
uniform int u_object;
uniform bool u_two_sided;
uniform int u_light_type;   // LR_LIGHT_POINT, _SPOT, _DIRECTIONAL, _QUAD, _DISK
uniform vec2 u_spot_cos;    // cos(outer), cos(inner)
// Area lights (render/area/frames.h): this frame's sample p_f is u_light_pos, and the whole
// emitter's Lambertian profile I(w) = A cos(theta_e) about u_area_n (|cos| two-sided) is
// the intensity, as lr_light_shape in the twin.
uniform vec3 u_area_n;
uniform float u_area;
uniform bool u_area_two_sided;
uniform int u_N;
uniform float u_r_max;      // 20 R; point/spot lights: r_max = max(u_r_max, u_r_max_dist d)
uniform float u_r_max_dist; // 20 (PIPELINE.md: r_max = 20 max(R, |x_l - x_o|))
uniform float u_near_mix;   // LR_PASS_NEAR_MIX (render/models/twin/radiosity.h): near lights
uniform uint u_seed;
uniform uint u_map;
uniform uint u_frame;
uniform int u_map_size;
uniform float u_map_scale; // stored value = B * scale (render/passes/radiosity.c)
uniform float u_map_max;   // largest stored value (half-float maps: below the fp16 maximum)
// Per object: S_d's energy normalisation per band (PIPELINE.md "Energy"; 1: the raw model).
uniform vec3 u_sd_norm[LR_MAX_OBJECTS];
layout(location = 0) out vec4 o_B;
layout(location = 1) out vec4 o_pos;
layout(location = 2) out vec4 o_nrm;

// A photometric profile (lib/profile.glsl): this light's planes at u_profile_light's rows,
// in the frame (C0, C90, nadir).
uniform bool u_profile_on;
uniform int u_profile_light;
uniform vec3 u_prof_x, u_prof_y, u_prof_z;

// The light's angular profile along `dir` (from the light): lr_light_shape.
float light_shape(vec3 dir)
{
    vec3 w = normalize(dir);
    if (u_light_type == LR_LIGHT_QUAD || u_light_type == LR_LIGHT_DISK) {
        float c = dot(w, u_area_n);
        if (u_profile_on) {
            if (c < 0.0 && u_area_two_sided) { // the back face: the front's pattern mirrored
                w -= 2.0 * c * u_area_n;
                c = -c;
            }
            c = c > 0.0 ? lr_profile_rel_world(u_profile_light, w, u_prof_x, u_prof_y, u_prof_z)
                        : 0.0;
        } else if (u_area_two_sided)
            c = abs(c);
        return c > 0.0 ? u_area * c : 0.0;
    }
    float s = u_light_type == LR_LIGHT_SPOT ? smoothstep(u_spot_cos.x, u_spot_cos.y,
                                                         dot(w, u_light_dir)) : 1.0;
    if (u_profile_on && s > 0.0)
        s *= lr_profile_rel_world(u_profile_light, w, u_prof_x, u_prof_y, u_prof_z);
    return s;
}

#include "lib/sh_translucency.glsl"

// Density per unit solid angle of the light's direction u under the stereographic lookup
// (seed 003 Eq. 13 inverted: the plane point on the line from the antipode A through
// x_l + d u), in coordinates relative to x_o (h = x_l - x_o); 0 where no sampled radius maps
// there. The twin's stereo_pdf_omega.
float stereo_pdf(vec3 u, vec3 h, float d, vec3 no, float sigma_tr, float mass, bool flat_r,
                 float r_max)
{
    vec3 hA = 2.0 * h;
    vec3 pa = h + d * u - hA;
    float den = dot(no, pa);
    if (den == 0.0)
        return 0.0;
    float s = -dot(no, hA) / den;
    if (!(s > 0.0))
        return 0.0;
    vec3 q = s * pa;  // x_j - A
    vec3 rj = hA + q; // x_j - x_o
    float r = length(rj);
    if (!(r > 0.0) || r > r_max * 1.000001)
        return 0.0;
    float pr = flat_r ? 1.0 / r_max : sigma_tr * exp(-sigma_tr * min(r, r_max)) / mass;
    float q2 = dot(q, q);
    vec3 l = q * inversesqrt(q2);
    float J = 2.0 * abs(2.0 * dot(h, l)) * abs(dot(l, no)) / (d * q2);
    return J > 0.0 ? pr / (2.0 * LR_PI * r) / J : 0.0;
}

void main()
{
    vec3 xo = v_pos;
    vec3 no = normalize(v_nrm);
    if (u_two_sided && !gl_FrontFacing)
        no = -no;
    if (u_tr_on) {
        // Translucent radiosity (seed 000 Eq. 14, solved over patches on the CPU,
        // render/transrad/): no estimator, the same B every frame, so the running mean is B.
        o_B = vec4(min(v_trB * u_map_scale, vec3(u_map_max)), 1.0);
        o_pos = vec4(xo, 1.0);
        o_nrm = vec4(no, float(u_object));
        return;
    }
    lr_coeffs_gl mat = lr_material(u_object);
    lr_sss_gl sss = lr_material_sss(u_object);
    if (LR_MODEL_HAS_B(sss.model)) {
        // A model with a B of its own (render/models/model.h glsl_B), drawn without samples:
        // seed 001's grid solved on the CPU (lib/dgrid.glsl), seed 002's SH evaluated once
        // per texel (Eq. 10-12, lib/sh_translucency.glsl).
        vec3 Bown = LR_MODEL_B(sss.model, u_object, mat, xo, no);
        o_B = vec4(min(Bown * u_map_scale, vec3(u_map_max)), 1.0);
        o_pos = vec4(xo, 1.0);
        o_nrm = vec4(no, float(u_object));
        return;
    }
    ivec2 tx = ivec2(gl_FragCoord.xy);
    uint state = lr_seed(uint(tx.y * u_map_size + tx.x), u_map, u_frame, u_seed);

    // Tangent frame at x_o (point lights), or the light's view plane (directional).
    vec3 axis = u_light_type == LR_LIGHT_DIRECTIONAL ? u_light_dir : no;
    vec3 a = abs(axis.z) < 0.9 ? vec3(0.0, 0.0, 1.0) : vec3(1.0, 0.0, 0.0);
    vec3 t1 = normalize(cross(a, axis));
    vec3 t2 = cross(axis, t1);

    vec3 h = u_light_pos - xo;
    float d = length(h);
    vec3 A = u_light_pos + h; // antipode of x_o on the sphere of radius d around the light

    float r_max = u_light_type == LR_LIGHT_DIRECTIONAL ? u_r_max : max(u_r_max, u_r_max_dist * d);
    vec3 B = vec3(0.0);
    for (int c = 0; c < 3; c++) {
        float sigma_tr = mat.sigma_tr[c];
        // lr_exp_radius_sample / _pdf with the per-band constant hoisted: for the inverted
        // CDF, e^{-sigma_tr r} = 1 - xi mass, so p(r) = sigma_tr (1 - xi mass) / mass.
        bool flat_r = sigma_tr * r_max < 1e-30;
        float mass = flat_r ? 1.0 : -lr_expm1(-sigma_tr * r_max);
        float sum = 0.0;
        // A near point or spot light (sigma_tr d < u_near_mix): odd samples a direction from
        // the light uniform over the sphere, combined with the lookup's by the balance
        // heuristic, a_d = floor(N / 2) / N (the twin's sample_pass, PIPELINE.md "Near lights").
        bool near = u_light_type != LR_LIGHT_DIRECTIONAL && sigma_tr * d < u_near_mix && u_N > 1;
        float ad = near ? float(u_N / 2) / float(u_N) : 0.0;
        for (int j = 0; j < u_N; j++) {
            float xi1 = lr_rand(state);
            float xi2 = lr_rand(state);
            if (near && (j & 1) == 1) {
                float z = 1.0 - 2.0 * xi1, ph = 2.0 * LR_PI * xi2;
                float sz = sqrt(max(0.0, 1.0 - z * z));
                vec3 u = vec3(sz * cos(ph), sz * sin(ph), z);
                float p = (1.0 - ad) * stereo_pdf(u, h, d, no, sigma_tr, mass, flat_r, r_max) +
                          ad / (4.0 * LR_PI);
                vec3 xi, ni;
                int id;
                if (!(d > 1e-6) || !lr_gbuffer_fetch(u, xi, ni, id) || id != u_object)
                    continue;
                vec3 wi = normalize(u_light_pos - xi);
                float cos_i = dot(ni, wi);
                if (!(cos_i > 0.0))
                    continue;
                float Ft = lr_fresnel_transmittance(cos_i, mat.eta);
                float sd = lr_sss_sd_band(mat, sss, c, xi, ni, wi, xo, no);
                sum += sd * Ft * light_shape(u) / p;
                continue;
            }
            float r, pr;
            if (flat_r) {
                r = xi1 * r_max;
                pr = 1.0 / r_max;
            } else {
                r = min(-lr_log1p(-xi1 * mass) / sigma_tr, r_max);
                pr = sigma_tr * (1.0 - xi1 * mass) / mass;
            }
            float alpha = 2.0 * LR_PI * xi2;
            // 1 / p_A = 2 pi r / p(r) (density per unit area of the sampling plane).
            if (!(pr > 0.0) || !(r > 0.0))
                continue;
            float inv_pA = 2.0 * LR_PI * r / pr;
            vec3 xj = xo + r * (cos(alpha) * t1 + sin(alpha) * t2);
            vec3 xi, ni;
            int id;
            vec3 wi;
            float J;
            float shape = 1.0;
            if (u_light_type == LR_LIGHT_DIRECTIONAL) {
                if (!lr_gbuffer_fetch(xj, xi, ni, id))
                    continue;
                wi = -u_light_dir;
                J = 1.0; // cos theta_i dA_i = dA_plane
            } else {
                if (!(d > 1e-6))
                    continue;
                // Seed 003 Eq. 13-14 (stereographic lookup), Jacobian of PIPELINE.md.
                vec3 q = xj - A;
                float q2 = dot(q, q);
                if (!(q2 > 0.0))
                    continue;
                vec3 l = q * inversesqrt(q2);
                float hl = dot(h, l);
                vec3 v = h - 2.0 * hl * l;
                float t = abs(2.0 * hl);
                J = 2.0 * t * abs(dot(l, no)) / (d * q2);
                if (!lr_gbuffer_fetch(v, xi, ni, id))
                    continue;
                wi = normalize(u_light_pos - xi);
                shape = light_shape(v);
            }
            if (id != u_object)
                continue; // light does not scatter from one object into another
            float cos_i = dot(ni, wi);
            if (!(cos_i > 0.0))
                continue;
            float Ft = lr_fresnel_transmittance(cos_i, mat.eta);
            float sd = lr_sss_sd_band(mat, sss, c, xi, ni, wi, xo, no);
            // near: p_s = p_A / J for this direction, mixed with the direction samples'
            float w = near ? 1.0 / ((1.0 - ad) + ad / (4.0 * LR_PI) * J * inv_pA) : 1.0;
            sum += sd * Ft * J * inv_pA * shape * w;
        }
        B[c] = LR_PI * sum / float(u_N) * u_sd_norm[clamp(u_object, 0, LR_MAX_OBJECTS - 1)][c];
    }
    o_B = vec4(min(B * u_map_scale, vec3(u_map_max)), 1.0);
    o_pos = vec4(xo, 1.0);
    o_nrm = vec4(no, float(u_object));
}
