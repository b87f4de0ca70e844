#include "render/mesh/triangle.h"

bool lr_ray_triangle(lr_vec3 o, lr_vec3 d, lr_vec3 a, lr_vec3 b, lr_vec3 c, double tmin,
                     double tmax, double *t, double *u, double *v)
{
    lr_vec3 e1 = lr_v3_sub(b, a), e2 = lr_v3_sub(c, a);
    lr_vec3 p = lr_v3_cross(d, e2);
    double det = lr_v3_dot(e1, p);
    /* det == 0: the ray is parallel to the plane (or the triangle degenerate): no single
     * crossing point. Exactly zero, no epsilon: a scale-free test (mm or m). */
    if (det == 0.0)
        return false;
    double inv = 1.0 / det;
    lr_vec3 s = lr_v3_sub(o, a);
    double uu = lr_v3_dot(s, p) * inv;
    if (uu < -LR_RAY_TRIANGLE_EDGE_TOL || uu > 1.0 + LR_RAY_TRIANGLE_EDGE_TOL)
        return false;
    lr_vec3 q = lr_v3_cross(s, e1);
    double vv = lr_v3_dot(d, q) * inv;
    if (vv < -LR_RAY_TRIANGLE_EDGE_TOL || uu + vv > 1.0 + LR_RAY_TRIANGLE_EDGE_TOL)
        return false;
    double tt = lr_v3_dot(e2, q) * inv;
    if (!(tt >= tmin && tt <= tmax))
        return false;
    *t = tt;
    *u = uu;
    *v = vv;
    return true;
}

lr_vec3 lr_closest_on_segment(lr_vec3 p, lr_vec3 a, lr_vec3 b, double w[2])
{
    lr_vec3 ab = lr_v3_sub(b, a);
    double l2 = lr_v3_dot(ab, ab);
    double s = l2 > 0.0 ? lr_v3_dot(lr_v3_sub(p, a), ab) / l2 : 0.0;
    s = s < 0.0 ? 0.0 : s > 1.0 ? 1.0 : s;
    w[0] = 1.0 - s;
    w[1] = s;
    return lr_v3_add(a, lr_v3_scale(ab, s));
}

lr_vec3 lr_closest_on_triangle(lr_vec3 p, lr_vec3 a, lr_vec3 b, lr_vec3 c, double w[3])
{
    lr_vec3 ab = lr_v3_sub(b, a), ac = lr_v3_sub(c, a), ap = lr_v3_sub(p, a);
    double d1 = lr_v3_dot(ab, ap), d2 = lr_v3_dot(ac, ap);
    if (d1 <= 0.0 && d2 <= 0.0) {
        w[0] = 1.0; w[1] = 0.0; w[2] = 0.0;
        return a;
    }
    lr_vec3 bp = lr_v3_sub(p, b);
    double d3 = lr_v3_dot(ab, bp), d4 = lr_v3_dot(ac, bp);
    if (d3 >= 0.0 && d4 <= d3) {
        w[0] = 0.0; w[1] = 1.0; w[2] = 0.0;
        return b;
    }
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
        double v = d1 / (d1 - d3);
        w[0] = 1.0 - v; w[1] = v; w[2] = 0.0;
        return lr_v3_add(a, lr_v3_scale(ab, v));
    }
    lr_vec3 cp = lr_v3_sub(p, c);
    double d5 = lr_v3_dot(ab, cp), d6 = lr_v3_dot(ac, cp);
    if (d6 >= 0.0 && d5 <= d6) {
        w[0] = 0.0; w[1] = 0.0; w[2] = 1.0;
        return c;
    }
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
        double v = d2 / (d2 - d6);
        w[0] = 1.0 - v; w[1] = 0.0; w[2] = v;
        return lr_v3_add(a, lr_v3_scale(ac, v));
    }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
        double v = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        w[0] = 0.0; w[1] = 1.0 - v; w[2] = v;
        return lr_v3_add(b, lr_v3_scale(lr_v3_sub(c, b), v));
    }
    double den = va + vb + vc;
    if (!(den > 0.0)) {
        /* Degenerate (collinear) triangle: the best of its three edges. */
        double wab[2], wbc[2], wca[2];
        lr_vec3 qab = lr_closest_on_segment(p, a, b, wab);
        lr_vec3 qbc = lr_closest_on_segment(p, b, c, wbc);
        lr_vec3 qca = lr_closest_on_segment(p, c, a, wca);
        double dab = lr_v3_len(lr_v3_sub(p, qab)), dbc = lr_v3_len(lr_v3_sub(p, qbc)),
               dca = lr_v3_len(lr_v3_sub(p, qca));
        if (dab <= dbc && dab <= dca) {
            w[0] = wab[0]; w[1] = wab[1]; w[2] = 0.0;
            return qab;
        }
        if (dbc <= dca) {
            w[0] = 0.0; w[1] = wbc[0]; w[2] = wbc[1];
            return qbc;
        }
        w[0] = wca[1]; w[1] = 0.0; w[2] = wca[0];
        return qca;
    }
    double v = vb / den, ww = vc / den;
    w[0] = 1.0 - v - ww; w[1] = v; w[2] = ww;
    return lr_v3_add(a, lr_v3_add(lr_v3_scale(ab, v), lr_v3_scale(ac, ww)));
}
