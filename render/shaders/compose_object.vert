// The objects' composition (compose_object.frag): mesh.vert, plus the receivers' light on the
// object per vertex (lib/recv_light_vert.glsl; indexed draw, so gl_VertexID is the vertex).
#include "lib/recv_light_vert.glsl"
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_nrm;
uniform mat4 u_vp;
out vec3 v_pos;
out vec3 v_nrm;

void main()
{
    v_pos = a_pos;
    v_nrm = a_nrm;
    lr_rl_vertex(gl_VertexID);
    gl_Position = u_vp * vec4(a_pos, 1.0);
}
