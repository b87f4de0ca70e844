// The receiver irradiance pass (render/passes/irradiance.c): E_vpl,l per light l at unit
// intensity at the centre of texel (s, t) of a plane receiver's grid (render/core/recv_grid.h:
// x = c + ((s + 1/2) / R - 1/2) w a + ((t + 1/2) / R - 1/2) h b), one layer per light. It
// depends on neither camera nor projector, so composition reads it with four fetches.
#include "lib/material.glsl"
#include "lib/lights.glsl"
#include "lib/vpl_irradiance.glsl"

uniform vec3 u_grid_c, u_grid_wa, u_grid_hb; // centre; w a and h b
uniform vec3 u_grid_n;                       // the plane's front normal
uniform int u_grid_size;                     // R
// Translucent radiosity (seed 000, render/transrad/tr_scene.h): per light the irradiance the
// VPLs do not carry (receiver inter-reflection, the objects' inner faces), on the same grid.
uniform bool u_tr_on;
uniform highp sampler2DArray u_tr_E;
uniform int u_tr_layer;
layout(location = 0) out vec4 o_light[LR_MAX_LIGHTS];

void main()
{
    vec2 uv = gl_FragCoord.xy / float(u_grid_size) - 0.5;
    vec3 x = u_grid_c + uv.x * u_grid_wa + uv.y * u_grid_hb;
    vec3 E[LR_MAX_LIGHTS];
    for (int l = 0; l < LR_MAX_LIGHTS; l++)
        E[l] = vec3(0.0);
    lr_vpl_irradiance(x, u_grid_n, E);
    if (u_tr_on)
        for (int l = 0; l < LR_MAX_LIGHTS; l++)
            if (l < u_n_lights)
                E[l] += texelFetch(u_tr_E, ivec3(ivec2(gl_FragCoord.xy), u_tr_layer + l), 0).rgb;
    o_light[0] = vec4(E[0], 1.0);
    o_light[1] = vec4(E[1], 1.0);
    o_light[2] = vec4(E[2], 1.0);
    o_light[3] = vec4(E[3], 1.0);
}
