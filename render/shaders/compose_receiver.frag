// Pass 3 for the diffuse receivers (table, wall): L_l = albedo / pi (E_direct,l + E_vpl,l)
// (render/passes/PIPELINE.md, pass 4), one image per light l at unit intensity (the blend pass
// weights them). E_direct,l: 1 / distance^2 * cos, shadowed by the objects through light l's
// G-buffer, per pixel. E_vpl,l: from the receiver irradiance grid where the receiver has one
// (a plane: irradiance.frag filled it, render/core/recv_grid.h; bilinear over texel centres,
// clamped at the edges), else the sum over the VPLs here (lib/vpl_irradiance.glsl).
#include "lib/material.glsl"
#include "lib/lights.glsl"
#include "lib/vpl_irradiance.glsl"

in vec3 v_pos;
in vec3 v_nrm;
uniform vec3 u_albedo;
uniform bool u_use_vpl;
uniform bool u_cached;               // this receiver has a grid
uniform highp sampler2DArray u_irr;  // grids, layer u_irr_layer + l for light l
uniform int u_irr_layer;
uniform vec3 u_grid_c, u_grid_a, u_grid_b; // centre; axes divided by the plane's w and h
// Area lights (quad, disk): their direct light is the running mean over the frame samples in
// u_area_grid (render/passes/area_direct.c), read like the VPL grid; the G-buffer holds only
// the last frame's sample.
uniform bool u_area_cached;
uniform highp sampler2DArray u_area_grid; // layer u_area_layer + l for light l
uniform int u_area_layer;
uniform vec3 u_area_c, u_area_a, u_area_b;
// Image l holds u_image_scale[l] L_l (half floats in their normal range; compose.h).
uniform float u_image_scale[LR_MAX_LIGHTS];
// Output l is light l's image (unrolled writes: GLSL ES indexes outputs by constants only).
// LR_RECV_LIGHTS: the scene's lights (one program per count, render/renderer.c), the bound of
// the per-light loops: llvmpipe runs a loop body for every index up to it.
#ifndef LR_RECV_LIGHTS
#define LR_RECV_LIGHTS LR_MAX_LIGHTS
#endif
layout(location = 0) out vec4 o_light[LR_MAX_LIGHTS];

// Bilinear over the texel centres of an R x R grid of layer z (clamped at the edges).
vec3 lr_grid_bilinear(highp sampler2DArray g, int z, vec3 x, vec3 c, vec3 ga, vec3 gb)
{
    int R = textureSize(g, 0).x;
    vec3 d = x - c;
    vec2 f = (vec2(dot(d, ga), dot(d, gb)) + 0.5) * float(R) - 0.5;
    vec2 i0 = floor(f);
    vec2 w = f - i0;
    ivec2 a = clamp(ivec2(i0), ivec2(0), ivec2(R - 1));
    ivec2 b = clamp(ivec2(i0) + 1, ivec2(0), ivec2(R - 1));
    return (1.0 - w.y) * ((1.0 - w.x) * texelFetch(g, ivec3(a.x, a.y, z), 0).rgb +
                          w.x * texelFetch(g, ivec3(b.x, a.y, z), 0).rgb) +
           w.y * ((1.0 - w.x) * texelFetch(g, ivec3(a.x, b.y, z), 0).rgb +
                  w.x * texelFetch(g, ivec3(b.x, b.y, z), 0).rgb);
}

void main()
{
    vec3 x = v_pos;
    vec3 nx = normalize(v_nrm);
    vec3 E[LR_MAX_LIGHTS];
    for (int l = 0; l < LR_MAX_LIGHTS; l++)
        E[l] = vec3(0.0);
    for (int l = 0; l < LR_RECV_LIGHTS; l++) {
        if (l >= u_n_lights)
            E[l] = vec3(0.0);
        else if (lr_lights_is_area(l))
            E[l] = u_area_cached ? lr_grid_bilinear(u_area_grid, u_area_layer + l, x, u_area_c,
                                                    u_area_a, u_area_b)
                                 : vec3(0.0);
        else // the grid's layer of a point or spot light holds its render.lpv light alone
            E[l] = vec3(lr_lights_direct(l, x, nx)) +
                   (u_area_cached ? lr_grid_bilinear(u_area_grid, u_area_layer + l, x, u_area_c,
                                                     u_area_a, u_area_b)
                                  : vec3(0.0));
    }
    if (u_use_vpl && u_cached) {
        int R = textureSize(u_irr, 0).x;
        vec3 d = x - u_grid_c;
        vec2 f = (vec2(dot(d, u_grid_a), dot(d, u_grid_b)) + 0.5) * float(R) - 0.5;
        vec2 i0 = floor(f);
        vec2 w = f - i0;
        ivec2 a = clamp(ivec2(i0), ivec2(0), ivec2(R - 1));
        ivec2 b = clamp(ivec2(i0) + 1, ivec2(0), ivec2(R - 1));
        for (int l = 0; l < LR_RECV_LIGHTS; l++) {
            if (l >= u_n_lights)
                break;
            int z = u_irr_layer + l;
            E[l] += (1.0 - w.y) * ((1.0 - w.x) * texelFetch(u_irr, ivec3(a.x, a.y, z), 0).rgb +
                                   w.x * texelFetch(u_irr, ivec3(b.x, a.y, z), 0).rgb) +
                    w.y * ((1.0 - w.x) * texelFetch(u_irr, ivec3(a.x, b.y, z), 0).rgb +
                           w.x * texelFetch(u_irr, ivec3(b.x, b.y, z), 0).rgb);
        }
    } else if (u_use_vpl) {
        lr_vpl_irradiance(x, nx, E);
    }
    vec3 alb = u_albedo / LR_PI;
    o_light[0] = vec4(u_image_scale[0] * alb * E[0], 1.0);
    o_light[1] = vec4(u_image_scale[1] * alb * E[1], 1.0);
    o_light[2] = vec4(u_image_scale[2] * alb * E[2], 1.0);
    o_light[3] = vec4(u_image_scale[3] * alb * E[3], 1.0);
}
