/* The surface cache's refinement, shared by the GPU pass and the CPU twin
 * (render/core/surface.h). */
#include "render/core/surface.h"

#include <math.h>

#include "render/mesh/lattice.h"

double lr_surface_edge_bound(const lr_scene *s, int object, int map_size)
{
    (void)object;
    lr_vec3 c;
    double R;
    lr_scene_bounds(s, &c, &R);
    /* The per-pixel gather it stands in for resolves nothing finer than a map texel (bilinear
     * taps); B's own scale, the diffusion length, only sets the error of the linear fit
     * (PIPELINE.md "Surface cache"). */
    double h = LR_SURFACE_EDGE_TEXELS * 2.0 * R / (map_size > 0 ? map_size : 1);
    return h > 1e-3 ? h : 1e-3;
}

int lr_surface_refine(const lr_scene *s, int object, int map_size, size_t budget,
                      lr_refined *out, double *h, lr_err *e)
{
    const lr_scene_object *o = lr_scene_object_at(s, object);
    *h = lr_surface_edge_bound(s, object, map_size);
    for (int tries = 0;; tries++) {
        lr_err e2 = {0};
        int rc = lr_refine_lattice(o->mesh, *h, budget > 0 ? budget : 1, out, &e2);
        if (rc != LR_EUNSUPPORTED || tries > 40) {
            if (rc && e)
                *e = e2;
            return rc;
        }
        *h *= 2.0;
    }
}
