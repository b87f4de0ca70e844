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
 *       segment's (lr_ref_chain_topology);
 *   (c) in renders, light tracing (lighttrace.c) for point and spot lights whose light meets
 *       a Fresnel reflection before its first non-specular vertex, which (a) cannot connect
 *       and no walk can hit.
 *
 * Inside media the walk samples free paths with the hero band's sigma_t and weights by the
 * single-scattering albedo at each collision (the walk is analogue in the hero band; the
 * other bands of its group have the same coefficients). At a boundary it chooses reflection
 * with the Fresnel probability and multiplies by (n_from / n_to)^2 on refraction (radiance,
 * not flux).
 *
 * A point or spot light inside a scattering medium (a light embedded in the material): NEE
 * from free-flight collisions alone has infinite variance there (the 1/d^2 of the connection
 * is not square-integrable over the volume around the light). Each flight segment in such a
 * medium therefore also takes one equiangular sample toward the light (Kulla & Fajardo 2012,
 * "Importance sampling techniques for path tracing in participating media", Sec. 4), and the
 * two distance strategies are combined with the balance heuristic (Veach & Guibas 1995), so
 * both stay unbiased and the singularity is cancelled by the equiangular density. */
#include "render/reference/ref_priv.h"

/* State of the last non-specular vertex, for deciding (b). */
typedef struct last_vertex {
    bool valid;   /* there is one and only refractions / null boundaries followed it */
    lr_vec3 x;
    int medium;
    int chain;    /* refractive interfaces since */
} last_vertex;

/* A free-flight segment in a medium: where the walk left from, and how far the next surface
 * is. */
typedef struct segment {
    lr_vec3 x0, d;
    double len;
    int medium;
    double sigma_t; /* hero band */
} segment;

/* Whether the equiangular strategy applies to light l on this segment. */
static bool eq_applies(const lr_ref_scene *s, const segment *sg, const lr_ref_light *l, int hero)
{
    return (l->d.kind == LR_REF_LIGHT_POINT || l->d.kind == LR_REF_LIGHT_SPOT) &&
           l->medium == sg->medium && s->media[sg->medium].sigma_s[hero] > 0.0 &&
           isfinite(sg->len);
}

/* Equiangular sampling of t in [0, len] for a point p: with delta the ray parameter closest to
 * p and D the distance there, t = delta + D tan(theta), theta uniform in [ta, tb], has density
 * D / ((tb - ta) (D^2 + (t - delta)^2)) (Kulla & Fajardo 2012, Eq. 6-7). */
typedef struct equiangular {
    double delta, D, ta, tb;
} equiangular;

static bool eq_setup(const segment *sg, lr_vec3 p, equiangular *q)
{
    lr_vec3 v = lr_v3_sub(p, sg->x0);
    q->delta = lr_v3_dot(v, sg->d);
    q->D = lr_v3_len(lr_v3_sub(v, lr_v3_scale(sg->d, q->delta)));
    if (!(q->D > 1e-12 * (1.0 + lr_v3_len(v))))
        return false; /* the ray runs through the light: a set of measure zero */
    q->ta = atan2(-q->delta, q->D);
    q->tb = atan2(sg->len - q->delta, q->D);
    return q->tb > q->ta;
}

static double eq_pdf(const equiangular *q, double t)
{
    double y = t - q->delta;
    return q->D / ((q->tb - q->ta) * (q->D * q->D + y * y));
}

/* Density of a free-flight collision at t (hero band). */
static double ff_pdf(const segment *sg, double t)
{
    return sg->sigma_t * exp(-sg->sigma_t * t);
}

/* Next-event estimation at x; f converts the arriving flux density into outgoing radiance
 * (phase function value, or albedo / pi times the cosine). sg: the segment whose free-flight
 * collision x is (medium vertices), for the MIS weight against equiangular sampling. */
