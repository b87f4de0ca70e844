// Every light of the scene at composition (render/passes/common.c lr_passes_bind_lights):
// direct irradiance on a receiver, shadowed through each light's own G-buffer. GLSL ES 3.10
// indexes sampler arrays with constant expressions only, so the per-light lookups below are
// unrolled for LR_MAX_LIGHTS = 4 (render/passes/passes.h).
#include "gbuffer_texel.glsl"
#include "profile.glsl"

#ifndef LR_MAX_LIGHTS
#define LR_MAX_LIGHTS 4
#endif
#if LR_MAX_LIGHTS != 4
#error "lights.glsl unrolls its sampler arrays for 4 lights"
#endif

uniform highp samplerCube u_lights_cube[LR_MAX_LIGHTS]; // G-buffer positions, cube mode
uniform highp sampler2D u_lights_2d[LR_MAX_LIGHTS];     // G-buffer positions, 2D modes
uniform int u_lights_mode[LR_MAX_LIGHTS];               // gbuffer.glsl u_gb_mode
uniform mat4 u_lights_vp[LR_MAX_LIGHTS];
uniform int u_lights_type[LR_MAX_LIGHTS];               // LR_LIGHT_*
uniform vec3 u_lights_pos[LR_MAX_LIGHTS];
uniform vec3 u_lights_dir[LR_MAX_LIGHTS];
uniform vec2 u_lights_spot_cos[LR_MAX_LIGHTS];          // cos(outer), cos(inner)
uniform vec3 u_lights_I[LR_MAX_LIGHTS];                 // intensity per band (with flicker)
// Area lights (render/area/frames.h): u_lights_pos is this frame's sample p_f; the profile is
// A cos(theta_e) about the emitter's normal (|cos| when two-sided), lr_light_shape.
uniform vec3 u_lights_area_n[LR_MAX_LIGHTS];
uniform float u_lights_area[LR_MAX_LIGHTS];
uniform bool u_lights_two_sided[LR_MAX_LIGHTS];
// A photometric profile (lib/profile.glsl) in the frame (C0, C90, nadir): lr_light_shape.
uniform bool u_lights_profile[LR_MAX_LIGHTS];
uniform vec3 u_lights_prof_x[LR_MAX_LIGHTS];
uniform vec3 u_lights_prof_y[LR_MAX_LIGHTS];
uniform vec3 u_lights_prof_z[LR_MAX_LIGHTS];
uniform int u_n_lights;

vec4 lr_lights_cube_pos(int l, vec3 v)
{
    if (l == 0)
        return texture(u_lights_cube[0], v);
    if (l == 1)
        return texture(u_lights_cube[1], v);
    if (l == 2)
        return texture(u_lights_cube[2], v);
    return texture(u_lights_cube[3], v);
}

ivec2 lr_lights_2d_size(int l)
{
    if (l == 0)
        return textureSize(u_lights_2d[0], 0);
    if (l == 1)
        return textureSize(u_lights_2d[1], 0);
    if (l == 2)
        return textureSize(u_lights_2d[2], 0);
    return textureSize(u_lights_2d[3], 0);
}

vec4 lr_lights_2d_pos(int l, ivec2 t)
{
    if (l == 0)
        return texelFetch(u_lights_2d[0], t, 0);
    if (l == 1)
        return texelFetch(u_lights_2d[1], t, 0);
    if (l == 2)
        return texelFetch(u_lights_2d[2], t, 0);
    return texelFetch(u_lights_2d[3], t, 0);
}

// gbuffer.glsl lr_gbuffer_lit for light l: x nearer to the light than the G-buffer's surface
// in its direction, or no surface there.
bool lr_lights_lit(int l, vec3 x)
{
    int mode = u_lights_mode[l];
    vec3 v = mode == LR_GB_ORTHO ? x : x - u_lights_pos[l];
    vec4 p;
    if (mode == LR_GB_CUBE) {
        p = lr_lights_cube_pos(l, v);
    } else {
        ivec2 t;
        if (!lr_gbuffer_texel(mode, u_lights_vp[l], u_lights_pos[l], v, lr_lights_2d_size(l), t))
            return true;
        p = lr_lights_2d_pos(l, t);
    }
    if (!(p.w > 0.5))
        return true;
    if (mode == LR_GB_ORTHO)
        return dot(x - p.xyz, u_lights_dir[l]) < 0.0;
    return length(v) < length(p.xyz - u_lights_pos[l]);
}

bool lr_lights_is_area(int l)
{
    return u_lights_type[l] == LR_LIGHT_QUAD || u_lights_type[l] == LR_LIGHT_DISK;
}

// Irradiance at receiver point x (normal nx) from light l for unit intensity (PIPELINE.md
// pass 4): cos / distance^2 times the spot's or the area light's profile (directional: cos),
// 0 in shadow. An area light: the point light at this frame's sample (area_direct.frag
// averages it over frames).
float lr_lights_direct(int l, vec3 x, vec3 nx)
{
    if (u_lights_type[l] == LR_LIGHT_DIRECTIONAL) {
        float c = dot(nx, -u_lights_dir[l]);
        return c > 0.0 && lr_lights_lit(l, x) ? c : 0.0;
    }
    vec3 to_l = u_lights_pos[l] - x;
    float d2 = dot(to_l, to_l);
    float c = dot(nx, to_l) * inversesqrt(d2);
    if (!(c > 0.0) || !lr_lights_lit(l, x))
        return 0.0;
    float shape = 1.0;
    vec3 w = -to_l * inversesqrt(d2); // the way the light travels to x
    if (lr_lights_is_area(l)) {
        float ce = dot(w, u_lights_area_n[l]);
        if (u_lights_profile[l]) {
            if (ce < 0.0 && u_lights_two_sided[l]) { // the back face: the front's pattern mirrored
                w -= 2.0 * ce * u_lights_area_n[l];
                ce = -ce;
            }
            ce = ce > 0.0 ? lr_profile_rel_world(l, w, u_lights_prof_x[l], u_lights_prof_y[l],
                                                 u_lights_prof_z[l]) : 0.0;
        } else if (u_lights_two_sided[l])
            ce = abs(ce);
        shape = ce > 0.0 ? u_lights_area[l] * ce : 0.0;
    } else {
        if (u_lights_type[l] == LR_LIGHT_SPOT)
            shape = smoothstep(u_lights_spot_cos[l].x, u_lights_spot_cos[l].y,
                               dot(w, u_lights_dir[l]));
        if (u_lights_profile[l] && shape > 0.0)
            shape *= lr_profile_rel_world(l, w, u_lights_prof_x[l], u_lights_prof_y[l],
                                          u_lights_prof_z[l]);
    }
    return shape * c / d2;
}
