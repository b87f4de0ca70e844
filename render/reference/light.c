/* Lights: emission profiles, sampling for next-event estimation and photon emission. */
#include "render/reference/ref_priv.h"

/* The spot profile: 1 inside the inner cone, 0 outside the outer one, and the smoothstep
 * 3x^2 - 2x^3 in cos theta between them (the profile the GLSL passes use too). */
static double spot_profile(const lr_ref_light *l, double c)
{
    if (c >= l->cos_inner)
        return 1.0;
    if (c <= l->cos_outer)
        return 0.0;
    double x = (c - l->cos_outer) / (l->cos_inner - l->cos_outer);
    return x * x * (3.0 - 2.0 * x);
}

/* rel of light l's profile along world direction w (the desc's frame). */
static double profile_rel(const lr_ref_light *l, lr_vec3 w)
{
    return lr_light_profile_eval(l->profile, lr_v3(lr_v3_dot(w, l->d.prof_x),
                                                   lr_v3_dot(w, l->d.prof_y),
                                                   lr_v3_dot(w, l->d.prof_z)));
}

double lr_ref_emitter_intensity(const lr_ref_emitter *em, lr_vec3 w, int b)
{
    const lr_ref_light *l = em->light;
    if (!l) {
        if (em->lambert)
            return em->power[b] * fmax(0.0, lr_v3_dot(em->n, w)) / LR_REF_PI;
        return em->power[b] * lr_ref_hg_eval(em->g, lr_v3_dot(em->d_in, w));
    }
    switch (l->d.kind) {
    case LR_REF_LIGHT_POINT:
        return l->d.emission[b] * (l->profile ? profile_rel(l, w) : 1.0);
    case LR_REF_LIGHT_SPOT: {
        double s = spot_profile(l, lr_v3_dot(w, l->normal));
        return l->d.emission[b] * (l->profile && s > 0.0 ? s * profile_rel(l, w) : s);
    }
    default: { /* Lambertian area element: I = L_e cos theta dA (a profile: L_e rel dA) */
        double c = lr_v3_dot(w, l->normal);
        if (c > 0.0 && l->profile)
            c = profile_rel(l, w);
        return c > 0.0 ? l->d.emission[b] * c * em->area_weight : 0.0;
    }
    }
}

/* Uniform point on an area light. */
static lr_vec3 area_point(const lr_ref_light *l, double u, double v)
{
    if (l->d.kind == LR_REF_LIGHT_QUAD)
        return lr_v3_add(l->d.position,
                         lr_v3_add(lr_v3_scale(l->d.edge1, u), lr_v3_scale(l->d.edge2, v)));
    double r = l->d.radius * sqrt(u), phi = 2.0 * LR_REF_PI * v;
    return lr_v3_add(l->d.position, lr_v3_add(lr_v3_scale(l->t1, r * cos(phi)),
                                              lr_v3_scale(l->t2, r * sin(phi))));
}

void lr_ref_light_sample(const lr_ref_scene *s, lr_ref_rng *rng, lr_ref_emitter *em,
                         double *pick)
{
    double u = lr_ref_rng_uniform(rng), acc = 0.0;
    int i = 0;
    for (; i < s->n_lights - 1; i++) {
        acc += s->light_pick[i];
        if (u < acc)
            break;
    }
    const lr_ref_light *l = &s->lights[i];
    *pick = s->light_pick[i];
    *em = (lr_ref_emitter){.light = l, .medium = l->medium, .area_weight = 1.0};
    em->p = l->d.position;
    if (l->object >= 0) {
        double a = lr_ref_rng_uniform(rng), b = lr_ref_rng_uniform(rng);
        em->p = area_point(l, a, b);
        em->area_weight = l->area;
    }
}

double lr_ref_light_power(const lr_ref_scene *s, int light, int band)
{
    return s->lights[light].power[band];
}

void lr_ref_light_emit_all(const lr_ref_light *l, lr_ref_rng *rng, lr_vec3 *origin,
                           lr_vec3 *dir, double power[3])
{
    double u1 = lr_ref_rng_uniform(rng), u2 = lr_ref_rng_uniform(rng);
    double phi = 2.0 * LR_REF_PI * u2;
    lr_vec3 axis = lr_v3(0.0, 0.0, 1.0);
    double c, k; /* power[b] = k * emission[b] */
    *origin = l->d.position;
    switch (l->d.kind) {
    case LR_REF_LIGHT_POINT: /* uniform on the sphere: power 4 pi I per photon */
        c = 1.0 - 2.0 * u1;
        k = 4.0 * LR_REF_PI;
        break;
    case LR_REF_LIGHT_SPOT: /* uniform in the outer cone, weighted by the profile */
        axis = l->normal;
        c = 1.0 - u1 * (1.0 - l->cos_outer);
        k = spot_profile(l, c) * 2.0 * LR_REF_PI * (1.0 - l->cos_outer);
        break;
    default: /* uniform point, cosine-weighted direction: each photon carries pi L_e A */
        axis = l->normal;
        *origin = area_point(l, lr_ref_rng_uniform(rng), lr_ref_rng_uniform(rng));
        c = sqrt(u1);
        k = LR_REF_PI * l->area;
        break;
    }
    if (l->profile) {
        /* By the profile's distribution (profile.h sampler), weight shape / pdf: a point's
         * rel, a spot's cone times rel, an area element's A rel (gamma < 90 only). */
        double pdf, u3 = lr_ref_rng_uniform(rng);
        lr_vec3 d = lr_profile_sample(l->sampler, u1, u2, u3, &pdf);
        *dir = lr_v3_normalize(lr_v3_add(lr_v3_scale(l->d.prof_x, d.x),
                                         lr_v3_add(lr_v3_scale(l->d.prof_y, d.y),
                                                   lr_v3_scale(l->d.prof_z, d.z))));
        double rel = profile_rel(l, *dir);
        if (l->d.kind == LR_REF_LIGHT_SPOT)
            rel *= spot_profile(l, lr_v3_dot(*dir, l->normal));
        else if (l->object >= 0)
            rel *= l->area;
        k = pdf > 0.0 ? rel / pdf : 0.0;
        for (int b = 0; b < 3; b++)
            power[b] = k * l->d.emission[b];
        return;
    }
    for (int b = 0; b < 3; b++)
        power[b] = k * l->d.emission[b];
    lr_vec3 t1, t2;
    lr_ref_frame(axis, &t1, &t2);
    double sn = sqrt(fmax(0.0, 1.0 - c * c));
    *dir = lr_v3_normalize(lr_v3_add(lr_v3_scale(axis, c),
                                     lr_v3_add(lr_v3_scale(t1, sn * cos(phi)),
                                               lr_v3_scale(t2, sn * sin(phi)))));
}

int lr_ref_light_emit(const lr_ref_scene *s, int light, int band, lr_ref_rng *rng,
                      lr_vec3 *origin, lr_vec3 *dir, double *power)
{
    double p[3];
    lr_ref_light_emit_all(&s->lights[light], rng, origin, dir, p);
    *power = p[band];
    return s->lights[light].medium;
}
