/* The transport steps every estimator shares: free flight to the next collision or surface,
 * and the smooth dielectric boundary. Camera paths and photons call exactly these. */
#include "render/reference/ref_priv.h"

#include "render/optics/optics.h"

enum lr_ref_event lr_ref_flight(const lr_ref_scene *s, lr_ref_walker *w, int hero,
                                lr_ref_rng *rng, lr_ref_surf *hit, double *segment)
{
    double st = s->media[w->medium].sigma_t[hero];
    /* Free path with density st exp(-st t) (inversion; 1 - u lies in (0, 1], so the log is
     * finite). A transparent medium never collides. */
    double tc = st > 0.0 ? -log(1.0 - lr_ref_rng_uniform(rng)) / st : INFINITY;
    double tmin = w->on_surface ? lr_ref_eps(w->x) : 0.0;
    /* The whole segment to the next surface when the caller wants its length (equiangular
     * sampling needs it), else only as far as the collision. */
    bool found = lr_ref_scene_intersect(s, w->x, w->d, tmin, segment ? INFINITY : tc, hit);
    if (segment)
        *segment = found ? hit->t : INFINITY;
    if (found && hit->t < tc) {
        w->x = hit->p;
        w->on_surface = true;
        return LR_REF_EV_SURFACE;
    }
    if (isinf(tc))
        return LR_REF_EV_ESCAPE;
    w->x = lr_v3_add(w->x, lr_v3_scale(w->d, tc));
    w->on_surface = false;
    return LR_REF_EV_SCATTER;
}

enum lr_ref_crossing lr_ref_cross(const lr_ref_scene *s, lr_ref_walker *w,
                                  const lr_ref_surf *hit, lr_ref_rng *rng, double *n_ratio2,
                                  lr_ref_stats *st)
{
    const lr_ref_object *ob = &s->objects[hit->object];
    bool front = lr_v3_dot(w->d, hit->n) < 0.0;
    int from = front ? ob->outside : ob->inside;
    int to = front ? ob->inside : ob->outside;
    /* The geometry decides: a walker that disagrees (a ray that slipped through a seam of a
     * mesh, say) continues as if it had come from the right side, and is counted. */
    if (from != w->medium && st)
        st->medium_mismatch++;
    *n_ratio2 = 1.0;
    double n1 = s->media[from].eta, n2 = s->media[to].eta;
    if (n1 == n2) { /* index-matched: a null boundary */
        w->medium = to;
        return LR_REF_PASS;
    }
    lr_vec3 nf = front ? hit->n : lr_v3_scale(hit->n, -1.0); /* faces the incident side */
    double cos_i = -lr_v3_dot(w->d, nf);
    /* Exact unpolarised Fresnel reflectance (render/optics; eta = n_transmitted / n_incident),
     * 1 under total internal reflection. Choosing the branch with probability R keeps the
     * weight unchanged (R / R, T / T). */
    double R = lr_fresnel_reflectance(cos_i, n2 / n1);
    lr_vec3 t;
    if (lr_ref_rng_uniform(rng) < R || !lr_ref_refract(w->d, nf, n1 / n2, &t)) {
        w->d = lr_v3_normalize(lr_ref_reflect(w->d, nf));
        w->medium = from;
        return LR_REF_REFLECT;
    }
    w->d = t;
    w->medium = to;
    /* Radiance over n^2 is invariant across a smooth interface (e.g. Veach 1997, Sec. 5.2):
     * radiance seen from the `from` side is (n_from / n_to)^2 times that on the `to` side. */
    *n_ratio2 = (n1 / n2) * (n1 / n2);
    return LR_REF_REFRACT;
}
