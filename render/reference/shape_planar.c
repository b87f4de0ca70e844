/* Analytic planar shapes: parallelograms (quads) and disks, for receivers and area lights. */
#include "render/reference/ref_priv.h"

#include <stdlib.h>

typedef struct planar {
    bool disk;
    lr_vec3 p;      /* quad: corner; disk: centre */
    lr_vec3 e1, e2; /* quad edges */
    lr_vec3 n;      /* unit normal */
    double radius;  /* disk */
    /* quad: rows of the inverse of [e1 e2] restricted to the plane (u = dot(q, a1), ...) */
    lr_vec3 a1, a2;
} planar;

static bool planar_intersect(const void *self, lr_vec3 o, lr_vec3 d, double tmin, double tmax,
                             lr_ref_hit *hit)
{
    const planar *s = self;
    double dn = lr_v3_dot(d, s->n);
    if (dn == 0.0)
        return false;
    double t = lr_v3_dot(lr_v3_sub(s->p, o), s->n) / dn;
    if (!(t > tmin && t < tmax))
        return false;
    lr_vec3 q = lr_v3_sub(lr_v3_add(o, lr_v3_scale(d, t)), s->p);
    if (s->disk) {
        if (lr_v3_dot(q, q) > s->radius * s->radius)
            return false;
    } else {
        double u = lr_v3_dot(q, s->a1), v = lr_v3_dot(q, s->a2);
        if (u < 0.0 || u > 1.0 || v < 0.0 || v > 1.0)
            return false;
    }
    hit->t = t;
    hit->n = s->n;
    return true;
}

static void planar_hash(const void *self, lr_ref_hash *h)
{
    const planar *s = self;
    lr_ref_hash_str(h, s->disk ? "disk" : "quad");
    lr_ref_hash_vec3(h, s->p);
    lr_ref_hash_vec3(h, s->disk ? s->n : s->e1);
    lr_ref_hash_vec3(h, s->disk ? lr_v3(s->radius, 0, 0) : s->e2);
}

static const lr_ref_shape_ops planar_ops = {
    .name = "planar",
    .intersect = planar_intersect,
    .hash = planar_hash,
    .destroy = free,
    .closed = false,
};

int lr_ref_quad_create(lr_vec3 corner, lr_vec3 edge1, lr_vec3 edge2, lr_ref_shape **out,
                       lr_err *e)
{
    *out = NULL;
    lr_vec3 c = lr_v3_cross(edge1, edge2);
    double area = lr_v3_len(c);
    if (!lr_v3_isfinite(corner) || !lr_v3_isfinite(edge1) || !lr_v3_isfinite(edge2) ||
        !(area > 0.0))
        return lr_err_set(e, LR_EINVAL, "reference: quad edges must be finite and not parallel");
    planar *s = calloc(1, sizeof *s);
    if (!s)
        return lr_err_set(e, LR_ENOMEM, "reference: out of memory for a quad");
    s->p = corner;
    s->e1 = edge1;
    s->e2 = edge2;
    s->n = lr_v3_scale(c, 1.0 / area);
    /* Dual basis: a1 = (e2 x n) / (e1 . (e2 x n)), so dot(u e1 + v e2, a1) = u. */
    lr_vec3 b1 = lr_v3_cross(edge2, s->n), b2 = lr_v3_cross(s->n, edge1);
    s->a1 = lr_v3_scale(b1, 1.0 / lr_v3_dot(edge1, b1));
    s->a2 = lr_v3_scale(b2, 1.0 / lr_v3_dot(edge2, b2));
    return lr_ref_shape_create(&planar_ops, s, out, e);
}

int lr_ref_disk_create(lr_vec3 center, lr_vec3 normal, double radius, lr_ref_shape **out,
                       lr_err *e)
{
    *out = NULL;
    if (!lr_v3_isfinite(center) || !lr_v3_isfinite(normal) || !(lr_v3_len(normal) > 0.0) ||
        !isfinite(radius) || !(radius > 0.0))
        return lr_err_set(e, LR_EINVAL,
                          "reference: disk needs a finite centre, a non-zero normal and a "
                          "radius > 0 (got %g)", radius);
    planar *s = calloc(1, sizeof *s);
    if (!s)
        return lr_err_set(e, LR_ENOMEM, "reference: out of memory for a disk");
    s->disk = true;
    s->p = center;
    s->n = lr_v3_normalize(normal);
    s->radius = radius;
    return lr_ref_shape_create(&planar_ops, s, out, e);
}
