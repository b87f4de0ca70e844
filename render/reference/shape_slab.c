/* Analytic slab top - thickness < z < top (infinite in x, y), or the half-space z < top: the
 * geometry of the published plane-parallel benchmarks. */
#include "render/reference/ref_priv.h"

#include <stdlib.h>

typedef struct slab {
    double top, bottom; /* bottom = -INFINITY for a half-space */
} slab;

static bool slab_intersect(const void *self, lr_vec3 o, lr_vec3 d, double tmin, double tmax,
                           lr_ref_hit *hit)
{
    const slab *s = self;
    if (d.z == 0.0)
        return false;
    double best = tmax;
    double nz = 0.0;
    double t = (s->top - o.z) / d.z;
    if (t > tmin && t < best) {
        best = t;
        nz = 1.0;
    }
    if (isfinite(s->bottom)) {
        t = (s->bottom - o.z) / d.z;
        if (t > tmin && t < best) {
            best = t;
            nz = -1.0;
        }
    }
    if (nz == 0.0)
        return false;
    hit->t = best;
    hit->n = lr_v3(0.0, 0.0, nz);
    return true;
}

static void slab_hash(const void *self, lr_ref_hash *h)
{
    const slab *s = self;
    lr_ref_hash_str(h, "slab");
    lr_ref_hash_double(h, s->top);
    lr_ref_hash_double(h, s->bottom);
}

static const lr_ref_shape_ops slab_ops = {
    .name = "slab",
    .intersect = slab_intersect,
    .hash = slab_hash,
    .destroy = free,
    .closed = true, /* closed at infinity: everything below top (and above bottom) is inside */
};

int lr_ref_slab_create(double top, double thickness, lr_ref_shape **out, lr_err *e)
{
    *out = NULL;
    if (!isfinite(top) || isnan(thickness) || thickness <= 0.0)
        return lr_err_set(e, LR_EINVAL,
                          "reference: slab top %g, thickness %g: need a finite top and a "
                          "thickness > 0 (INFINITY for a half-space)", top, thickness);
    slab *s = malloc(sizeof *s);
    if (!s)
        return lr_err_set(e, LR_ENOMEM, "reference: out of memory for a slab");
    s->top = top;
    s->bottom = isinf(thickness) ? -INFINITY : top - thickness;
    return lr_ref_shape_create(&slab_ops, s, out, e);
}
