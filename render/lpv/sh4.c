/* lamprig — two-band SH for the light-propagation volumes (see sh4.h). */
#include "render/lpv/sh4.h"

#include <math.h>

void lr_sh4_basis(lr_vec3 w, double y[4])
{
    y[0] = LR_SH4_K0;
    y[1] = LR_SH4_K1 * w.x;
    y[2] = LR_SH4_K1 * w.y;
    y[3] = LR_SH4_K1 * w.z;
}

double lr_sh4_eval(const double c[4], lr_vec3 w)
{
    return c[0] * LR_SH4_K0 + LR_SH4_K1 * (c[1] * w.x + c[2] * w.y + c[3] * w.z);
}

void lr_sh4_cosine_lobe(lr_vec3 n, double c[4])
{
    /* integral max(0, cos) k0 dw = pi k0 = sqrt(pi)/2; integral max(0, cos) k1 cos dw
     * = k1 2 pi / 3 = sqrt(pi / 3). */
    const double a0 = 0.88622692545275801; /* sqrt(pi) / 2 */
    const double a1 = 1.0233267079464885;  /* sqrt(pi / 3) */
    c[0] = a0;
    c[1] = a1 * n.x;
    c[2] = a1 * n.y;
    c[3] = a1 * n.z;
}

double lr_sh4_flux(const double c[4]) { return c[0] * 3.5449077018110318; /* sqrt(4 pi) */ }

double lr_sh4_cosine_integral(const double c[4], lr_vec3 d)
{
    return M_PI * LR_SH4_K0 * c[0] +
           (2.0 * M_PI / 3.0) * LR_SH4_K1 * (c[1] * d.x + c[2] * d.y + c[3] * d.z);
}

/* integral over the unit square face centred at `center` (cell units) with unit normal fn of
 * (w . a) dw, w the direction from the origin: the midpoint rule in dw = |fn.q| / |q|^3 dA. */
static double face_moment(lr_vec3 center, lr_vec3 fn, lr_vec3 t1, lr_vec3 t2, lr_vec3 a)
{
    const int m = 512;
    double s = 0.0;
    for (int i = 0; i < m; i++) {
        double u = (i + 0.5) / m - 0.5;
        for (int j = 0; j < m; j++) {
            double v = (j + 0.5) / m - 0.5;
            lr_vec3 q = lr_v3_add(center, lr_v3_add(lr_v3_scale(t1, u), lr_v3_scale(t2, v)));
            double d2 = lr_v3_dot(q, q), d = sqrt(d2);
            s += fabs(lr_v3_dot(fn, q)) / (d2 * d) * (lr_v3_dot(q, a) / d);
        }
    }
    return s / ((double)m * m);
}

void lr_sh4_face_moments(lr_sh4_faces *f)
{
    f->omega_front = 4.0 * asin(0.1);
    f->omega_side = (2.0 * M_PI / 3.0 - f->omega_front) / 4.0;
    lr_vec3 x = lr_v3(1, 0, 0), y = lr_v3(0, 1, 0), z = lr_v3(0, 0, 1);
    f->mz_front = face_moment(lr_v3(0, 0, 1.5), z, x, y, z);
    f->mz_side = face_moment(lr_v3(0.5, 0, 1), x, y, z, z);
    f->mx_side = face_moment(lr_v3(0.5, 0, 1), x, y, z, x);
}

void lr_sh4_face_transfer(const lr_sh4_faces *f, lr_vec3 main, lr_vec3 side, int is_side,
                          double v[4])
{
    lr_vec3 m = is_side ? lr_v3_add(lr_v3_scale(main, f->mz_side), lr_v3_scale(side, f->mx_side))
                        : lr_v3_scale(main, f->mz_front);
    v[0] = LR_SH4_K0 * (is_side ? f->omega_side : f->omega_front);
    v[1] = LR_SH4_K1 * m.x;
    v[2] = LR_SH4_K1 * m.y;
    v[3] = LR_SH4_K1 * m.z;
}
