/* lamprig — point-light irradiance over a patch (near_light.h). */
#include "render/optics/near_light.h"

#include <math.h>

double lr_solid_angle_triangle(lr_vec3 p, lr_vec3 a, lr_vec3 b, lr_vec3 c)
{
    lr_vec3 u = lr_v3_sub(a, p), v = lr_v3_sub(b, p), w = lr_v3_sub(c, p);
    double lu = lr_v3_len(u), lv = lr_v3_len(v), lw = lr_v3_len(w);
    /* (u x v) . w is the volume with the orientation of the triangle's normal when p is
     * behind it; seen from p on the normal's side it is negative, hence the sign. */
    double num = -lr_v3_dot(u, lr_v3_cross(v, w));
    double den = lu * lv * lw + lr_v3_dot(u, v) * lw + lr_v3_dot(u, w) * lv +
                 lr_v3_dot(v, w) * lu;
    return 2.0 * atan2(num, den);
}

void lr_near_light_frame(lr_vec3 n, lr_vec3 *t1, lr_vec3 *t2)
{
    /* Duff et al. 2017's branchless orthonormal basis. */
    double s = n.z >= 0.0 ? 1.0 : -1.0;
    double a = -1.0 / (s + n.z), b = n.x * n.y * a;
    *t1 = lr_v3(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    *t2 = lr_v3(b, s + n.y * n.y * a, -n.y);
}

double lr_solid_angle_square(lr_vec3 p, lr_vec3 c, lr_vec3 n, double side)
{
    lr_vec3 t1, t2;
    lr_near_light_frame(n, &t1, &t2);
    /* t1 x t2 = n, so the corners counter-clockwise about n. */
    lr_vec3 e1 = lr_v3_scale(t1, 0.5 * side), e2 = lr_v3_scale(t2, 0.5 * side);
    lr_vec3 q0 = lr_v3_sub(lr_v3_sub(c, e1), e2), q1 = lr_v3_sub(lr_v3_add(c, e1), e2);
    lr_vec3 q2 = lr_v3_add(lr_v3_add(c, e1), e2), q3 = lr_v3_add(lr_v3_sub(c, e1), e2);
    return lr_solid_angle_triangle(p, q0, q1, q2) + lr_solid_angle_triangle(p, q0, q2, q3);
}

double lr_patch_irradiance(lr_vec3 p, lr_vec3 c, lr_vec3 n, double side)
{
    if (!(side > 0.0)) {
        lr_vec3 d = lr_v3_sub(p, c);
        double r2 = lr_v3_dot(d, d);
        double cn = lr_v3_dot(n, d);
        return r2 > 0.0 && cn > 0.0 ? cn / (r2 * sqrt(r2)) : 0.0;
    }
    return fmax(0.0, lr_solid_angle_square(p, c, n, side)) / (side * side);
}
