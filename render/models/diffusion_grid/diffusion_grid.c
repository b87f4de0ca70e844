/* Seed 001: the diffusion equation solved on a grid inside the closed body (render/diffusion/),
 * not a BSSRDF: B is read from the solved field, on the GPU (lib/dgrid.glsl) and the CPU twin
 * alike. */
#include "render/models/diffusion_grid/diffusion_grid.h"

#include <math.h>
#include <stdio.h>

#include "render/diffusion/dscene.h"
#include "render/models/model.h"
#include "render/scene/scene.h"

static const char *limit(const lr_scene_object *o, char *buf, size_t cap)
{
    const lr_coeffs *c = &o->coeffs;
    double h = lr_dscene_spacing(o);
    double s = fmax(c->sigma_tr[0], fmax(c->sigma_tr[1], c->sigma_tr[2]));
    if (!(s * h <= LR_GRID_MAX_SIGMA_H)) {
        snprintf(buf, cap, "the grid spacing %.2g mm is %.2g diffusion lengths of the "
                 "material (sigma_tr %.3g /mm in its largest band; at most %g: the "
                 "stencil's decay rate is then %.0f %% low)",
                 h, s * h, s, LR_GRID_MAX_SIGMA_H,
                 100.0 * (1.0 - acosh(1.0 + 0.5 * s * h * s * h) / (s * h)));
        return buf;
    }
    /* A wall thinner than the spacing has cells with no interior node: the grid's boundary
     * ghosts have nothing to couple to (render/diffusion/system.c refuses it). */
    if (o->thickness_mm > 0.0 && o->thickness_mm < h) {
        snprintf(buf, cap, "the wall (%.3g mm) is thinner than the grid spacing %.3g mm",
                 o->thickness_mm, h);
        return buf;
    }
    return NULL;
}

const lr_model_ops lr_model_diffusion_grid = {
    .name = "diffusion_grid",
    .props = {.no_profile = true,
              .solves = "the diffusion equation is solved on the CPU grid",
              .needs_closed = "needs a closed mesh (the grid diffusion solves inside a solid "
                              "body)",
              .no_closure = "the grid closes the cavity in its own field "
                            "(render/diffusion/dscene.h: the gain measured from its solved B)",
              .grid_field = true},
    .limit = limit,
    .glsl_B = "lr_dgrid_B(xo)",
};
