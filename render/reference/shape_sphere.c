/* Analytic sphere. */
#include "render/reference/ref_priv.h"

#include <stdlib.h>

typedef struct sphere {
    lr_vec3 c;
    double r;
} sphere;

static bool sphere_intersect(const void *self, lr_vec3 o, lr_vec3 d, double tmin, double tmax,
                             lr_ref_hit *hit)
{
    const sphere *s = self;
    lr_vec3 oc = lr_v3_sub(o, s->c);
    double b = lr_v3_dot(oc, d);
    /* |oc|^2 - r^2 as (|oc| - r)(|oc| + r): accurate for origins on the surface, where the
     * small root must come out as ~0 and not as a cancellation residue. */
    double len = lr_v3_len(oc);
    double c = (len - s->r) * (len + s->r);
    double disc = b * b - c;
    if (disc < 0.0)
        return false;
    /* Numerically stable roots (Press et al., Numerical Recipes, 5.6): q = -(b + sign(b) sqrt). */
    double sq = sqrt(disc);
    double q = b >= 0.0 ? -(b + sq) : -(b - sq);
    double t0 = q, t1 = q != 0.0 ? c / q : 0.0;
    if (t0 > t1) {
        double t = t0;
        t0 = t1;
        t1 = t;
    }
    double t = t0 > tmin ? t0 : t1;
    if (!(t > tmin && t < tmax))
        return false;
    hit->t = t;
    hit->n = lr_v3_normalize(lr_v3_sub(lr_v3_add(o, lr_v3_scale(d, t)), s->c));
    return true;
}

static void sphere_hash(const void *self, lr_ref_hash *h)
{
    const sphere *s = self;
    lr_ref_hash_str(h, "sphere");
    lr_ref_hash_vec3(h, s->c);
    lr_ref_hash_double(h, s->r);
}

static const lr_ref_shape_ops sphere_ops = {
    .name = "sphere",
    .intersect = sphere_intersect,
    .hash = sphere_hash,
    .destroy = free,
    .closed = true,
};

int lr_ref_sphere_create(lr_vec3 center, double radius, lr_ref_shape **out, lr_err *e)
{
    *out = NULL;
    if (!lr_v3_isfinite(center) || !isfinite(radius) || radius <= 0.0)
        return lr_err_set(e, LR_EINVAL, "reference: sphere radius %g: must be finite and > 0",
                          radius);
    sphere *s = malloc(sizeof *s);
    if (!s)
        return lr_err_set(e, LR_ENOMEM, "reference: out of memory for a sphere");
    s->c = center;
    s->r = radius;
    return lr_ref_shape_create(&sphere_ops, s, out, e);
}
