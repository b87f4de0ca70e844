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

/* The square's corners, counter-clockwise about n (t1 x t2 = n). */
static void square_corners(lr_vec3 c, lr_vec3 n, double side, lr_vec3 q[4])
{
    lr_vec3 t1, t2;
    lr_near_light_frame(n, &t1, &t2);
    lr_vec3 e1 = lr_v3_scale(t1, 0.5 * side), e2 = lr_v3_scale(t2, 0.5 * side);
    q[0] = lr_v3_sub(lr_v3_sub(c, e1), e2);
    q[1] = lr_v3_sub(lr_v3_add(c, e1), e2);
    q[2] = lr_v3_add(lr_v3_add(c, e1), e2);
    q[3] = lr_v3_add(lr_v3_sub(c, e1), e2);
}

double lr_solid_angle_square(lr_vec3 p, lr_vec3 c, lr_vec3 n, double side)
{
    lr_vec3 q[4];
    square_corners(c, n, side, q);
    return lr_solid_angle_triangle(p, q[0], q[1], q[2]) +
           lr_solid_angle_triangle(p, q[0], q[2], q[3]);
}

double lr_projected_solid_angle_square(lr_vec3 p, lr_vec3 c, lr_vec3 n, double side)
{
    lr_vec3 q[4];
    square_corners(c, n, side, q);
    double sum = 0.0;
    for (int k = 0; k < 4; k++) {
        lr_vec3 a = lr_v3_sub(q[k], p), b = lr_v3_sub(q[(k + 1) & 3], p);
        lr_vec3 x = lr_v3_cross(a, b);
        double sx = lr_v3_len(x);
        if (!(sx > 0.0))
            continue; /* p on the edge's line: the edge subtends nothing */
        double beta = atan2(sx, lr_v3_dot(a, b));
        sum += beta * lr_v3_dot(x, n) / sx;
    }
    return 0.5 * sum;
}

double lr_projected_solid_angle_triangle(lr_vec3 p, lr_vec3 a, lr_vec3 b, lr_vec3 c, lr_vec3 n)
{
    lr_vec3 q[3] = {a, b, c};
    double sum = 0.0;
    for (int k = 0; k < 3; k++) {
        lr_vec3 u = lr_v3_sub(q[k], p), v = lr_v3_sub(q[(k + 1) % 3], p);
        lr_vec3 x = lr_v3_cross(u, v);
        double sx = lr_v3_len(x);
        if (!(sx > 0.0))
            continue; /* p on the edge's line: the edge subtends nothing */
        sum += atan2(sx, lr_v3_dot(u, v)) * lr_v3_dot(x, n) / sx;
    }
    return 0.5 * sum;
}

double lr_patch_irradiance(lr_vec3 p, lr_vec3 c, lr_vec3 n, double side, double *mean_cos)
{
    lr_vec3 d = lr_v3_sub(p, c);
    double r2 = lr_v3_dot(d, d), cn = lr_v3_dot(n, d);
    double mu = r2 > 0.0 && cn > 0.0 ? cn / sqrt(r2) : 0.0, E;
    if (!(side > 0.0)) {
        E = mu > 0.0 ? mu / r2 : 0.0;
    } else {
        double om = lr_solid_angle_square(p, c, n, side);
        E = fmax(0.0, om) / (side * side);
        if (om > 0.0)
            mu = fmin(1.0, fmax(0.0, lr_projected_solid_angle_square(p, c, n, side) / om));
    }
    if (mean_cos)
        *mean_cos = E > 0.0 ? mu : 0.0;
    return E;
}

double lr_patch_irradiance_far(lr_vec3 p, lr_vec3 c, lr_vec3 n, double side, double *mean_cos)
{
    lr_vec3 d = lr_v3_sub(p, c);
    double r = lr_v3_len(d);
    double t = side > 0.0 ? (r / side - LR_PATCH_FAR_LO) / (LR_PATCH_FAR_HI - LR_PATCH_FAR_LO)
                          : 1.0;
    t = fmin(1.0, fmax(0.0, t));
    double w = t * t * (3.0 - 2.0 * t); /* GLSL smoothstep's */
    double mu0 = 0.0, E0 = lr_patch_irradiance(p, c, n, 0.0, &mu0);
    if (w >= 1.0) {
        if (mean_cos)
            *mean_cos = mu0;
        return E0;
    }
    double mu1 = 0.0, E1 = lr_patch_irradiance(p, c, n, side, &mu1);
    if (mean_cos)
        *mean_cos = mu1 + w * (mu0 - mu1);
    return E1 + w * (E0 - E1);
}
