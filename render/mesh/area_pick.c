/* lamprig — picking points uniformly by area over a mesh (area_pick.h). */
#include "render/mesh/area_pick.h"

size_t lr_cdf_pick(const double *cdf, size_t n, double u)
{
    size_t lo = 0, hi = n - 1;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (cdf[mid] > u)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

lr_vec3 lr_triangle_fold_point(const lr_vec3 v[3], double s, double t)
{
    if (s + t > 1.0) {
        s = 1.0 - s;
        t = 1.0 - t;
    }
    return lr_v3_add(v[0], lr_v3_add(lr_v3_scale(lr_v3_sub(v[1], v[0]), s),
                                     lr_v3_scale(lr_v3_sub(v[2], v[0]), t)));
}
