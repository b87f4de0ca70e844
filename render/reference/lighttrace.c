/* Light tracing: the paths camera paths cannot find.
 *
 * Camera-path NEE connects a vertex to a light through refractions only. A point or spot
 * light whose light first meets a Fresnel *reflection* (the 4 % mirrored by the wax surface
 * onto the wall, the light a shade reflects back across its cavity into its far side) reaches
 * the first scattering vertex along a path no camera walk can hit and no refraction chain
 * describes. Those paths are traced from the light instead (Veach 1997, ch. 10: the "t = 1"
 * strategy of bidirectional path tracing, connecting to the camera): photons leave the point
 * and spot lights, and when the path from the light to their first non-specular vertex is
 * *not* one NEE covers (lr_ref_nee_covers_light_end), every non-specular vertex of the walk is
 * connected to the pinhole through the refractions between them (lr_ref_connect, the same
 * solver, with the vertex as the emitter), and splatted into the pixel it lands in. Photons
 * whose light end NEE covers stop at their first vertex: each path is counted once, by one
 * strategy. A path with a reflection at both ends (seen in the wax as a mirror image AND lit
 * by a mirrored light) is counted by neither; it carries a product of two Fresnel
 * reflectances (~0.2 % at normal incidence) and is listed in render/reference/README.md as a known
 * omission.
 *
 * The pinhole measurement: the camera averages radiance over the pixel's area on an image
 * plane at distance 1; a point source of flux density E across the beam, seen at angle theta
 * from the axis, adds E / (A_pixel cos^3 theta) to that average (dw = cos^3 theta dA_plane).
 */
#include "render/reference/ref_priv.h"

#include <stdlib.h>

void lr_ref_pinhole_init(lr_ref_pinhole *p, const lr_ref_camera *cam, int width, int height,
                         int medium)
{
    double th = tan(0.5 * cam->fov_y_deg * LR_REF_PI / 180.0);
    p->c = cam->position;
    p->f = lr_v3_normalize(lr_v3_sub(cam->look_at, cam->position));
    p->r = lr_v3_normalize(lr_v3_cross(p->f, cam->up));
    p->u = lr_v3_cross(p->r, p->f);
    p->ty = th;
    p->tx = th * (double)width / (double)height;
    p->width = width;
    p->height = height;
    p->medium = medium;
}

long lr_ref_pinhole_pixel(const lr_ref_pinhole *p, lr_vec3 w, double *cos3)
{
    double z = lr_v3_dot(w, p->f);
    if (!(z > 0.0))
        return -1;
    double sx = lr_v3_dot(w, p->r) / (z * p->tx), sy = lr_v3_dot(w, p->u) / (z * p->ty);
    double px = 0.5 * (sx + 1.0) * p->width, py = 0.5 * (1.0 - sy) * p->height;
    if (!(px >= 0.0 && px < p->width && py >= 0.0 && py < p->height))
        return -1;
    *cos3 = z * z * z;
    return (long)py * p->width + (long)px;
}

bool lr_ref_nee_covers_light_end(const lr_ref_scene *s, lr_vec3 p, int mp,
                                 const lr_ref_photon_vertex *v)
{
    if (v->reflected || v->refractions > LR_REF_MAX_CHAIN)
        return false;
    lr_ref_topology t;
    lr_ref_chain_topology(s, p, mp, v->x, v->medium, &t);
    return t.k == v->refractions;
}

typedef struct tracer {
    const lr_ref_scene *s;
    const lr_ref_pinhole *cam;
    lr_vec3 light_p;
    int light_medium;
    int mask;
    double power[3]; /* flux the photon carried at emission, per band (/ pick probability) */
    double a_pix;
    lr_ref_rng *rng;
    lr_ref_stats *st;
    lr_ref_splats *out;
} tracer;

static void push(lr_ref_splats *o, long pixel, const double rgb[3])
{
    if (o->n == o->cap) {
        size_t nc = o->cap ? 2 * o->cap : 256;
        lr_ref_splat *v = realloc(o->v, nc * sizeof *v);
        if (!v) {
            o->oom = true;
            return;
        }
        o->v = v;
        o->cap = nc;
    }
    o->v[o->n++] = (lr_ref_splat){pixel, {rgb[0], rgb[1], rgb[2]}};
}

static bool visit(void *user, const lr_ref_photon_vertex *v)
{
    tracer *t = user;
    if (v->index == 0 && lr_ref_nee_covers_light_end(t->s, t->light_p, t->light_medium, v))
        return false; /* camera paths count this one */
    /* The vertex re-emits what it scatters: flux times albedo, with its phase function (or
     * Lambert's law) as the angular distribution. */
    lr_ref_emitter em = {.p = v->x, .medium = v->medium, .area_weight = 1.0, .d_in = v->d_in,
                         .n = v->n, .lambert = v->receiver != NULL};
    const double *albedo = v->receiver ? v->receiver->albedo : t->s->media[v->medium].albedo;
    em.g = t->s->media[v->medium].g;
    for (int b = 0; b < 3; b++)
        em.power[b] = t->power[b] * v->beta[b] * albedo[b];
    double E[3];
    lr_vec3 w_in;
    if (lr_ref_connect(t->s, &em, t->cam->c, t->cam->medium, t->mask, t->rng, t->st, E, &w_in)) {
        double cos3;
        long pix = lr_ref_pinhole_pixel(t->cam, w_in, &cos3);
        if (pix >= 0) {
            double rgb[3] = {0, 0, 0};
            for (int b = 0; b < 3; b++)
                if (t->mask & (1 << b))
                    rgb[b] = E[b] / (t->a_pix * cos3);
            push(t->out, pix, rgb);
        }
    }
    return true;
}

void lr_ref_light_trace(const lr_ref_scene *s, const lr_ref_pinhole *cam, uint64_t seed,
                        uint64_t j, uint64_t first, uint64_t count, lr_ref_splats *out,
                        lr_ref_stats *st)
{
    tracer t = {.s = s, .cam = cam, .st = st, .out = out};
    t.a_pix = (2.0 * cam->tx / cam->width) * (2.0 * cam->ty / cam->height);
    for (uint64_t i = first; i < first + count; i++) {
        lr_ref_rng rng;
        /* Streams apart from the camera paths' (another seed), keyed by (sample, photon). */
        lr_ref_rng_seed(&rng, lr_ref_mix64(seed ^ 0x6c69676874747261ULL), (j << 32) | i);
        t.rng = &rng;
        double u = lr_ref_rng_uniform(&rng), acc = 0.0;
        int li = -1;
        for (int k = 0; k < s->n_lights; k++) {
            if (s->delta_pick[k] <= 0.0)
                continue;
            li = k;
            acc += s->delta_pick[k];
            if (u < acc)
                break;
        }
        if (li < 0)
            return; /* no point or spot lights: nothing to trace */
        const lr_ref_light *l = &s->lights[li];
        lr_vec3 o, d;
        double power[3];
        lr_ref_light_emit_all(l, &rng, &o, &d, power);
        t.light_p = l->d.position;
        t.light_medium = l->medium;
        st->photons++;
        for (int g = 0; g < s->n_groups; g++) {
            t.mask = s->group_mask[g];
            double beta[3];
            for (int b = 0; b < 3; b++) {
                beta[b] = (t.mask & (1 << b)) ? 1.0 : 0.0;
                t.power[b] = power[b] / s->delta_pick[li];
            }
            lr_ref_walker w = {.x = o, .d = d, .medium = l->medium, .on_surface = false};
            lr_ref_photon_walk(s, w, t.mask, s->group_hero[g], &rng, st, visit, &t, NULL, beta);
        }
    }
}
