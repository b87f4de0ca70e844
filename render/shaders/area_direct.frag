// The area lights' direct light on a plane receiver (render/passes/area_direct.c): at the
// centre of texel (s, t) of its grid (render/core/recv_grid.h), the direct irradiance from
// each area light's sample of this frame (the G-buffer was drawn there), unit radiance,
// profile A cos(theta_e) (lib/lights.glsl); 0 for the other lights, whose direct light
// composition shadows per pixel. The caller blends it into the running mean (weight 1/F).
#include "lib/lights.glsl"

uniform vec3 u_grid_c, u_grid_wa, u_grid_hb; // centre; w a and h b
uniform vec3 u_grid_n;                       // the plane's front normal
uniform int u_grid_size;                     // R
// render.lpv: the light-propagation volume's indirect irradiance of this receiver's texel,
// light l in layer u_lpv_layer + l (render/lpv/scene_lpv.h), added to every frame alike.
uniform bool u_lpv_on;
uniform highp sampler2DArray u_lpv;
uniform int u_lpv_layer;
layout(location = 0) out vec4 o_light[LR_MAX_LIGHTS];

vec3 lr_lpv_at(int l)
{
    if (!u_lpv_on || l >= u_n_lights)
        return vec3(0.0);
    return texelFetch(u_lpv, ivec3(ivec2(gl_FragCoord.xy), u_lpv_layer + l), 0).rgb;
}

void main()
{
    vec2 uv = gl_FragCoord.xy / float(u_grid_size) - 0.5;
    vec3 x = u_grid_c + uv.x * u_grid_wa + uv.y * u_grid_hb;
    float E[LR_MAX_LIGHTS];
    for (int l = 0; l < LR_MAX_LIGHTS; l++)
        E[l] = l < u_n_lights && lr_lights_is_area(l) ? lr_lights_direct(l, x, u_grid_n) : 0.0;
    o_light[0] = vec4(vec3(E[0]) + lr_lpv_at(0), 1.0);
    o_light[1] = vec4(vec3(E[1]) + lr_lpv_at(1), 1.0);
    o_light[2] = vec4(vec3(E[2]) + lr_lpv_at(2), 1.0);
    o_light[3] = vec4(vec3(E[3]) + lr_lpv_at(3), 1.0);
}
