/* Section "optics": single-core evaluation rates of the BSSRDF formulas of render/optics, on
 * inputs shaped like the scattered-radiosity pass of seed 003 (x_i drawn around x_o with the
 * exponential radius sampling of Eq. 12, slightly curved surface, light from the upper
 * hemisphere). One evaluation = all three colour bands. */
#include "tools/bench/bench.h"

#include <math.h>
#include <stdint.h>

#include "render/optics/optics.h"

#define NCFG 4096 /* power of two: the loop indexes with & (NCFG - 1) */
#define RUNS 7
#define RUN_SECONDS 0.3

typedef struct cfg {
    lr_vec3 xi, ni, wi, xo, no;
    double r;
} cfg;

typedef struct ctx {
    lr_coeffs c;
    cfg cfgs[NCFG];
} ctx;

static uint64_t splitmix64(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static double uniform01(uint64_t *s) { return (double)(splitmix64(s) >> 11) * 0x1.0p-53; }

static void make_inputs(ctx *x)
{
    uint64_t seed = 3;
    for (int k = 0; k < NCFG; k++) {
        cfg *g = &x->cfgs[k];
        int band = k % 3;
        double r = lr_exp_radius_sample(x->c.sigma_tr[band], 20.0, uniform01(&seed));
        double a = 2.0 * M_PI * uniform01(&seed);
        /* A sphere of radius 20 mm around (0, 0, -20): x_o at its top, x_i at arc length ~r. */
        double R = 20.0, t = r / R;
        lr_vec3 ni = lr_v3(sin(t) * cos(a), sin(t) * sin(a), cos(t));
        g->xo = lr_v3(0.0, 0.0, 0.0);
        g->no = lr_v3(0.0, 0.0, 1.0);
        g->ni = ni;
        g->xi = lr_v3_add(lr_v3(0.0, 0.0, -R), lr_v3_scale(ni, R));
        double ct = 0.05 + 0.95 * uniform01(&seed), ph = 2.0 * M_PI * uniform01(&seed);
        double st = sqrt(1.0 - ct * ct);
        /* light direction in n_i's hemisphere, cos_i in [0.05, 1] */
        lr_vec3 t1 = lr_v3_normalize(lr_v3_cross(ni, lr_v3(1.0, 0.0, 0.0)));
        lr_vec3 t2 = lr_v3_cross(ni, t1);
        g->wi = lr_v3_add(lr_v3_add(lr_v3_scale(t1, st * cos(ph)), lr_v3_scale(t2, st * sin(ph))),
                          lr_v3_scale(ni, ct));
        g->r = r;
    }
}

static double body_dirpole(void *p, long n)
{
    const ctx *x = p;
    double acc = 0.0, out[3];
    for (long i = 0; i < n; i++) {
        const cfg *g = &x->cfgs[i & (NCFG - 1)];
        lr_dirpole_sd(&x->c, g->xi, g->ni, g->wi, g->xo, g->no, out);
        acc += out[0] + out[1] + out[2];
    }
    return acc;
}

static double body_dirpole_fresnel(void *p, long n)
{
    const ctx *x = p;
    double acc = 0.0, out[3];
    for (long i = 0; i < n; i++) {
        const cfg *g = &x->cfgs[i & (NCFG - 1)];
        lr_dirpole_sd_fresnel(&x->c, g->xi, g->ni, g->wi, g->xo, g->no, out);
        acc += out[0] + out[1] + out[2];
    }
    return acc;
}

static double body_dipole(void *p, long n)
{
    const ctx *x = p;
    double acc = 0.0, out[3];
    for (long i = 0; i < n; i++) {
        lr_dipole_rd(&x->c, x->cfgs[i & (NCFG - 1)].r, out);
        acc += out[0] + out[1] + out[2];
    }
    return acc;
}

/* The slab multipole of a 1.5 mm wall (Donner & Jensen 2005): with the pole-pair count
 * worked out per call (lr_multipole_sd_fresnel) and given once per wall, as the CPU twin's
 * estimator does (lr_multipole_sd_fresnel_n). */
#define MULTIPOLE_WALL_MM 1.5

static double body_multipole_fresnel(void *p, long n)
{
    const ctx *x = p;
    double acc = 0.0, out[3];
    for (long i = 0; i < n; i++) {
        const cfg *g = &x->cfgs[i & (NCFG - 1)];
        lr_multipole_sd_fresnel(&x->c, MULTIPOLE_WALL_MM, g->xi, g->ni, g->wi, g->xo, g->no, out);
        acc += out[0] + out[1] + out[2];
    }
    return acc;
}

static double body_multipole_fresnel_n(void *p, long n)
{
    const ctx *x = p;
    double acc = 0.0, out[3];
    int pairs = lr_multipole_pairs(&x->c, MULTIPOLE_WALL_MM);
    for (long i = 0; i < n; i++) {
        const cfg *g = &x->cfgs[i & (NCFG - 1)];
        lr_multipole_sd_fresnel_n(&x->c, MULTIPOLE_WALL_MM, pairs, g->xi, g->ni, g->wi, g->xo,
                                  g->no, out);
        acc += out[0] + out[1] + out[2];
    }
    return acc;
}

static void row(FILE *out, const char *name, lrb_body body, void *x)
{
    double rates[RUNS];
    double med = lrb_measure_rate(body, x, RUN_SECONDS, RUNS, rates);
    double lo = rates[0], hi = rates[0];
    for (int k = 1; k < RUNS; k++) {
        lo = rates[k] < lo ? rates[k] : lo;
        hi = rates[k] > hi ? rates[k] : hi;
    }
    fprintf(out, "| `%s` | %.2f M | %.1f | %.2f–%.2f M |\n", name, med * 1e-6, 1e9 / med, lo * 1e-6,
            hi * 1e-6);
}

static int run(FILE *out)
{
    static ctx x; /* 200 KiB: keep it off the stack */
    const lr_medium marble = {{0.0021, 0.0041, 0.0071}, {2.19, 2.62, 3.00}, 1.5, 0.0};
    lr_err e;
    if (lr_coeffs_derive(&marble, &x.c, &e) != LR_OK) {
        fprintf(stderr, "lamprig-bench: optics: %s\n", e.msg);
        return 1;
    }
    make_inputs(&x);
    int cpu = lrb_pin_to_current_cpu();
    char cpu_name[200];
    lrb_cpu_name(cpu_name, sizeof cpu_name);

    fprintf(out, "### optics: BSSRDF evaluations, one core\n\n");
    fprintf(out, "| function (3 colour bands per call) | evaluations/s (median of %d) | ns/eval | "
                 "min–max |\n|---|---|---|---|\n", RUNS);
    row(out, "lr_dirpole_sd", body_dirpole, &x);
    row(out, "lr_dirpole_sd_fresnel", body_dirpole_fresnel, &x);
    row(out, "lr_dipole_rd", body_dipole, &x);
    row(out, "lr_multipole_sd_fresnel (1.5 mm)", body_multipole_fresnel, &x);
    row(out, "lr_multipole_sd_fresnel_n (1.5 mm, pairs given)", body_multipole_fresnel_n, &x);
    fprintf(out, "\nMarble (Jensen 2001), %d inputs cycled (x_i at exponentially sampled radii on a "
                 "20 mm sphere, light in the upper hemisphere); %d runs of ~%.1f s each. "
                 "Host: %s, %s.\n\n",
            NCFG, RUNS, RUN_SECONDS, cpu_name,
            cpu >= 0 ? "pinned to one CPU" : "not pinned (sched_setaffinity failed)");
    return 0;
}

const lrb_section lrb_optics_section = {
    .name = "optics",
    .summary = "directional and standard dipole evaluations per second (one core)",
    .run = run,
};
