// The radiosity pass's vertex shader: mesh.vert, plus, for an object whose model is
// translucent_radiosity (seed 000, render/transrad/), the vertex's solved B for the current
// light, fetched by vertex index from a texture of u_tr_width texels per row (light l's block
// starts at row u_tr_row0), interpolated over the triangle like the CPU twin's barycentrics.
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_nrm;
uniform mat4 u_vp;
uniform bool u_tr_on;
uniform highp sampler2D u_tr_B;
uniform int u_tr_row0;
out vec3 v_pos;
out vec3 v_nrm;
out vec3 v_trB;

const int u_tr_width = 1024; // render/passes/radiosity.c LR_TR_TEX_WIDTH

void main()
{
    v_pos = a_pos;
    v_nrm = a_nrm;
    v_trB = vec3(0.0);
    if (u_tr_on)
        v_trB = texelFetch(u_tr_B, ivec2(gl_VertexID % u_tr_width, u_tr_row0 + gl_VertexID / u_tr_width), 0).rgb;
    gl_Position = u_vp * vec4(a_pos, 1.0);
}
