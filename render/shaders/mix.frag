// The mix pass (render/passes/mix.h): one layer of the per-light images as a per-band
// weighted geometric mean of the same layer of up to six image arrays, for an interpolated
// state of the control-space cache (render/async/cache.h): out = exp(sum_k a_k ln in_k) / d
// with the weights a_k summing to 1 per band and d the sets' scales (u_lnd = ln d). A texel
// that is 0 in a set of non-zero weight stays 0. Unused sets have weight 0 and repeat set 0.
uniform highp sampler2DArray u_set0, u_set1, u_set2, u_set3, u_set4, u_set5;
uniform int u_layer;
uniform vec3 u_a[6];
uniform vec3 u_lnd;
layout(location = 0) out vec4 o_color;

// a ln(v), with 0 for a = 0 (whatever v) and -inf-like for v <= 0.
vec3 term(vec3 a, vec3 v)
{
    return mix(a * log(max(v, vec3(1e-37))), vec3(0.0), equal(a, vec3(0.0)));
}

void main()
{
    ivec3 p = ivec3(ivec2(gl_FragCoord.xy), u_layer);
    vec4 s0 = texelFetch(u_set0, p, 0);
    vec3 l = term(u_a[0], s0.rgb);
    l += term(u_a[1], texelFetch(u_set1, p, 0).rgb);
    l += term(u_a[2], texelFetch(u_set2, p, 0).rgb);
    l += term(u_a[3], texelFetch(u_set3, p, 0).rgb);
    l += term(u_a[4], texelFetch(u_set4, p, 0).rgb);
    l += term(u_a[5], texelFetch(u_set5, p, 0).rgb);
    // Below ln(1e-30): a zero in a set (1e-37 floor) weighs it down to 0.
    vec3 c = mix(exp(l - u_lnd), vec3(0.0), lessThan(l, vec3(-69.0)));
    // Alpha is coverage (compose_object.frag): the same in every state of one view.
    o_color = vec4(c, s0.a);
}
