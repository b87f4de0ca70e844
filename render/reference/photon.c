/* Photons: the same transport steps run forward from a source, carrying flux. */
#include "render/reference/ref_priv.h"

void lr_ref_photon_trace(const lr_ref_scene *s, lr_vec3 origin, lr_vec3 dir, int medium,
                         int band, lr_ref_rng *rng, lr_ref_stats *stats,
                         lr_ref_photon_exit *out)
{
    lr_ref_stats local = {0};
    lr_ref_stats *st = stats ? stats : &local;
    *out = (lr_ref_photon_exit){.position = origin, .direction = dir, .weight = 1.0};
    lr_ref_walker w = {.x = origin, .d = dir, .medium = medium, .on_surface = true};
    st->paths++;
    for (int ev = 0;; ev++) {
        if (ev == LR_REF_MAX_EVENTS) {
            st->truncated++;
            out->weight = 0.0;
            return;
        }
        lr_ref_surf h;
        enum lr_ref_event e = lr_ref_flight(s, &w, band, rng, &h);
        if (e == LR_REF_EV_ESCAPE) {
            out->escaped = true;
            out->direction = w.d;
            return;
        }
        st->events++;
        if (e == LR_REF_EV_SURFACE) {
            const lr_ref_object *ob = &s->objects[h.object];
            out->position = h.p;
            if (ob->kind == LR_REF_SURF_LIGHT) { /* lights absorb */
                out->weight = 0.0;
                return;
            }
            if (ob->kind == LR_REF_SURF_BOUNDARY) {
                double n2; /* flux crosses unscaled */
                lr_ref_cross(s, &w, &h, rng, &n2, st);
                continue;
            }
            lr_vec3 nf = lr_v3_dot(w.d, h.n) < 0.0 ? h.n : lr_v3_scale(h.n, -1.0);
            out->weight *= ob->albedo[band];
            out->receiver_hits++;
            w.d = lr_ref_cosine_sample(nf, lr_ref_rng_uniform(rng), lr_ref_rng_uniform(rng));
        } else {
            const lr_ref_medium *m = &s->media[w.medium];
            out->weight *= m->albedo[band];
            out->scatterings++;
            w.d = lr_ref_hg_sample(m->g, w.d, lr_ref_rng_uniform(rng), lr_ref_rng_uniform(rng));
        }
        /* Russian roulette (unbiased): below the threshold survive with probability w / t at
         * weight t (MCML's scheme, Wang, Jacques, Zheng 1995, Sec. 3.8). */
        if (out->weight < LR_REF_RR_THRESHOLD) {
            if (!(lr_ref_rng_uniform(rng) * LR_REF_RR_THRESHOLD < out->weight)) {
                out->weight = 0.0;
                return;
            }
            out->weight = LR_REF_RR_THRESHOLD;
        }
    }
}
