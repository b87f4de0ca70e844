// A point light's irradiance over a surface patch, not at a point: render/optics/near_light.h
// is the C version and the derivation (lr_patch_irradiance_far, the form a GPU estimator and
// its CPU twin share). Constants: LR_PATCH_FAR_LO / HI there.

// Signed solid angle of triangle (a, b, c) seen from p (Van Oosterom & Strackee).
float lr_solid_angle_triangle(vec3 p, vec3 a, vec3 b, vec3 c)
{
    vec3 u = a - p, v = b - p, w = c - p;
    float lu = length(u), lv = length(v), lw = length(w);
    float num = -dot(u, cross(v, w));
    float den = lu * lv * lw + dot(u, v) * lw + dot(u, w) * lv + dot(v, w) * lu;
    return 2.0 * atan(num, den);
}

// lr_near_light_frame: Duff et al. 2017's branchless orthonormal basis.
void lr_near_light_frame(vec3 n, out vec3 t1, out vec3 t2)
{
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z), b = n.x * n.y * a;
    t1 = vec3(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    t2 = vec3(b, s + n.y * n.y * a, -n.y);
}

// Mean over the square of side `side` about c (plane normal n) of a unit point light at p's
// irradiance, and its solid-angle-weighted mean cosine (lr_patch_irradiance).
float lr_patch_irradiance(vec3 p, vec3 c, vec3 n, float side, out float mean_cos)
{
    vec3 t1, t2;
    lr_near_light_frame(n, t1, t2);
    vec3 e1 = 0.5 * side * t1, e2 = 0.5 * side * t2;
    vec3 q[4];
    q[0] = c - e1 - e2;
    q[1] = c + e1 - e2;
    q[2] = c + e1 + e2;
    q[3] = c - e1 + e2;
    float om = lr_solid_angle_triangle(p, q[0], q[1], q[2]) +
               lr_solid_angle_triangle(p, q[0], q[2], q[3]);
    mean_cos = 0.0;
    if (!(om > 0.0))
        return 0.0;
    // Lambert's polygon formula: the projected solid angle.
    float phi = 0.0;
    for (int k = 0; k < 4; k++) {
        vec3 a = q[k] - p, b = q[(k + 1) & 3] - p;
        vec3 x = cross(a, b);
        float sx = length(x);
        if (sx > 0.0)
            phi += atan(sx, dot(a, b)) * dot(x, n) / sx;
    }
    mean_cos = clamp(0.5 * phi / om, 0.0, 1.0);
    return om / (side * side);
}

// lr_patch_irradiance_far: the patch mean near the light, the point sample cos / r^2 from 32
// sides on, smoothstep between (float's cancellation in the solid angle grows as r^2).
float lr_patch_irradiance_far(vec3 p, vec3 c, vec3 n, float side, out float mean_cos)
{
    vec3 d = p - c;
    float r = length(d), cn = dot(n, d);
    float mu0 = r > 0.0 && cn > 0.0 ? cn / r : 0.0;
    float E0 = mu0 > 0.0 ? mu0 / (r * r) : 0.0;
    float w = side > 0.0 ? smoothstep(16.0, 32.0, r / side) : 1.0;
    mean_cos = mu0;
    if (w >= 1.0)
        return E0;
    float mu1;
    float E1 = lr_patch_irradiance(p, c, n, side, mu1);
    mean_cos = mu1 + w * (mu0 - mu1);
    return E1 + w * (E0 - E1);
}
