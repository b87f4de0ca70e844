// Composition of the objects from the surface cache (render/passes/surface.h): the refined
// mesh's vertex gl_VertexID of this object is cache entry u_base + gl_VertexID (its back side,
// for an open object, u_base + u_nv + gl_VertexID); B_l of each light is passed on to be
// interpolated over the triangle. Position and normal pass through as in mesh.vert.
// LR_CACHE_LIGHTS: the scene's lights (one program per count, render/renderer.c), so that a
// one-light scene interpolates two vec4 per fragment rather than eight.
#ifndef LR_CACHE_LIGHTS
#define LR_CACHE_LIGHTS LR_MAX_LIGHTS
#endif
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_nrm;
uniform mat4 u_vp;
uniform highp sampler2DArray u_surface_B; // layer l: light l's B (rgb), a map saw it (a)
uniform int u_surface_row;                 // entries per row
uniform int u_base, u_nv;
uniform bool u_two_sided;
out vec3 v_pos;
out vec3 v_nrm;
out vec4 v_front[LR_CACHE_LIGHTS];
out vec4 v_back[LR_CACHE_LIGHTS];

vec4 entry(int k, int l)
{
    return texelFetch(u_surface_B, ivec3(k % u_surface_row, k / u_surface_row, l), 0);
}

void main()
{
    v_pos = a_pos;
    v_nrm = a_nrm;
    int k = u_base + gl_VertexID;
    for (int l = 0; l < LR_CACHE_LIGHTS; l++) {
        v_front[l] = entry(k, l);
        v_back[l] = u_two_sided ? entry(k + u_nv, l) : vec4(0.0);
    }
    gl_Position = u_vp * vec4(a_pos, 1.0);
}
