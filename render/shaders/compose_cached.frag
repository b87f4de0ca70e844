// Pass 3 for the translucent objects from the surface cache (render/passes/surface.h), one
// image per light at unit intensity: B_l interpolated linearly over the lattice sub-triangle
// that holds the pixel's point (render/mesh/lattice.h; the same arithmetic as
// lr_lattice_locate, the CPU twin's), times this object's cavity gain for light l (u_gain,
// PIPELINE.md "Energy"), then L_o,l = F_t(w_o) B_l / pi (seed 003 Eq. 5), the view-dependent
// factor. compose_object.frag is the per-pixel gather this replaces (render.surface_cache).
// render.lpv adds the volume's indirect light on the object per pixel (lib/lpv_object.glsl),
// render.receiver_light_on_objects the receivers' light on it (lib/recv_light.glsl).
#include "lib/material.glsl"
#include "lib/lpv_object.glsl"
#include "lib/recv_light.glsl"
#ifndef LR_CACHE_LIGHTS
#define LR_CACHE_LIGHTS LR_MAX_LIGHTS
#endif

in vec3 v_pos;
in vec3 v_nrm;
in vec2 v_uv;
flat in ivec2 v_lat; // first entry of the triangle's lattice, resolution R
uniform highp sampler2DArray u_surface_B; // layer l: light l's B (rgb), a map saw it (a)
uniform int u_surface_row;                 // entries per row
uniform int u_nv;                          // entries of the object's front side
uniform int u_object;
uniform bool u_two_sided;
uniform vec3 u_eye;      // camera position (perspective)
uniform vec3 u_view_dir; // camera forward (orthographic)
uniform bool u_ortho;
uniform vec3 u_gain[LR_MAX_LIGHTS];
layout(location = 0) out vec4 o_light[LR_MAX_LIGHTS];

ivec3 lr_entry(int k, int l)
{
    return ivec3(k % u_surface_row, k / u_surface_row, l);
}

// Lattice point (i, j) of resolution R, counted from the triangle's first (lattice.h).
int lr_lat_vertex(int R, int i, int j)
{
    return j * (2 * R + 3 - j) / 2 + i;
}

vec4 lr_cached(ivec3 k0, ivec3 k1, ivec3 k2, vec3 w, int l)
{
    k0.z = k1.z = k2.z = l;
    return w.x * texelFetch(u_surface_B, k0, 0) + w.y * texelFetch(u_surface_B, k1, 0) +
           w.z * texelFetch(u_surface_B, k2, 0);
}

void main()
{
    vec3 no = normalize(v_nrm);
    bool back = u_two_sided && !gl_FrontFacing;
    if (back)
        no = -no;
    vec3 wo = u_ortho ? -u_view_dir : normalize(u_eye - v_pos);
    float s = lr_fresnel_transmittance(abs(dot(no, wo)), lr_material(u_object).eta) / LR_PI;
    // The sub-triangle: cell (i, j), i, j >= 0, i + j <= R - 1, lower or upper half.
    int R = v_lat.y;
    float fR = float(R);
    vec2 xy = v_uv * fR;
    float fi = clamp(floor(xy.x), 0.0, fR - 1.0);
    float fj = clamp(floor(xy.y), 0.0, fR - 1.0 - fi);
    float fx = xy.x - fi, fy = xy.y - fj;
    int i = int(fi), j = int(fj);
    bool upper = fx + fy > 1.0 && i + j <= R - 2;
    int base = v_lat.x + (back ? u_nv : 0);
    vec3 w;
    int c0, c1, c2;
    if (upper) {
        w = vec3(1.0 - fy, fx + fy - 1.0, 1.0 - fx);
        c0 = lr_lat_vertex(R, i + 1, j);
        c1 = lr_lat_vertex(R, i + 1, j + 1);
    } else {
        w = vec3(1.0 - fx - fy, fx, fy);
        c0 = lr_lat_vertex(R, i, j);
        c1 = lr_lat_vertex(R, i + 1, j);
    }
    c2 = lr_lat_vertex(R, i, j + 1);
    ivec3 k0 = lr_entry(base + c0, 0), k1 = lr_entry(base + c1, 0), k2 = lr_entry(base + c2, 0);
    // Lights beyond the scene's have no image attached: their writes are dropped.
    vec4 b0 = lr_cached(k0, k1, k2, w, 0);
    vec4 b1 = vec4(0.0), b2 = vec4(0.0), b3 = vec4(0.0);
#if LR_CACHE_LIGHTS >= 2
    b1 = lr_cached(k0, k1, k2, w, 1);
#endif
#if LR_CACHE_LIGHTS >= 3
    b2 = lr_cached(k0, k1, k2, w, 2);
#endif
#if LR_CACHE_LIGHTS >= 4
    b3 = lr_cached(k0, k1, k2, w, 3);
#endif
    // Coverage as compose_object.frag's: 0 where the entries mostly took the fallback.
    float a = b0.a >= 0.5 ? 1.0 : 0.0;
    o_light[0] = vec4(s * (u_gain[0] * b0.rgb + lr_lpv_obj_B(0, v_pos, no) +
                        lr_rl_B(0, v_rlp[0], v_rlm[0], back)), a);
    o_light[1] = vec4(s * (u_gain[1] * b1.rgb + lr_lpv_obj_B(1, v_pos, no) +
                        lr_rl_B(1, v_rlp[1], v_rlm[1], back)), a);
    o_light[2] = vec4(s * (u_gain[2] * b2.rgb + lr_lpv_obj_B(2, v_pos, no) +
                        lr_rl_B(2, v_rlp[2], v_rlm[2], back)), a);
    o_light[3] = vec4(s * (u_gain[3] * b3.rgb + lr_lpv_obj_B(3, v_pos, no) +
                        lr_rl_B(3, v_rlp[3], v_rlm[3], back)), a);
}
