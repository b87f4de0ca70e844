/* The receiver irradiance grid (render/core/recv_grid.h). */
#include "render/core/recv_grid.h"

#include <math.h>

bool lr_recv_grid_frame_of(const lr_receiver *rc, lr_recv_grid_frame *f)
{
    if (rc->type != LR_RECEIVER_PLANE)
        return false;
    f->c = rc->center;
    f->a = lr_v3_normalize(rc->u_dir);
    f->b = lr_v3_normalize(lr_v3_cross(rc->normal, f->a));
    f->w = rc->size[0];
    f->h = rc->size[1];
    return f->w > 0.0 && f->h > 0.0;
}

lr_vec3 lr_recv_grid_point(const lr_recv_grid_frame *f, int s, int t)
{
    const double R = LR_RECV_GRID;
    double u = ((s + 0.5) / R - 0.5) * f->w, v = ((t + 0.5) / R - 0.5) * f->h;
    return lr_v3_add(f->c, lr_v3_add(lr_v3_scale(f->a, u), lr_v3_scale(f->b, v)));
}

static int clampi(int i)
{
    return i < 0 ? 0 : i >= LR_RECV_GRID ? LR_RECV_GRID - 1 : i;
}

void lr_recv_grid_taps(const lr_recv_grid_frame *f, lr_vec3 x, int idx[4], double w[4])
{
    const double R = LR_RECV_GRID;
    lr_vec3 d = lr_v3_sub(x, f->c);
    double fs = (lr_v3_dot(d, f->a) / f->w + 0.5) * R - 0.5;
    double ft = (lr_v3_dot(d, f->b) / f->h + 0.5) * R - 0.5;
    double s0 = floor(fs), t0 = floor(ft);
    double ws = fs - s0, wt = ft - t0;
    int is = (int)fmax(fmin(s0, R), -2.0), it = (int)fmax(fmin(t0, R), -2.0);
    for (int q = 0; q < 4; q++) {
        int os = q & 1, ot = q >> 1;
        idx[q] = clampi(is + os) + LR_RECV_GRID * clampi(it + ot);
        w[q] = (os ? ws : 1.0 - ws) * (ot ? wt : 1.0 - wt);
    }
}
