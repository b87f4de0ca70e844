/* lamprig — the light-propagation volume's irradiance gather over interface values (lpv.h,
 * lr_lpv_face_gather): shared by the volume itself (lpv.c) and the objects' field
 * (objfield.c), so that the GPU's lib/lpv_object.glsl and both CPU readers agree. */
#include "render/lpv/lpv.h"

#include <math.h>

void lr_lpv_face_gather(int N, const double uu[3], lr_vec3 n, lr_lpv_face_fn face,
                        const void *ctx, double E[3])
{
    E[0] = E[1] = E[2] = 0.0;
    double nn[3] = {n.x, n.y, n.z};
    for (int a = 0; a < 3; a++) {
        if (nn[a] == 0.0)
            continue;
        int s = nn[a] > 0.0; /* light arriving at this side travels toward -axis */
        double ia = floor(uu[a] + 0.5);
        int b1 = (a + 1) % 3, b2 = (a + 2) % 3, i0[2];
        if (!(ia >= 0.0 && ia <= N) ||
            !(uu[b1] >= 0.0 && uu[b1] <= N && uu[b2] >= 0.0 && uu[b2] <= N))
            continue; /* beside the box */
        /* Bilinear over the interface plane between the cells' centres across. */
        double f[2];
        for (int q = 0; q < 2; q++) {
            double c = fmin(fmax(uu[q ? b2 : b1] - 0.5, 0.0), N - 1.0);
            i0[q] = (int)fmin(floor(c), N - 2.0);
            f[q] = c - i0[q];
        }
        double acc[3] = {0, 0, 0}, wsum = 0.0;
        for (int corner = 0; corner < 4; corner++) {
            int idx[3];
            idx[a] = (int)ia;
            idx[b1] = i0[0] + (corner & 1);
            idx[b2] = i0[1] + (corner >> 1);
            double w = ((corner & 1) ? f[0] : 1.0 - f[0]) * ((corner >> 1) ? f[1] : 1.0 - f[1]);
            double v[3];
            if (w <= 0.0 || !face(ctx, idx, a, s, v))
                continue;
            for (int ch = 0; ch < 3; ch++)
                acc[ch] += w * v[ch];
            wsum += w;
        }
        if (wsum > 0.0)
            for (int ch = 0; ch < 3; ch++)
                E[ch] += fabs(nn[a]) * acc[ch] / wsum;
    }
}
