// E_vpl per light at unit intensity (render/passes/PIPELINE.md pass 4): the VPLs with the
// bounded geometry term, A_v bounding the singularity; VPL v carries B per light for unit
// intensity (row l of u_vpl_B), times the cavity gain of its object for that light. Shared by
// composition (receivers without a cached grid) and the receiver irradiance pass
// (irradiance.frag). Needs lib/material.glsl and u_n_lights (lib/lights.glsl).

// Per light l and object i, element l LR_MAX_OBJECTS + i: light sent back into a cavity
// around light l (PIPELINE.md "Energy"); multiplies light l's B of the VPLs of object i.
uniform vec3 u_cavity_gain[LR_MAX_LIGHTS * LR_MAX_OBJECTS];
uniform highp sampler2D u_vpl_pos; // x_v, A_v
uniform highp sampler2D u_vpl_nrm; // n_v, object id
uniform highp sampler2D u_vpl_B;   // B_v per light (row l), unit intensity
uniform int u_n_vpl;
// VPL visibility (beyond seed 003, whose VPLs have none): the segment from the VPL to x is
// blocked where it passes inside the objects' outer envelope, i.e. nearer to the VPL centre c
// than the outermost surface in that direction (the VPL pass's cube map; exact for objects
// star-shaped around c, and a hollow shade counts as solid, which is right for light leaving
// its outer surface: it would have to cross the wall again).
uniform bool u_vpl_vis;
uniform highp samplerCube u_outer_pos;
uniform vec3 u_center;
uniform float u_outer_r; // mm: the objects' bounding sphere about u_center (the cube map's reach)
uniform float u_vis_eps; // mm: the start is moved this far off the surface along n_v

// 32 points: on jar_candle the segments from the pool's VPLs that graze the rim slip between
// 8 points (the wall then kept 2x the visible VPLs' light; tests/render/test_render_vplvis.c).
// They are spread over the part of the segment inside the objects' bounding sphere, the only
// part the envelope can block (over the whole segment to a wall 400 mm away they were 12 mm
// apart, three times the candle's rim). The envelope's texels are the test's resolution too:
// at the default 64^2 a face each VPL's shadow edge stepped with them (render/README.md).
#define LR_VIS_STEPS 32

bool lr_vpl_visible(vec3 xv, vec3 nv, vec3 x)
{
    vec3 a = xv + u_vis_eps * nv;
    // |a + t (x - a) - c| = R: t in [t0, t1] is inside the sphere (a is, up to eps).
    vec3 seg = x - a, ac = a - u_center;
    float dd = max(dot(seg, seg), 1e-30), b = dot(ac, seg) / dd;
    float q = b * b - (dot(ac, ac) - u_outer_r * u_outer_r) / dd;
    if (!(q > 0.0))
        return true;
    float t0 = max(0.0, -b - sqrt(q)), t1 = min(1.0, -b + sqrt(q));
    if (!(t1 > t0))
        return true;
    for (int s = 1; s <= LR_VIS_STEPS; s++) {
        vec3 p = mix(a, x, mix(t0, t1, float(s) / float(LR_VIS_STEPS + 1)));
        vec3 d = p - u_center;
        vec4 o = texture(u_outer_pos, d);
        vec3 od = o.xyz - u_center;
        if (o.w > 0.5 && dot(d, d) < dot(od, od))
            return false;
    }
    return true;
}

// Adds light l's E_vpl at x (unit normal nx) to E[l].
void lr_vpl_irradiance(vec3 x, vec3 nx, inout vec3 E[LR_MAX_LIGHTS])
{
    for (int v = 0; v < u_n_vpl; v++) {
        vec4 p = texelFetch(u_vpl_pos, ivec2(v, 0), 0);
        if (!(p.w > 0.0))
            continue;
        vec4 nv = texelFetch(u_vpl_nrm, ivec2(v, 0), 0);
        vec3 dv = x - p.xyz;
        float d2 = dot(dv, dv);
        vec3 w = dv * inversesqrt(max(d2, 1e-30));
        float cv = dot(nv.xyz, w);
        float cx = -dot(nx, w);
        if (!(cv > 0.0 && cx > 0.0))
            continue;
        if (u_vpl_vis && !lr_vpl_visible(p.xyz, nv.xyz, x))
            continue;
        int id = clamp(int(nv.w + 0.5), 0, LR_MAX_OBJECTS - 1);
        float eta = lr_material(id).eta;
        float g = lr_fresnel_transmittance(cv, eta) / LR_PI * p.w * cv * cx / max(d2, p.w);
        for (int l = 0; l < LR_MAX_LIGHTS; l++) {
            if (l >= u_n_lights)
                break;
            E[l] += g * u_cavity_gain[l * LR_MAX_OBJECTS + id] *
                    texelFetch(u_vpl_B, ivec2(v, l), 0).rgb;
        }
    }
}
