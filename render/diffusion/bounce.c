/* lamprig — the first bounce of an object's own light across its cavity (bounce.h). */
#include "render/diffusion/bounce.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "render/core/ray.h"
#include "render/optics/optics.h"

/* A turn in [0, 1) from b's coordinates, so neighbouring points do not share one pattern. */
static double turn_of(lr_vec3 b)
{
    uint64_t h = 1469598103934665603ull;
    const double v[3] = {b.x, b.y, b.z};
    for (int i = 0; i < 3; i++) {
        uint64_t u;
        memcpy(&u, &v[i], sizeof u);
        h = (h ^ u) * 1099511628211ull;
        h ^= h >> 29;
    }
    return (double)(h >> 11) * (1.0 / 9007199254740992.0);
}

void lr_dbounce_q(const void *ctx, lr_vec3 b, lr_vec3 n, double q[3])
{
    const lr_dbounce *k = ctx;
    const lr_scene_object *obj = k->obj;
    const double eta = obj->material.medium.eta, eps = 1e-5 * fmax(obj->radius, 1.0);
    q[0] = q[1] = q[2] = 0.0;
    const int s = (int)sqrt((double)(k->rays > 1 ? k->rays : 1));
    lr_vec3 t1, t2;
    lr_tangents(n, &t1, &t2);
    const lr_vec3 o = lr_v3_add(b, lr_v3_scale(n, eps));
    const double turn = turn_of(b);
    for (int i = 0; i < s; i++)
        for (int j = 0; j < s; j++) {
            /* Stratified (i, j) cell centres, cosine-distributed (Malley). */
            double u1 = (i + 0.5) / s, u2 = fmod((j + 0.5) / s + turn, 1.0);
            double r = sqrt(u1), ph = 2.0 * M_PI * u2, z = sqrt(fmax(0.0, 1.0 - u1));
            lr_vec3 d = lr_v3_add(lr_v3_scale(n, z), lr_v3_add(lr_v3_scale(t1, r * cos(ph)),
                                                            lr_v3_scale(t2, r * sin(ph))));
            lr_vec3 y, ny;
            if (!(z > 0.0) || !lr_first_surface(obj, o, d, eps, &y, &ny))
                continue;
            double cy = -lr_v3_dot(ny, d);
            if (!(cy > 0.0))
                continue; /* the back of a surface: no light leaves towards b */
            double B[3];
            lr_dfield_eval(k->field.data, k->field.n, k->field.origin, k->field.h, y, B);
            double w = lr_fresnel_transmittance(z, eta) * lr_fresnel_transmittance(cy, eta);
            for (int c = 0; c < 3; c++)
                q[c] += w * B[c];
        }
    for (int c = 0; c < 3; c++)
        q[c] /= (double)s * s;
}
