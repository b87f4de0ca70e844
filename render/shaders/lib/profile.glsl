// A light's photometric profile (render/photometry/profile.h): rel, the intensity per direction
// over its largest, on the grid gamma 0..180 (LR_PROFILE_NG samples) x C 0..360
// (LR_PROFILE_NC), light l's planes in rows l * LR_PROFILE_NC .. of one R32F texture
// (render/passes/gbuffer.c). Bilinear by hand from texelFetch, as lr_light_profile_at does on
// the same floats: GLES 3.1 does not promise linear filtering of float textures.
#ifndef LR_PROFILE_GLSL
#define LR_PROFILE_GLSL

uniform highp sampler2D u_profiles;

// rel of light l's profile along local direction d (unit; z the nadir, x the C0 plane).
float lr_profile_rel(int l, vec3 d)
{
    float g = acos(clamp(d.z, -1.0, 1.0)) * (float(LR_PROFILE_NG - 1) / 3.14159265358979);
    // atan(0, 0) is undefined in GLSL: on the axis every C plane meets, take C0 (as the C side).
    float c = (d.x == 0.0 && d.y == 0.0) ? 0.0 : degrees(atan(d.y, d.x));
    if (c < 0.0)
        c += 360.0;
    c *= float(LR_PROFILE_NC - 1) / 360.0;
    int g0 = min(int(g), LR_PROFILE_NG - 2), c0 = min(int(c), LR_PROFILE_NC - 2);
    float fg = g - float(g0), fc = c - float(c0);
    int row = l * LR_PROFILE_NC + c0;
    float r00 = texelFetch(u_profiles, ivec2(g0, row), 0).r;
    float r01 = texelFetch(u_profiles, ivec2(g0 + 1, row), 0).r;
    float r10 = texelFetch(u_profiles, ivec2(g0, row + 1), 0).r;
    float r11 = texelFetch(u_profiles, ivec2(g0 + 1, row + 1), 0).r;
    float a = r00 + fg * (r01 - r00), b = r10 + fg * (r11 - r10);
    return a + fc * (b - a);
}

// The same along world direction w in the frame (x, y, z) = (C0, C90, nadir).
float lr_profile_rel_world(int l, vec3 w, vec3 x, vec3 y, vec3 z)
{
    return lr_profile_rel(l, vec3(dot(w, x), dot(w, y), dot(w, z)));
}

#endif
