// Seed 003 Algorithm 1: scattered radiosity B at a surface point from the K maps, a
// visibility-weighted average. Each map k has its direction d_k and world -> texture matrix
// P_k (x, y in [0, 1] across the map, z the map's depth in [0, 1]).
//
// Visibility is the shadow-map test against map k's depth with bias eps_bias, taken at the
// 2x2 texels around the lookup (bilinear weights), x_o first moved by eps_comb along
// -(n_o - cos theta d_k). A tap also needs the map's stored normal to face the same side as
// n_o (n_map . n_o > 0): beyond the paper; without it a shell thinner than eps_bias (a
// 1.5 mm shade) would take its outer surface's radiosity for its inner surface.

#ifndef LR_MAX_K
#define LR_MAX_K 32
#endif

uniform highp sampler2DArray u_map_B;     // B.rgb (unit light intensity)
uniform highp sampler2DArray u_map_nrm;   // n_o.xyz, object id
uniform highp sampler2DArray u_map_depth; // depth (1 = nothing)
uniform mat4 u_map_P[LR_MAX_K];
uniform vec3 u_map_d[LR_MAX_K];
uniform int u_K;
uniform float u_eps_bias; // in map depth units
uniform float u_eps_comb; // mm
#ifndef LR_MAX_LIGHTS
#define LR_MAX_LIGHTS 4
#endif
// Light l's map k is layer l K + k of u_map_B; the gather returns sum_l u_light_w[l] B_l,
// the weights per band carrying the maps' scale (render/passes/common.c lr_passes_bind_gather):
// intensities at composition, one light at a time for the VPLs.
uniform vec3 u_light_w[LR_MAX_LIGHTS];
uniform int u_n_lights;

// Adds wq u_light_w[l] B_l at texel ti of map k to each light's sum.
void lr_map_B_add(ivec2 ti, int k, float wq, inout vec3 Bl[LR_MAX_LIGHTS])
{
    for (int l = 0; l < LR_MAX_LIGHTS; l++) {
        if (l >= u_n_lights)
            break;
        Bl[l] += wq * u_light_w[l] * texelFetch(u_map_B, ivec3(ti, l * u_K + k), 0).rgb;
    }
}

// Algorithm 1 per light: Bl[l] = u_light_w[l] B_l (the same taps and visibility weights for
// every light, so sum_l Bl[l] is lr_gather's result); *n receives the summed visibility weight
// (0: no map sees x_o, in which case the map with the largest n_o . d_k is used without
// visibility). Composition writes one image per light from it.
void lr_gather_each(vec3 xo, vec3 no, out float n, out vec3 Bl[LR_MAX_LIGHTS])
{
    for (int l = 0; l < LR_MAX_LIGHTS; l++)
        Bl[l] = vec3(0.0);
    n = 0.0;
    ivec2 sz = textureSize(u_map_B, 0).xy;
    int best = 0;
    float best_cos = -2.0;
    for (int k = 0; k < LR_MAX_K; k++) {
        if (k >= u_K)
            break;
        vec3 d = u_map_d[k];
        float c = dot(no, d);
        if (c > best_cos) {
            best_cos = c;
            best = k;
        }
        float cos_t = clamp(c, 0.0, 1.0);
        vec3 xb = xo - u_eps_comb * (no - cos_t * d);
        vec3 t = (u_map_P[k] * vec4(xb, 1.0)).xyz;
        vec2 f = t.xy * vec2(sz) - 0.5;
        ivec2 i0 = ivec2(floor(f));
        vec2 w = f - vec2(i0);
        for (int q = 0; q < 4; q++) {
            ivec2 o = ivec2(q & 1, q >> 1);
            ivec2 ti = i0 + o;
            if (any(lessThan(ti, ivec2(0))) || any(greaterThanEqual(ti, sz)))
                continue;
            float wq = (o.x == 1 ? w.x : 1.0 - w.x) * (o.y == 1 ? w.y : 1.0 - w.y);
            float depth = texelFetch(u_map_depth, ivec3(ti, k), 0).r;
            if (!(depth < 1.0) || t.z - u_eps_bias > depth)
                continue;
            vec4 nm = texelFetch(u_map_nrm, ivec3(ti, k), 0);
            if (dot(nm.xyz, no) <= 0.0)
                continue;
            lr_map_B_add(ti, k, wq, Bl);
            n += wq;
        }
    }
    if (n > 1e-6) {
        for (int l = 0; l < LR_MAX_LIGHTS; l++)
            Bl[l] /= n;
        return;
    }
    // No map sees x_o: the one that faces it most, nearest texel, no visibility test.
    vec3 t = (u_map_P[best] * vec4(xo, 1.0)).xyz;
    ivec2 ti = clamp(ivec2(t.xy * vec2(sz)), ivec2(0), sz - 1);
    n = 0.0;
    for (int l = 0; l < LR_MAX_LIGHTS; l++)
        Bl[l] = vec3(0.0);
    lr_map_B_add(ti, best, 1.0, Bl);
}

// The weighted sum sum_l u_light_w[l] B_l (the VPL pass sets one light's weight at a time).
vec3 lr_gather(vec3 xo, vec3 no, out float n)
{
    vec3 Bl[LR_MAX_LIGHTS];
    lr_gather_each(xo, no, n, Bl);
    vec3 b = vec3(0.0);
    for (int l = 0; l < LR_MAX_LIGHTS; l++)
        b += Bl[l];
    return b;
}
