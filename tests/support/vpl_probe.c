/* lamprig tests — emergent light at receiver points from the renderer's VPLs (vpl_probe.h). */
#include "tests/support/vpl_probe.h"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "render/core/recv_grid.h"
#include "render/core/vpl.h"

void lr_test_vpl_irradiance(lr_renderer *r, const lr_scene *s, const lr_debug_vpl *v, int n,
                            lr_vec3 x, lr_vec3 nx, bool vis, double E[3])
{
    E[0] = E[1] = E[2] = 0.0;
    for (int i = 0; i < n; i++) {
        if (!v[i].valid)
            continue;
        lr_vpl_point c = {.valid = true, .x = v[i].pos, .n = v[i].nrm, .u = v[i].u,
                        .area = v[i].area};
        double gain[3];
        lr_renderer_debug_cavity_gain(r, v[i].object, gain);
        for (int b = 0; b < 3; b++)
            c.B[b] = v[i].B[b] * gain[b];
        lr_vpl_point_irradiance_vis(vis ? s : NULL, &c, 1,
                                  lr_scene_object_at(s, v[i].object)->coeffs.eta, x, nx, E, NULL);
    }
}

void lr_test_grid_irradiance(lr_renderer *r, const lr_scene *s, const lr_debug_vpl *v, int n,
                             const lr_receiver *rc, lr_vec3 x, bool vis, double E[3])
{
    lr_recv_grid_frame f;
    assert_true(lr_recv_grid_frame_of(rc, &f));
    int idx[4];
    double w[4];
    lr_recv_grid_taps(&f, x, idx, w);
    E[0] = E[1] = E[2] = 0.0;
    for (int q = 0; q < 4; q++) {
        double Eq[3];
        lr_vec3 p = lr_recv_grid_point(&f, idx[q] % LR_RECV_GRID, idx[q] / LR_RECV_GRID);
        lr_test_vpl_irradiance(r, s, v, n, p, rc->normal, vis, Eq);
        for (int c = 0; c < 3; c++)
            E[c] += w[q] * Eq[c];
    }
}
