/* Photons: the same transport steps run forward from a source, carrying flux. */
#include "render/reference/ref_priv.h"

void lr_ref_photon_walk(const lr_ref_scene *s, lr_ref_walker w, int mask, int hero,
                        lr_ref_rng *rng, lr_ref_stats *st, lr_ref_photon_visit visit,
                        void *user, lr_ref_photon_exit *out, double beta[3])
{
    lr_ref_photon_exit local;
    if (!out)
        out = &local;
    *out = (lr_ref_photon_exit){.position = w.x, .direction = w.d};
    lr_ref_photon_vertex v = {.beta = beta};
    for (int ev = 0;; ev++) {
        if (ev == LR_REF_MAX_EVENTS) {
            st->truncated++;
            break;
        }
        lr_ref_surf h;
        enum lr_ref_event e = lr_ref_flight(s, &w, hero, rng, &h, NULL);
        if (e == LR_REF_EV_ESCAPE) {
            out->escaped = true;
            out->direction = w.d;
            return;
        }
        st->events++;
        const double *albedo;
        if (e == LR_REF_EV_SURFACE) {
            const lr_ref_object *ob = &s->objects[h.object];
            if (ob->kind == LR_REF_SURF_LIGHT) { /* lights absorb */
                out->hit_light = true;
                out->direction = w.d;
                return;
            }
            if (ob->kind == LR_REF_SURF_BOUNDARY) {
                out->position = h.p;
                out->boundaries++;
                double n2; /* flux crosses unscaled */
                enum lr_ref_crossing c = lr_ref_cross(s, &w, &h, rng, &n2, st);
                if (v.index == 0) {
                    v.reflected = v.reflected || c == LR_REF_REFLECT;
                    v.refractions += c == LR_REF_REFRACT;
                }
                continue;
            }
            v.receiver = ob;
            v.n = lr_v3_dot(w.d, h.n) < 0.0 ? h.n : lr_v3_scale(h.n, -1.0);
            albedo = ob->albedo;
        } else {
            v.receiver = NULL;
            albedo = s->media[w.medium].albedo;
        }
        v.x = w.x;
        v.medium = w.medium;
        v.d_in = w.d;
        if (visit && !visit(user, &v))
            return;
        v.index++;
        for (int b = 0; b < 3; b++)
            beta[b] *= albedo[b];
        if (v.receiver) {
            out->receiver_hits++;
            w.d = lr_ref_cosine_sample(v.n, lr_ref_rng_uniform(rng), lr_ref_rng_uniform(rng));
        } else {
            out->scatterings++;
            w.d = lr_ref_hg_sample(s->media[w.medium].g, w.d, lr_ref_rng_uniform(rng),
                                   lr_ref_rng_uniform(rng));
        }
        /* Russian roulette (unbiased): below the threshold survive with probability m / t at
         * throughput scaled by t / m (MCML's scheme, Wang, Jacques, Zheng 1995, Sec. 3.8). */
        double m = lr_ref_max3(beta);
        if (m < LR_REF_RR_THRESHOLD) {
            if (!(lr_ref_rng_uniform(rng) * LR_REF_RR_THRESHOLD < m))
                break;
            for (int b = 0; b < 3; b++)
                beta[b] *= LR_REF_RR_THRESHOLD / m;
        }
    }
    for (int b = 0; b < 3; b++)
        beta[b] = 0.0; /* absorbed, roulette or capped: nothing leaves */
}

void lr_ref_photon_trace(const lr_ref_scene *s, lr_vec3 origin, lr_vec3 dir, int medium,
                         int band, lr_ref_rng *rng, lr_ref_stats *stats,
                         lr_ref_photon_exit *out)
{
    lr_ref_stats local = {0};
    double beta[3] = {0.0, 0.0, 0.0};
    beta[band] = 1.0;
    lr_ref_walker w = {.x = origin, .d = dir, .medium = medium, .on_surface = true};
    lr_ref_stats *st = stats ? stats : &local;
    st->paths++;
    lr_ref_photon_walk(s, w, 1 << band, band, rng, st, NULL, NULL, out, beta);
    out->weight = beta[band];
}
