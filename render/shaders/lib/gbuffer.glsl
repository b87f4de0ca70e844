// Lookups into the light G-buffer (pass 1): first surface of the translucent objects seen
// from the light. Mode 0: cube map around a point light (lookup by direction from the light);
// 1: one perspective 2D map (point/spot light, lookup by direction); 2: orthographic 2D map
// (directional light, lookup by world point). Position texels hold (x, id + 1), 0 = empty.

#include "gbuffer_texel.glsl"

uniform highp samplerCube u_gb_cube_pos;
uniform highp samplerCube u_gb_cube_nrm;
uniform highp sampler2D u_gb_pos;
uniform highp sampler2D u_gb_nrm;
uniform int u_gb_mode;     // LR_GB_CUBE, LR_GB_PERSPECTIVE, LR_GB_ORTHO (render/passes/gbuffer.h)
uniform mat4 u_gb_vp;      // world -> clip of the 2D map
uniform vec3 u_light_pos;  // point, spot
uniform vec3 u_light_dir;  // spot axis, directional travel direction (unit)

// Looks up the G-buffer along direction v from the light (LR_GB_CUBE, LR_GB_PERSPECTIVE) or
// at world point v (LR_GB_ORTHO). Returns false where there is no surface.
bool lr_gbuffer_fetch(vec3 v, out vec3 xi, out vec3 ni, out int id)
{
    vec4 p;
    vec4 n;
    if (u_gb_mode == LR_GB_CUBE) {
        p = texture(u_gb_cube_pos, v);
        n = texture(u_gb_cube_nrm, v);
    } else {
        ivec2 t;
        if (!lr_gbuffer_texel(u_gb_mode, u_gb_vp, u_light_pos, v, textureSize(u_gb_pos, 0), t))
            return false;
        p = texelFetch(u_gb_pos, t, 0);
        n = texelFetch(u_gb_nrm, t, 0);
    }
    if (!(p.w > 0.5))
        return false;
    xi = p.xyz;
    ni = normalize(n.xyz);
    id = int(p.w + 0.5) - 1;
    return true;
}

// Whether world point x (a receiver) sees the light: nearer to it than the G-buffer's surface
// in its direction, or no surface there. bias in mm.
bool lr_gbuffer_lit(vec3 x, float bias)
{
    vec3 xi, ni;
    int id;
    if (u_gb_mode == LR_GB_ORTHO) {
        if (!lr_gbuffer_fetch(x, xi, ni, id))
            return true;
        return dot(x - xi, u_light_dir) < bias;
    }
    vec3 v = x - u_light_pos;
    if (!lr_gbuffer_fetch(v, xi, ni, id))
        return true;
    return length(v) < length(xi - u_light_pos) + bias;
}
