/* lamprig — the thinnest wall of a closed mesh (see wall.h). */
#include "render/mesh/wall.h"

#include <math.h>
#include <stdlib.h>

typedef struct wall_sample {
    double t, area;
} wall_sample;

static int by_thickness(const void *a, const void *b)
{
    double x = ((const wall_sample *)a)->t, y = ((const wall_sample *)b)->t;
    return (x > y) - (x < y);
}

double lr_mesh_wall_thickness(const lr_bvh *b)
{
    const lr_mesh *m = lr_bvh_mesh(b);
    const size_t nt = lr_mesh_triangle_count(m);
    wall_sample *s = malloc((nt ? nt : 1) * sizeof *s);
    if (!s)
        return 0.0;
    lr_vec3 lo, hi;
    lr_mesh_bounds(m, &lo, &hi);
    /* Self-hits at the start: a step of a millionth of the body's size is far below any
     * wall and far above the triangle test's rounding. */
    const double eps = 1e-6 * lr_v3_len(lr_v3_sub(hi, lo));
    size_t n = 0;
    double total = 0.0;
    for (size_t k = 0; k < nt; k++) {
        lr_vec3 p[3];
        lr_mesh_triangle(m, k, p);
        lr_vec3 c = lr_v3_scale(lr_v3_add(lr_v3_add(p[0], p[1]), p[2]), 1.0 / 3.0);
        lr_vec3 inward = lr_v3_scale(lr_mesh_triangle_normal(m, k), -1.0);
        lr_hit h;
        if (!lr_bvh_intersect(b, c, inward, eps, INFINITY, &h))
            continue;
        s[n].t = h.t;
        s[n].area = lr_mesh_triangle_area(m, k);
        total += s[n++].area;
    }
    double wall = 0.0;
    if (n) {
        qsort(s, n, sizeof *s, by_thickness);
        double want = total * LR_MESH_WALL_PERCENTILE / 100.0, acc = 0.0;
        size_t k = 0;
        while (k + 1 < n && (acc += s[k].area) < want)
            k++;
        wall = s[k].t;
    }
    free(s);
    return wall;
}
