// Seed 001's grid diffusion (render/diffusion/): the solved surface radiosity field of the
// object being drawn for the current light, B per band per unit intensity at the grid's nodes
// (render/diffusion/field.c), one array layer per z slice, light l's slices from u_dg_layer0.
// A point's B is the trilinear blend of its cell's corners renormalised over the corners that
// hold a value (.w = 1): the same arithmetic as lr_dfield_eval, the CPU twin.
uniform highp sampler2DArray u_dg_field;
uniform vec3 u_dg_origin;
uniform float u_dg_h;
uniform ivec3 u_dg_dims;
uniform int u_dg_layer0;

vec3 lr_dgrid_B(vec3 p)
{
    vec3 f = (p - u_dg_origin) / u_dg_h;
    ivec3 c0;
    vec3 t;
    for (int a = 0; a < 3; a++) {
        if (u_dg_dims[a] == 1) {
            c0[a] = 0;
            t[a] = 0.0;
        } else {
            c0[a] = int(clamp(floor(f[a]), 0.0, float(u_dg_dims[a] - 2)));
            t[a] = clamp(f[a] - float(c0[a]), 0.0, 1.0);
        }
    }
    vec3 acc = vec3(0.0);
    float wsum = 0.0;
    for (int k = 0; k < 2; k++)
        for (int j = 0; j < 2; j++)
            for (int i = 0; i < 2; i++) {
                ivec3 c = min(c0 + ivec3(i, j, k), u_dg_dims - 1);
                float w = (i == 1 ? t.x : 1.0 - t.x) * (j == 1 ? t.y : 1.0 - t.y) *
                          (k == 1 ? t.z : 1.0 - t.z);
                vec4 v = texelFetch(u_dg_field, ivec3(c.x, c.y, u_dg_layer0 + c.z), 0);
                w *= v.w;
                wsum += w;
                acc += w * v.xyz;
            }
    return wsum > 1e-6 ? acc / wsum : vec3(0.0);
}
