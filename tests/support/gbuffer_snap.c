/* lamprig tests — the light G-buffer's texels as lookups (gbuffer_snap.h). */
#include "tests/support/gbuffer_snap.h"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "render/base/mat4.h"

lr_vec3 lr_test_snap_lookup(void *p, lr_vec3 v)
{
    lr_test_snap *g = p;
    int face = 0;
    if (g->info.cube) {
        double ax = fabs(v.x), ay = fabs(v.y), az = fabs(v.z);
        if (ax >= ay && ax >= az)
            face = v.x > 0 ? 0 : 1;
        else if (ay >= az)
            face = v.y > 0 ? 2 : 3;
        else
            face = v.z > 0 ? 4 : 5;
    }
    lr_vec3 world = g->info.orthographic ? v : lr_v3_add(g->info.light_pos, v);
    const double *m = g->info.vp[face];
    double cx = m[0] * world.x + m[4] * world.y + m[8] * world.z + m[12];
    double cy = m[1] * world.x + m[5] * world.y + m[9] * world.z + m[13];
    double cz = m[2] * world.x + m[6] * world.y + m[10] * world.z + m[14];
    double cw = m[3] * world.x + m[7] * world.y + m[11] * world.z + m[15];
    if (!(cw > 0.0))
        return v;
    double nx = cx / cw, ny = cy / cw, nz = cz / cw;
    if (fabs(nx) > 1.0 || fabs(ny) > 1.0)
        return v;
    int S = g->info.size;
    int tx = (int)floor((nx * 0.5 + 0.5) * S), ty = (int)floor((ny * 0.5 + 0.5) * S);
    tx = tx < 0 ? 0 : tx >= S ? S - 1 : tx;
    ty = ty < 0 ? 0 : ty >= S ? S - 1 : ty;
    lr_vec3 c = lr_mat4_project(g->inv[face], lr_v3((tx + 0.5) / S * 2.0 - 1.0,
                                                    (ty + 0.5) / S * 2.0 - 1.0, nz));
    return g->info.orthographic ? c : lr_v3_sub(c, g->info.light_pos);
}

void lr_test_snap_init(lr_renderer *r, int light, lr_test_snap *g)
{
    lr_renderer_debug_light_gbuffer_info(r, light, &g->info);
    for (int f = 0; f < (g->info.cube ? 6 : 1); f++)
        assert_int_equal(lr_mat4_inverse(g->info.vp[f], g->inv[f]), 0);
}
