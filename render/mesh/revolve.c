/* Surfaces of revolution for the candle and the shade. */
#include "render/mesh/mesh_internal.h"

#include <math.h>
#include <stdlib.h>

double (*lr_mb_angles(int segments))[2]
{
    double (*cs)[2] = malloc((size_t)segments * sizeof *cs);
    if (!cs)
        return NULL;
    for (int j = 0; j < segments; j++) {
        double a = 2.0 * M_PI * j / segments;
        cs[j][0] = cos(a);
        cs[j][1] = sin(a);
    }
    return cs;
}

void lr_mb_revolve(lr_mesh_builder *b, const double (*cs)[2], int n, const double *rho,
                   const double *z, const double *nrho, const double *nz, int count)
{
    uint32_t prev = 0;
    bool prev_point = false;
    for (int k = 0; k < count; k++) {
        uint32_t first;
        bool point = rho[k] == 0.0;
        if (point) {
            first = lr_mb_vertex(b, lr_v3(0.0, 0.0, z[k]), lr_v3(0.0, 0.0, nz[k] < 0 ? -1.0 : 1.0));
        } else {
            double l = hypot(nrho[k], nz[k]);
            first = 0;
            for (int j = 0; j < n; j++) {
                lr_vec3 p = lr_v3(rho[k] * cs[j][0], rho[k] * cs[j][1], z[k]);
                lr_vec3 nn = lr_v3(nrho[k] / l * cs[j][0], nrho[k] / l * cs[j][1], nz[k] / l);
                uint32_t v = lr_mb_vertex(b, p, nn);
                if (j == 0)
                    first = v;
            }
        }
        if (k > 0) {
            for (int j = 0; j < n; j++) {
                int j1 = (j + 1) % n;
                /* A = (k-1, j), B = (k-1, j+1), C = (k, j+1), D = (k, j) */
                uint32_t A = prev_point ? prev : prev + (uint32_t)j;
                uint32_t B = prev_point ? prev : prev + (uint32_t)j1;
                uint32_t C = point ? first : first + (uint32_t)j1;
                uint32_t D = point ? first : first + (uint32_t)j;
                if (!prev_point)
                    lr_mb_triangle(b, A, B, C);
                if (!point)
                    lr_mb_triangle(b, A, C, D);
            }
        }
        prev = first;
        prev_point = point;
    }
}
