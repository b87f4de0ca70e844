/* "Photon in, count what comes out": the published plane-parallel benchmarks and the sphere
 * energy balance, run on the renderer's own transport steps (lr_ref_photon_trace). */
#include "render/reference/ref_priv.h"

#include <stdlib.h>

/* Fixed batch count: photons are split the same way whatever the thread count, each batch
 * has its own random stream, and batch sums are combined in order. */
#define BATCHES 64

enum { T_RTOT, T_RSPEC, T_RDIFF, T_TTOT, T_TUNS, T_ABS, T_SCAT, T_LT, N_TALLY };

typedef struct tally {
    double sum[N_TALLY], sum2[N_TALLY];
    lr_ref_stats stats;
} tally;

typedef struct job {
    const lr_ref_scene *scene;
    uint64_t photons, seed;
    lr_vec3 origin, dir; /* slab: the pencil beam; else unused (the light emits) */
    int light;           /* the light that emits, or -1 for the pencil beam */
    tally *t;            /* BATCHES */
} job;

static void add(tally *t, int i, double x)
{
    t->sum[i] += x;
    t->sum2[i] += x * x;
}

/* Light end of a photon from the light: whether camera-path NEE covers it. */
typedef struct first_vertex {
    const lr_ref_scene *s;
    const lr_ref_light *l;
    bool seen, covered;
} first_vertex;

static bool classify(void *user, const lr_ref_photon_vertex *v)
{
    first_vertex *f = user;
    if (v->index == 0) {
        f->seen = true;
        f->covered = lr_ref_nee_covers_light_end(f->s, f->l->d.position, f->l->medium, v);
    }
    return true;
}

static void run_batch(int batch, void *user)
{
    const job *j = user;
    tally *t = &j->t[batch];
    uint64_t n = j->photons / BATCHES + ((uint64_t)batch < j->photons % BATCHES ? 1 : 0);
    lr_ref_rng rng;
    lr_ref_rng_seed(&rng, j->seed, (uint64_t)batch);
    for (uint64_t i = 0; i < n; i++) {
        lr_vec3 o = j->origin, d = j->dir;
        int medium = 0;
        double power = 1.0;
        if (j->light >= 0) {
            medium = lr_ref_light_emit(j->scene, j->light, 0, &rng, &o, &d, &power);
            power /= lr_ref_light_power(j->scene, j->light, 0); /* fraction of its power */
        }
        lr_ref_photon_exit x;
        double beta[3] = {1.0, 0.0, 0.0};
        first_vertex fv = {.s = j->scene};
        if (j->light >= 0)
            fv.l = &j->scene->lights[j->light];
        lr_ref_walker wk = {.x = o, .d = d, .medium = medium, .on_surface = true};
        t->stats.paths++;
        lr_ref_photon_walk(j->scene, wk, 1, 0, &rng, &t->stats, j->light >= 0 ? classify : NULL,
                           &fv, &x, beta);
        double w = x.escaped ? beta[0] * power : 0.0;
        bool up = x.direction.z > 0.0;
        add(t, T_RTOT, up ? w : 0.0);
        add(t, T_RSPEC, up && x.scatterings == 0 ? w : 0.0);
        add(t, T_RDIFF, up && x.scatterings > 0 ? w : 0.0);
        add(t, T_TTOT, up ? 0.0 : w);
        add(t, T_TUNS, !up && x.scatterings == 0 ? w : 0.0);
        add(t, T_ABS, power - w);
        add(t, T_SCAT, x.scatterings > 0 ? w : 0.0);
        add(t, T_LT, fv.seen && !fv.covered ? w : 0.0);
    }
}

static lr_ref_estimate estimate(const tally *t, int i, uint64_t n)
{
    double s = 0.0, s2 = 0.0;
    for (int b = 0; b < BATCHES; b++) {
        s += t[b].sum[i];
        s2 += t[b].sum2[i];
    }
    double mean = s / (double)n;
    double var = n > 1 ? (s2 - (double)n * mean * mean) / (double)(n - 1) : 0.0;
    return (lr_ref_estimate){mean, sqrt(fmax(var, 0.0) / (double)n)};
}

static int run(job *j, int threads, lr_ref_stats *stats, lr_err *e)
{
    j->t = calloc(BATCHES, sizeof *j->t);
    if (!j->t)
        return lr_err_set(e, LR_ENOMEM, "reference: out of memory for tallies");
    int rc = lr_ref_parallel(BATCHES, threads, run_batch, j, e);
    if (stats) {
        *stats = (lr_ref_stats){0};
        for (int b = 0; b < BATCHES; b++)
            lr_ref_stats_add(stats, &j->t[b].stats);
    }
    return rc;
}

