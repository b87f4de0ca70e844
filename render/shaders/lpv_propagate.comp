// lamprig — one light-propagation-volume step (seed 004 Sec. 4.4, Eq. 9-16, after Kaplanyan &
// Dachsbacher 2010), the GPU twin of render/lpv/propagate.c (read lpv.h for the energy scale,
// the blocking and the absorbed record). One invocation per destination cell d gathers from
// its six face neighbours s: the flux s sends through each of d's five far faces
// (Eq. 13: Phi_f = v_f . c_s), clamped at 0 and scaled so s never sends more than it holds,
// becomes the lobe (Phi_f / pi) max(0, n_f . w) in d (Eq. 16), times the transmittance
// 1 - min(1, B) of the interface s and d share; the blocked part is added to that interface's
// absorbed record. Each (interface, axis, direction) record is written by exactly one
// invocation, so the r32f image needs no atomics (GLES 3.1 has none for floats).
//
// Layouts (lpv.h): u_src / u_dst texel (3 i + ch, j, k) holds channel ch's 4 coefficients;
// u_block texel (i, j, k) holds B_x, B_y, B_z of interface (i, j, k); u_absorbed texel
// ((6 i + 2 a + s) * 3 + ch, j, k), s = 1 for travel toward -axis.

layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;

uniform highp sampler3D u_src;
uniform highp sampler3D u_block;
layout(rgba32f, binding = 0) writeonly uniform highp image3D u_dst;
layout(r32f, binding = 1) uniform highp image3D u_absorbed;
uniform int u_n;
uniform vec4 u_v[30];    // Eq. 14's transfer vectors, main direction m = 0..5 times 5 faces
uniform vec4 u_lobe[30]; // Eq. 16's lobes max(0, n_f . w) / pi

ivec3 dir_of(int m)
{
    ivec3 d = ivec3(0);
    d[m / 2] = (m % 2 == 1) ? -1 : 1;
    return d;
}

// min(1, Phi_s / sum_f max(0, v_f . c)): the source's clamped face fluxes within its flux.
float source_scale(vec4 c)
{
    float phi = c.x * 3.5449077018110318;
    if (!(phi > 0.0))
        return 0.0;
    float outf = 0.0;
    for (int f = 0; f < 30; f++)
        outf += max(0.0, dot(u_v[f], c));
    return outf > phi ? phi / outf : 1.0;
}

void main()
{
    ivec3 d = ivec3(gl_GlobalInvocationID);
    if (any(greaterThanEqual(d, ivec3(u_n))))
        return;
    vec4 outc[3];
    for (int ch = 0; ch < 3; ch++)
        outc[ch] = vec4(0.0);
    for (int m = 0; m < 6; m++) {
        ivec3 s = d - dir_of(m);
        if (any(lessThan(s, ivec3(0))) || any(greaterThanEqual(s, ivec3(u_n))))
            continue;
        int a = m / 2;
        ivec3 f = d;
        f[a] = max(s[a], d[a]);
        float tr = 1.0 - min(1.0, texelFetch(u_block, f, 0)[a]);
        for (int ch = 0; ch < 3; ch++) {
            vec4 c = texelFetch(u_src, ivec3(3 * s.x + ch, s.y, s.z), 0);
            float sc = source_scale(c);
            if (sc <= 0.0)
                continue;
            float sent = 0.0;
            for (int face = 0; face < 5; face++) {
                float phi = dot(u_v[m * 5 + face], c);
                if (phi <= 0.0)
                    continue;
                sent += sc * phi;
                outc[ch] += (tr * sc * phi) * u_lobe[m * 5 + face];
            }
            ivec3 at = ivec3((6 * f.x + 2 * a + (m % 2)) * 3 + ch, f.y, f.z);
            float prev = imageLoad(u_absorbed, at).x;
            imageStore(u_absorbed, at, vec4(prev + (1.0 - tr) * sent, 0.0, 0.0, 0.0));
        }
    }
    for (int ch = 0; ch < 3; ch++)
        imageStore(u_dst, ivec3(3 * d.x + ch, d.y, d.z), outc[ch]);
}
