// The blend pass's vertex stage (render/passes/blend.h): the fullscreen triangle of
// fullscreen.vert, which also hands the fragment stage the weights and layers as flat
// varyings. Why: llvmpipe loads a fragment shader's uniforms again for every block of pixels,
// where a flat varying is set up once per triangle; with the weights as uniforms the blend
// measured 1.6x the floor pass at 1280x720, with them as flat varyings 1.35x (tools/bench/
// README.md "The blend's weights as flat varyings"). A GPU does either at no cost.
uniform vec3 u_w[4];
uniform int u_layer[4];
flat out vec3 v_w[4];
flat out ivec4 v_layer;

void main()
{
    vec2 p = vec2(float((gl_VertexID & 1) << 2) - 1.0, float((gl_VertexID & 2) << 1) - 1.0);
    for (int k = 0; k < 4; k++)
        v_w[k] = u_w[k];
    v_layer = ivec4(u_layer[0], u_layer[1], u_layer[2], u_layer[3]);
    gl_Position = vec4(p, 0.0, 1.0);
}