int lr_ref_slab_rt(const lr_ref_slab_problem *p, lr_ref_slab_result *out, lr_err *e)
{
    *out = (lr_ref_slab_result){0};
    if (!(p->albedo >= 0.0 && p->albedo <= 1.0) || !(p->optical_depth > 0.0) || p->photons < 2)
        return lr_err_set(e, LR_EINVAL, "reference: slab problem: need albedo in [0, 1], "
                          "optical depth > 0 and at least 2 photons");
    /* sigma_t = 1 mm^-1: lengths are in mean free paths and the thickness is the optical
     * depth. */
    lr_ref_scene *s;
    int rc = lr_ref_scene_create(NULL, &s, e);
    if (rc)
        return rc;
    lr_ref_medium_desc md = {.g = p->g, .eta = p->eta, .name = "slab"};
    for (int b = 0; b < 3; b++) {
        md.sigma_s[b] = p->albedo;
        md.sigma_a[b] = 1.0 - p->albedo;
    }
    int id;
    lr_ref_shape *shape;
    if (!(rc = lr_ref_scene_add_medium(s, &md, &id, e)) &&
        !(rc = lr_ref_slab_create(0.0, p->optical_depth, &shape, e))) {
        lr_ref_object_desc od = {.kind = LR_REF_BOUNDARY, .shape = shape, .inside = id,
                                 .name = "slab"};
        rc = lr_ref_scene_add_object(s, &od, e);
    }
    if (!rc)
        rc = lr_ref_scene_finish(s, e);
    job j = {.scene = s, .photons = p->photons, .seed = p->seed,
             .origin = lr_v3(0.0, 0.0, 1.0), .dir = lr_v3(0.0, 0.0, -1.0), .light = -1};
    if (!rc)
        rc = run(&j, p->threads, &out->stats, e);
    if (!rc) {
        out->r_total = estimate(j.t, T_RTOT, p->photons);
        out->r_specular = estimate(j.t, T_RSPEC, p->photons);
        out->r_diffuse = estimate(j.t, T_RDIFF, p->photons);
        out->t_total = estimate(j.t, T_TTOT, p->photons);
        out->t_unscattered = estimate(j.t, T_TUNS, p->photons);
        out->absorbed = estimate(j.t, T_ABS, p->photons);
    }
    free(j.t);
    lr_ref_scene_destroy(s);
    return rc;
}

int lr_ref_escape(const lr_ref_scene *s, int light, uint64_t photons, uint64_t seed, int threads,
                  lr_ref_escape_result *out, lr_err *e)
{
    *out = (lr_ref_escape_result){0};
    if (!s->finished || light < 0 || light >= s->n_lights || photons < 2 ||
        !(lr_ref_light_power(s, light, 0) > 0.0))
        return lr_err_set(e, LR_EINVAL, "reference: escape count needs a finished scene, a "
                          "light with power in band 0 and at least 2 photons");
    job j = {.scene = s, .photons = photons, .seed = seed, .light = light};
    int rc = run(&j, threads, &out->stats, e);
    if (!rc) {
        /* Everything escaping counts, whichever way it leaves: escaped = 1 - absorbed per
         * photon, so the absorbed tally's error is the escape's. */
        lr_ref_estimate absorbed = estimate(j.t, T_ABS, photons);
        out->escaped = (lr_ref_estimate){1.0 - absorbed.value, absorbed.se};
        out->escaped_scattered = estimate(j.t, T_SCAT, photons);
        out->escaped_light_traced = estimate(j.t, T_LT, photons);
    }
    free(j.t);
    return rc;
}

int lr_ref_sphere_escape(const lr_ref_sphere_problem *p, lr_ref_escape_result *out, lr_err *e)
{
    *out = (lr_ref_escape_result){0};
    double rl = lr_v3_len(p->offset);
    if (!(p->radius > 0.0) || !(rl < p->radius) || !(p->cavity >= 0.0 && p->cavity < p->radius) ||
        (p->cavity > 0.0 && !(rl < p->cavity)) || p->photons < 2)
        return lr_err_set(e, LR_EINVAL, "reference: sphere problem: need radius > 0, 0 <= "
                          "cavity < radius, the light inside (the cavity) and at least 2 "
                          "photons");
    lr_ref_scene *s;
    int rc = lr_ref_scene_create(NULL, &s, e);
    if (rc)
        return rc;
    int id;
    lr_ref_shape *shape;
    if (!(rc = lr_ref_scene_add_medium(s, &p->medium, &id, e)) &&
        !(rc = lr_ref_sphere_create(lr_v3(0.0, 0.0, 0.0), p->radius, &shape, e))) {
        lr_ref_object_desc od = {.kind = LR_REF_BOUNDARY, .shape = shape, .inside = id,
                                 .name = "sphere"};
        rc = lr_ref_scene_add_object(s, &od, e);
    }
    if (!rc && p->cavity > 0.0 &&
        !(rc = lr_ref_sphere_create(lr_v3(0.0, 0.0, 0.0), p->cavity, &shape, e))) {
        lr_ref_object_desc od = {.kind = LR_REF_BOUNDARY, .shape = shape, .inside = 0,
                                 .outside = id, .name = "cavity"};
        rc = lr_ref_scene_add_object(s, &od, e);
    }
    lr_ref_light_desc ld = {.kind = LR_REF_LIGHT_POINT, .position = p->offset,
                            .emission = {1.0, 1.0, 1.0}};
    if (!rc)
        rc = lr_ref_scene_add_light(s, &ld, e);
    if (!rc)
        rc = lr_ref_scene_finish(s, e);
    if (!rc)
        rc = lr_ref_escape(s, 0, p->photons, p->seed, p->threads, out, e);
    lr_ref_scene_destroy(s);
    return rc;
}