static void nee(const lr_ref_scene *s, lr_vec3 x, int medium, int mask, int hero,
                const double beta[3], lr_vec3 d, const lr_vec3 *receiver_n, const double *albedo,
                const segment *sg, lr_ref_rng *rng, lr_ref_stats *st, double L[3])
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
    equiangular q;
    if (sg && eq_applies(s, sg, em.light, hero) && eq_setup(sg, em.p, &q)) {
        double t = lr_v3_dot(lr_v3_sub(x, sg->x0), sg->d), pf = ff_pdf(sg, t);
        f *= pf / (pf + eq_pdf(&q, t)); /* balance heuristic */
    }
    for (int b = 0; b < 3; b++)
        if (mask & (1 << b))
            L[b] += beta[b] * f * (albedo ? albedo[b] : 1.0) * E[b] / pick;
}

/* The equiangular half of the MIS pair: one distance on the segment sampled toward a light
 * embedded in its medium. beta is the throughput at the segment's start. */
static void nee_equiangular(const lr_ref_scene *s, const segment *sg, int mask, int hero,
                            const double beta[3], lr_ref_rng *rng, lr_ref_stats *st,
                            double L[3])
{
    lr_ref_emitter em;
    double pick;
    lr_ref_light_sample(s, rng, &em, &pick);
    double u = lr_ref_rng_uniform(rng);
    equiangular q;
    if (!(pick > 0.0) || !eq_applies(s, sg, em.light, hero) || !eq_setup(sg, em.p, &q))
        return;
    double t = q.delta + q.D * tan(q.ta + u * (q.tb - q.ta));
    if (!(t > 0.0 && t < sg->len))
        return;
    lr_vec3 x = lr_v3_add(sg->x0, lr_v3_scale(sg->d, t));
    double E[3];
    lr_vec3 w_in;
    if (!lr_ref_connect(s, &em, x, sg->medium, mask, NULL, st, E, &w_in))
        return;
    const lr_ref_medium *m = &s->media[sg->medium];
    double f = lr_ref_hg_eval(m->g, lr_v3_dot(w_in, sg->d)) / (pick * (eq_pdf(&q, t) + ff_pdf(sg, t)));
    for (int b = 0; b < 3; b++)
        if (mask & (1 << b))
            L[b] += beta[b] * exp(-m->sigma_t[b] * t) * m->sigma_s[b] * f * E[b];
}

/* Whether some point or spot light sits in medium m (which then needs equiangular samples). */
static bool has_embedded_light(const lr_ref_scene *s, int m)
{
    for (int i = 0; i < s->n_lights; i++)
        if (s->lights[i].medium == m && (s->lights[i].d.kind == LR_REF_LIGHT_POINT ||
                                         s->lights[i].d.kind == LR_REF_LIGHT_SPOT))
            return true;
    return false;
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
    double m = lr_ref_max3(beta);
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
        segment sg = {.x0 = w.x, .d = w.d, .medium = w.medium,
                      .sigma_t = s->media[w.medium].sigma_t[hero]};
        bool eq = s->media[w.medium].sigma_s[hero] > 0.0 && has_embedded_light(s, w.medium);
        enum lr_ref_event e = lr_ref_flight(s, &w, hero, rng, &h, eq ? &sg.len : NULL);
        if (eq)
            nee_equiangular(s, &sg, mask, hero, beta, rng, st, L);
        if (e == LR_REF_EV_ESCAPE)
            return;
        st->events++;
        if (e == LR_REF_EV_SCATTER) {
            const lr_ref_medium *m = &s->media[w.medium];
            for (int b = 0; b < 3; b++)
                beta[b] *= m->albedo[b];
            nee(s, w.x, w.medium, mask, hero, beta, w.d, NULL, NULL, eq ? &sg : NULL, rng, st, L);
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
            nee(s, w.x, w.medium, mask, hero, beta, w.d, &nf, ob->albedo, NULL, rng, st, L);
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
