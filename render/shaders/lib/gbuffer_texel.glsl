// The texel of a 2D light G-buffer (pass 1) that holds lookup v: direction from the light at
// light_pos (LR_GB_PERSPECTIVE) or world point (LR_GB_ORTHO); vp the map's world ->
// clip, sz its size. False outside the map. Shared by gbuffer.glsl (one light) and lights.glsl
// (every light).
bool lr_gbuffer_texel(int mode, mat4 vp, vec3 light_pos, vec3 v, ivec2 sz, out ivec2 t)
{
    t = ivec2(0);
    vec4 clip = vp * vec4(mode == LR_GB_PERSPECTIVE ? light_pos + v : v, 1.0);
    if (!(clip.w > 0.0))
        return false;
    vec3 ndc = clip.xyz / clip.w;
    if (any(greaterThan(abs(ndc.xy), vec2(1.0))))
        return false;
    t = clamp(ivec2((ndc.xy * 0.5 + 0.5) * vec2(sz)), ivec2(0), sz - 1);
    return true;
}
