/* The camera-path estimator: radiance along a ray by a random walk with next-event estimation.
 *
 * Path-space bookkeeping (Veach 1997, ch. 8, in the one-strategy-per-path form): every light
 * path is counted by exactly one of
 *   (a) next-event estimation from its last non-specular vertex (a diffuse receiver or a
 *       scattering event in a medium) to a point on a light, through the refractive
 *       interfaces the straight segment crosses (lr_ref_connect; up to LR_REF_MAX_CHAIN);
 *   (b) the walk hitting an area light, for paths (a) cannot produce: no non-specular vertex
 *       yet (camera -> [specular chain] -> light), a Fresnel reflection since the last one, a
 *       longer chain, or a chain whose interface sequence differs from the straight
 *       segment's (lr_ref_chain_topology).
 * Point and spot lights are reached by (a) only, since no walk can hit them.
 *
 * Inside media the walk samples free paths with the hero band's sigma_t and weights by the
 * single-scattering albedo at each collision (the walk is analogue in the hero band; the
 * other bands of its group have the same coefficients). At a boundary it chooses reflection
 * with the Fresnel probability and multiplies by (n_from / n_to)^2 on refraction (radiance,
 * not flux). */
#include "render/reference/ref_priv.h"

/* State of the last non-specular vertex, for deciding (b). */
typedef struct last_vertex {
    bool valid;   /* there is one and only refractions / null boundaries followed it */
    lr_vec3 x;
    int medium;
    int chain;    /* refractive interfaces since */
} last_vertex;

static double max3(const double v[3])
{
    return fmax(v[0], fmax(v[1], v[2]));
}

/* Next-event estimation at x; f converts the arriving flux density into outgoing radiance
 * (phase function value, or albedo / pi times the cosine). */
static void nee(const lr_ref_scene *s, lr_vec3 x, int medium, int mask, const double beta[3],
                lr_vec3 d, const lr_vec3 *receiver_n, const double *albedo, lr_ref_rng *rng,
                lr_ref_stats *st, double L[3])
{
    if (s->n_lights == 0)
        return;
    lr_ref_emitter em;
    double pick;
    lr_ref_light_sample(s, rng, &em, &pick);
    if (!(pick > 0.0))
        return;
    double E[3];
    lr_vec3 w_in;
    if (!lr_ref_connect(s, &em, x, medium, mask, rng, st, E, &w_in))
        return;
    double f;
    if (receiver_n) {
        double c = lr_v3_dot(w_in, *receiver_n);
        if (c <= 0.0)
            return; /* lit from behind: the receiver is opaque */
        f = c / LR_REF_PI;
    } else {
        /* Light travels along -w_in and leaves toward the camera along -d. */
        f = lr_ref_hg_eval(s->media[medium].g, lr_v3_dot(w_in, d));
    }
    for (int b = 0; b < 3; b++)
        if (mask & (1 << b))
            L[b] += beta[b] * f * (albedo ? albedo[b] : 1.0) * E[b] / pick;
}

/* True when NEE from v could have produced the path that just hit area-light point p. */
static bool nee_covers(const lr_ref_scene *s, const last_vertex *v, const lr_ref_light *l,
                       lr_vec3 p)
{
    if (!v->valid || v->chain > LR_REF_MAX_CHAIN)
        return false;
    lr_ref_topology t;
    lr_ref_chain_topology(s, p, l->medium, v->x, v->medium, &t);
    return t.k == v->chain;
}

/* Russian roulette on the path throughput; false when the path ends. */
static bool roulette(double beta[3], lr_ref_rng *rng)
{
    double m = max3(beta);
    if (m >= LR_REF_RR_THRESHOLD)
        return true;
    double q = m / LR_REF_RR_THRESHOLD;
    if (!(lr_ref_rng_uniform(rng) < q))
        return false;
    for (int b = 0; b < 3; b++)
        beta[b] /= q;
    return true;
}

static void trace_group(const lr_ref_scene *s, lr_vec3 origin, lr_vec3 dir, int medium,
                        int mask, int hero, lr_ref_rng *rng, lr_ref_stats *st, double L[3])
{
    double beta[3];
    for (int b = 0; b < 3; b++)
        beta[b] = (mask & (1 << b)) ? 1.0 : 0.0;
    lr_ref_walker w = {.x = origin, .d = dir, .medium = medium, .on_surface = true};
    last_vertex v = {.valid = false};
    st->paths++;
    for (int ev = 0;; ev++) {
        if (ev == LR_REF_MAX_EVENTS) {
            st->truncated++;
            return;
        }
        lr_ref_surf h;
        enum lr_ref_event e = lr_ref_flight(s, &w, hero, rng, &h);
        if (e == LR_REF_EV_ESCAPE)
            return;
        st->events++;
        if (e == LR_REF_EV_SCATTER) {
            const lr_ref_medium *m = &s->media[w.medium];
            for (int b = 0; b < 3; b++)
                beta[b] *= m->albedo[b];
            nee(s, w.x, w.medium, mask, beta, w.d, NULL, NULL, rng, st, L);
            w.d = lr_ref_hg_sample(m->g, w.d, lr_ref_rng_uniform(rng), lr_ref_rng_uniform(rng));
            v = (last_vertex){.valid = true, .x = w.x, .medium = w.medium, .chain = 0};
            if (!roulette(beta, rng))
                return;
            continue;
        }
        const lr_ref_object *ob = &s->objects[h.object];
        if (ob->kind == LR_REF_SURF_LIGHT) {
            const lr_ref_light *l = &s->lights[ob->light];
            if (lr_v3_dot(w.d, l->normal) < 0.0 && !nee_covers(s, &v, l, h.p))
                for (int b = 0; b < 3; b++)
                    L[b] += beta[b] * l->d.emission[b];
            return; /* lights are black bodies otherwise */
        }
        if (ob->kind == LR_REF_SURF_RECEIVER) {
            lr_vec3 nf = lr_v3_dot(w.d, h.n) < 0.0 ? h.n : lr_v3_scale(h.n, -1.0);
            nee(s, w.x, w.medium, mask, beta, w.d, &nf, ob->albedo, rng, st, L);
            for (int b = 0; b < 3; b++)
                beta[b] *= ob->albedo[b];
            w.d = lr_ref_cosine_sample(nf, lr_ref_rng_uniform(rng), lr_ref_rng_uniform(rng));
            v = (last_vertex){.valid = true, .x = w.x, .medium = w.medium, .chain = 0};
            if (!roulette(beta, rng))
                return;
            continue;
        }
        double n2;
        enum lr_ref_crossing c = lr_ref_cross(s, &w, &h, rng, &n2, st);
        if (c == LR_REF_REFLECT) {
            v.valid = false;
        } else if (c == LR_REF_REFRACT) {
            for (int b = 0; b < 3; b++)
                beta[b] *= n2;
            v.chain++;
        }
    }
}

void lr_ref_radiance(const lr_ref_scene *s, lr_vec3 origin, lr_vec3 dir, int medium,
                     lr_ref_rng *rng, lr_ref_stats *stats, double L[3])
{
    lr_ref_stats local = {0};
    lr_ref_stats *st = stats ? stats : &local;
    for (int g = 0; g < s->n_groups; g++)
        trace_group(s, origin, dir, medium, s->group_mask[g], s->group_hero[g], rng, st, L);
}
