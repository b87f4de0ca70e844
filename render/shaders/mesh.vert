// World-space meshes (objects and receivers are stored in world coordinates): position and
// normal pass through; u_vp is the pass's world -> clip matrix.
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_nrm;
uniform mat4 u_vp;
out vec3 v_pos;
out vec3 v_nrm;

void main()
{
    v_pos = a_pos;
    v_nrm = a_nrm;
    gl_Position = u_vp * vec4(a_pos, 1.0);
}
