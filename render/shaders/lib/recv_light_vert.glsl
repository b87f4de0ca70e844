// The receivers' light on the objects, vertex side (render/bounce/objlight.h,
// render.receiver_light_on_objects): per light at unit intensity the vertex's E+ (its normal's
// side) and E- (the far face of a wall, or the back of an open surface), W/mm^2, fetched by
// entry k (the vertex index, or the surface cache's corner 3 t + c) from a texture of
// u_rl_width texels a row, light l side s from row (2 l + s) u_rl_rows
// (render/passes/irradiance.c), and interpolated over the triangle like the CPU twin's
// barycentrics. lib/recv_light.glsl turns them into B.
uniform bool u_rl_on;
uniform highp sampler2D u_rl;
uniform int u_rl_rows;
out vec3 v_rlp[LR_MAX_LIGHTS];
out vec3 v_rlm[LR_MAX_LIGHTS];

const int u_rl_width = 1024; // render/passes/irradiance.h LR_RL_TEX_WIDTH

vec3 lr_rl_fetch(int k, int block)
{
    return texelFetch(u_rl, ivec2(k % u_rl_width, block * u_rl_rows + k / u_rl_width), 0).rgb;
}

void lr_rl_vertex(int k)
{
    for (int l = 0; l < LR_MAX_LIGHTS; l++) {
        v_rlp[l] = u_rl_on ? lr_rl_fetch(k, 2 * l) : vec3(0.0);
        v_rlm[l] = u_rl_on ? lr_rl_fetch(k, 2 * l + 1) : vec3(0.0);
    }
}
