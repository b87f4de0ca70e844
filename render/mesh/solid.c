/* Inside and around: winding numbers and distance to the convex hull, which decide whether a
 * light is surrounded by an object (cube-map G-buffer and stereographic correction). */
#include "render/mesh/mesh_internal.h"

#include <math.h>

#include "render/mesh/triangle.h"

double lr_mesh_winding_number(const lr_mesh *m, lr_vec3 p)
{
    double sum = 0.0;
    for (size_t t = 0; t < m->nt; t++) {
        lr_vec3 q[3];
        lr_mesh_triangle(m, t, q);
        lr_vec3 a = lr_v3_sub(q[0], p), b = lr_v3_sub(q[1], p), c = lr_v3_sub(q[2], p);
        double la = lr_v3_len(a), lb = lr_v3_len(b), lc = lr_v3_len(c);
        double num = lr_v3_dot(a, lr_v3_cross(b, c));
        double den = la * lb * lc + lr_v3_dot(a, b) * lc + lr_v3_dot(a, c) * lb +
                     lr_v3_dot(b, c) * la;
        /* Van Oosterom & Strackee: tan(Omega / 2) = num / den. On the surface both vanish
         * and the triangle contributes nothing (atan2(0, 0) = 0). */
        sum += 2.0 * atan2(num, den);
    }
    return sum / (4.0 * M_PI);
}

/* Closest point of the simplex s[0..*n) to the origin; keeps in s only the points it needs
 * (those with non-zero weight). Returns the closest point; *inside when a tetrahedron
 * contains the origin. */
static lr_vec3 simplex_closest(lr_vec3 s[4], int *n, bool *inside)
{
    lr_vec3 o = lr_v3(0, 0, 0);
    *inside = false;
    if (*n == 1)
        return s[0];
    if (*n == 2) {
        double w[2];
        lr_vec3 x = lr_closest_on_segment(o, s[0], s[1], w);
        int k = 0;
        lr_vec3 keep[2];
        for (int i = 0; i < 2; i++)
            if (w[i] > 0.0)
                keep[k++] = s[i];
        for (int i = 0; i < k; i++)
            s[i] = keep[i];
        *n = k;
        return x;
    }
    if (*n == 3) {
        double w[3];
        lr_vec3 x = lr_closest_on_triangle(o, s[0], s[1], s[2], w);
        int k = 0;
        lr_vec3 keep[3];
        for (int i = 0; i < 3; i++)
            if (w[i] > 0.0)
                keep[k++] = s[i];
        for (int i = 0; i < k; i++)
            s[i] = keep[i];
        *n = k;
        return x;
    }
    /* Tetrahedron: inside when the origin is on the inner side of all four faces. */
    static const int face[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
    double vol = lr_v3_dot(lr_v3_sub(s[1], s[0]),
                           lr_v3_cross(lr_v3_sub(s[2], s[0]), lr_v3_sub(s[3], s[0])));
    if (vol != 0.0) {
        bool in = true;
        for (int f = 0; f < 4 && in; f++) {
            lr_vec3 a = s[face[f][0]], b = s[face[f][1]], c = s[face[f][2]];
            /* Sign of the origin against face f, relative to the opposite vertex f. */
            double so = lr_v3_dot(lr_v3_scale(a, -1.0), lr_v3_cross(lr_v3_sub(b, a),
                                                                   lr_v3_sub(c, a)));
            double sv = lr_v3_dot(lr_v3_sub(s[f], a), lr_v3_cross(lr_v3_sub(b, a),
                                                                 lr_v3_sub(c, a)));
            in = (so >= 0.0) == (sv >= 0.0) || so == 0.0;
        }
        if (in) {
            *inside = true;
            return o;
        }
    }
    double best = INFINITY;
    lr_vec3 bx = s[0], keep[3];
    int bk = 1;
    keep[0] = s[0];
    for (int f = 0; f < 4; f++) {
        double w[3];
        lr_vec3 a = s[face[f][0]], b = s[face[f][1]], c = s[face[f][2]];
        lr_vec3 x = lr_closest_on_triangle(o, a, b, c, w);
        double d = lr_v3_len(x);
        if (d < best) {
            best = d;
            bx = x;
            bk = 0;
            lr_vec3 abc[3] = {a, b, c};
            for (int i = 0; i < 3; i++)
                if (w[i] > 0.0)
                    keep[bk++] = abc[i];
        }
    }
    for (int i = 0; i < bk; i++)
        s[i] = keep[i];
    *n = bk;
    return bx;
}

double lr_mesh_hull_distance(const lr_mesh *m, lr_vec3 p)
{
    double scale = 0.0;
    for (size_t v = 0; v < m->nv; v++)
        scale = fmax(scale, lr_v3_len(lr_v3_sub(lr_mesh_vertex(m, v), p)));
    double tol = 1e-12 * scale;
    lr_vec3 s[4] = {lr_v3_sub(lr_mesh_vertex(m, 0), p)};
    int n = 1;
    lr_vec3 x = s[0];
    for (int iter = 0; iter < 200; iter++) {
        double xx = lr_v3_dot(x, x);
        if (sqrt(xx) <= tol)
            return 0.0;
        /* Support point: the vertex farthest along -x. */
        lr_vec3 w = lr_v3_sub(lr_mesh_vertex(m, 0), p);
        double best = lr_v3_dot(x, w);
        for (size_t v = 1; v < m->nv; v++) {
            lr_vec3 q = lr_v3_sub(lr_mesh_vertex(m, v), p);
            double d = lr_v3_dot(x, q);
            if (d < best) {
                best = d;
                w = q;
            }
        }
        /* No vertex lies beyond the plane through x normal to x by more than rounding: x is
         * the closest point (the GJK termination test, relative to |x|^2). */
        if (xx - best <= 1e-12 * xx)
            return sqrt(xx);
        for (int i = 0; i < n; i++)
            if (s[i].x == w.x && s[i].y == w.y && s[i].z == w.z)
                return sqrt(xx);
        s[n++] = w;
        bool inside;
        x = simplex_closest(s, &n, &inside);
        if (inside)
            return 0.0;
    }
    return lr_v3_len(x);
}
