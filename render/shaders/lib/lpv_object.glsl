// The light-propagation volume's irradiance on the objects (render/lpv/objfield.h; issue 14
// item 2): per light l at unit intensity, the irradiance E(x, n) the receivers' volumes
// deliver to the surface, read exactly as lr_lpv_objfield_eval does (per axis the interface
// nearest x, bilinear across between cell centres over the covered interfaces, weighted by
// |n_a|), and the scattered radiosity it gives, B_ind = kR E(x, n) + kT E(x, -n): E times the
// profile's total diffuse reflectance (and, through a thin wall, transmittance) and the mean
// entry Fresnel factor, with the image's scale (render/passes/lpv_pass.c sets them per object).
// Composition adds F_t(w_o) B_ind / pi like the maps' B (seed 003 Eq. 5).
uniform bool u_lpv_obj_on;
uniform highp sampler2DArray u_lpv_obj; // light l: layers l (n+1) + k, texel (i, j + (2a+s)(n+1))
uniform int u_lpv_obj_n;                // cells per axis
uniform int u_lpv_obj_lights;           // lights with a field
uniform vec3 u_lpv_obj_origin;
uniform float u_lpv_obj_h;
uniform vec3 u_lpv_obj_r[LR_MAX_LIGHTS]; // kR of this object, per light (times the image scale)
uniform vec3 u_lpv_obj_t[LR_MAX_LIGHTS]; // kT

vec3 lr_lpv_obj_E(int l, vec3 x, vec3 nrm)
{
    int N = u_lpv_obj_n, N1 = u_lpv_obj_n + 1;
    float fN = float(N);
    vec3 u = (x - u_lpv_obj_origin) / u_lpv_obj_h;
    vec3 E = vec3(0.0);
    for (int a = 0; a < 3; a++) {
        if (nrm[a] == 0.0)
            continue;
        int s = nrm[a] > 0.0 ? 1 : 0; // light arriving at this side travels toward -axis
        int b1 = (a + 1) % 3, b2 = (a + 2) % 3;
        float ia = floor(u[a] + 0.5);
        if (!(ia >= 0.0 && ia <= fN) || !(u[b1] >= 0.0 && u[b1] <= fN) ||
            !(u[b2] >= 0.0 && u[b2] <= fN))
            continue;
        vec2 c = clamp(vec2(u[b1], u[b2]) - 0.5, 0.0, fN - 1.0);
        vec2 c0 = min(floor(c), vec2(fN - 2.0));
        vec2 f = c - c0;
        ivec2 i0 = ivec2(c0);
        vec3 acc = vec3(0.0);
        float wsum = 0.0;
        for (int corner = 0; corner < 4; corner++) {
            ivec3 idx;
            idx[a] = int(ia);
            idx[b1] = i0.x + (corner & 1);
            idx[b2] = i0.y + (corner >> 1);
            float w = ((corner & 1) != 0 ? f.x : 1.0 - f.x) * ((corner >> 1) != 0 ? f.y : 1.0 - f.y);
            vec4 t = texelFetch(u_lpv_obj, ivec3(idx.x, idx.y + (2 * a + s) * N1, l * N1 + idx.z), 0);
            if (t.a > 0.0 && w > 0.0) {
                acc += w * t.rgb;
                wsum += w;
            }
        }
        if (wsum > 0.0)
            E += abs(nrm[a]) * acc / wsum;
    }
    return E;
}

vec3 lr_lpv_obj_B(int l, vec3 x, vec3 nrm)
{
    if (!u_lpv_obj_on || l >= u_lpv_obj_lights)
        return vec3(0.0);
    vec3 B = u_lpv_obj_r[l] * lr_lpv_obj_E(l, x, nrm);
    if (any(greaterThan(u_lpv_obj_t[l], vec3(0.0))))
        B += u_lpv_obj_t[l] * lr_lpv_obj_E(l, x, -nrm);
    return B;
}
