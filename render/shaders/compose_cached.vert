// Composition of the objects from the surface cache (render/passes/surface.h): the object's
// original mesh, drawn unindexed (glDrawArrays), so that gl_VertexID / 3 is the triangle and
// gl_VertexID % 3 its corner; the corner's barycentrics (u, v) of p1 and p2 are interpolated
// (perspective-correct: the surface point's barycentrics in its triangle) and the triangle's
// lattice, a_lat = (first cache entry, resolution R; render/mesh/lattice.h), passes flat, so
// that compose_cached.frag finds the point's three cache entries by arithmetic. GLSL ES 3.1
// has no gl_PrimitiveID in fragment shaders, hence the flat varying. Position and normal pass
// through as in mesh.vert. The receivers' light on the object per corner
// (lib/recv_light_vert.glsl, its texture laid out by corner 3 t + c).
#include "lib/recv_light_vert.glsl"
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_nrm;
layout(location = 2) in ivec2 a_lat;
uniform mat4 u_vp;
out vec3 v_pos;
out vec3 v_nrm;
out vec2 v_uv;
flat out ivec2 v_lat;

void main()
{
    v_pos = a_pos;
    v_nrm = a_nrm;
    int c = gl_VertexID % 3;
    v_uv = vec2(c == 1 ? 1.0 : 0.0, c == 2 ? 1.0 : 0.0);
    v_lat = a_lat;
    lr_rl_vertex(gl_VertexID);
    gl_Position = u_vp * vec4(a_pos, 1.0);
}
