#include "tests/support/mesh_quad.h"

#include <math.h>

void lrt_mesh_quadrature(const lr_mesh *m, double max_edge, lrt_mesh_point_fn f, void *user)
{
    for (size_t t = 0; t < lr_mesh_triangle_count(m); t++) {
        lr_vec3 p[3];
        lr_mesh_triangle(m, t, p);
        lr_vec3 e1 = lr_v3_sub(p[1], p[0]), e2 = lr_v3_sub(p[2], p[0]);
        lr_vec3 n = lr_mesh_triangle_normal(m, t);
        double L = fmax(lr_v3_len(e1), fmax(lr_v3_len(e2), lr_v3_len(lr_v3_sub(p[2], p[1]))));
        int R = (int)ceil(L / max_edge);
        double dA = lr_mesh_triangle_area(m, t) / ((double)R * R);
        for (int j = 0; j < R; j++)
            for (int i = 0; i + j < R; i++)
                for (int up = 0; up < 2 && (up == 0 || i + j + 1 < R); up++) {
                    /* lower (i, j), (i+1, j), (i, j+1); upper (i+1, j), (i+1, j+1), (i, j+1) */
                    double u = up ? (i + 2.0 / 3.0) / R : (i + 1.0 / 3.0) / R;
                    double w = up ? (j + 2.0 / 3.0) / R : (j + 1.0 / 3.0) / R;
                    lr_vec3 x = lr_v3_add(p[0], lr_v3_add(lr_v3_scale(e1, u), lr_v3_scale(e2, w)));
                    f(user, t, u, w, x, n, dA);
                }
    }
}
