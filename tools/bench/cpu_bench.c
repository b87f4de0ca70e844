/* Section "cpu": the CPU twin and reference (render/cpu). (1) Single-core rates of the
 * radiosity estimator, pass and reference, at a texel of the candle (one sample = one band);
 * (2) the twin's progressive error: RMS relative error of its radiosity-map texels against the
 * converged reference at the same points after 1, 4, 16 and 64 frames, candle and lampshade.
 * The GPU's own error table needs the renderer (render/renderer_debug.h gives the same texels);
 * the CPU table is what the pass's estimator itself achieves per frame count. */
#include "tools/bench/bench.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/paths.h"
#include "render/cpu/maps.h"
#include "render/base/rng.h"
#include "render/scene/scene.h"

typedef struct rate_ctx {
    const lr_scene_object *o;
    const lr_light *l;
    lr_vec3 xo, no;
    enum lr_cpu_sampler mode;
    uint64_t key;
} rate_ctx;

static double rate_body(void *p, long n)
{
    rate_ctx *c = p;
    lr_cpu_radiosity_desc d = {.N = (int)(n / 3 > 0 ? n / 3 : 1), .sampler = c->mode};
    lr_cpu_estimate est;
    lr_cpu_radiosity(c->o, c->l, c->xo, c->no, &d, c->key++, &est);
    return est.mean[0] + est.mean[1] + est.mean[2];
}

static lr_scene *load(const char *name)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/scenes/%s.json", lr_configs_dir(), name);
    lr_scene *s = NULL;
    lr_err e = {0};
    if (lr_scene_load(path, &(const lr_warn_sink){lr_warn_stderr, "lamprig-bench"}, &s, &e))
        fprintf(stderr, "bench cpu: %s\n", e.msg);
    return s;
}

static int progressive(FILE *out, const char *name)
{
    lr_scene *s = load(name);
    if (!s)
        return 1;
    const int K = 4, S = 24, N = 16;
    lr_cpu_maps_desc d = {.object = lr_scene_object_at(s, 0), .light = lr_scene_light_at(s, 0),
                          .K = K, .map_size = S, .N = N,
                          .threads = 1 /* the section pins its thread; workers would share the core */};
    lr_cpu_maps *m;
    lr_err e = {0};
    if (lr_cpu_maps_create(&d, &m, &e)) {
        fprintf(stderr, "bench cpu: %s\n", e.msg);
        lr_scene_destroy(s);
        return 1;
    }
    size_t n = (size_t)K * S * S;
    double(*ref)[3] = calloc(n, sizeof *ref), (*rv)[3] = calloc(n, sizeof *rv);
    lr_cpu_radiosity_desc rd = {.N = 2048, .sampler = LR_CPU_REFERENCE};
    for (int k = 0; k < K; k++)
        for (int t = 0; t < S * S; t++) {
            const lr_cpu_texel *tx = lr_cpu_maps_texel(m, k, t % S, t / S);
            if (!tx->valid)
                continue;
            lr_cpu_estimate est;
            lr_cpu_radiosity(d.object, d.light, tx->x, tx->n, &rd, lr_rng_key(5, k, t, 0), &est);
            for (int c = 0; c < 3; c++) {
                ref[k * S * S + t][c] = est.mean[c];
                rv[k * S * S + t][c] = est.var[c] / est.n;
            }
        }
    static const int frames[] = {1, 4, 16, 64};
    fprintf(out, "| %s | ", name);
    for (int f = 0; f < 4; f++) {
        lr_cpu_maps_accumulate(m, frames[f] - lr_cpu_maps_frames(m));
        double se = 0, sw = 0;
        for (int k = 0; k < K; k++)
            for (int t = 0; t < S * S; t++) {
                const lr_cpu_texel *tx = lr_cpu_maps_texel(m, k, t % S, t / S);
                if (!tx->valid)
                    continue;
                for (int c = 0; c < 3; c++) {
                    double r = ref[k * S * S + t][c];
                    if (!(r > 0))
                        continue;
                    /* Error weighted by B (bright texels dominate what one sees), minus the
                     * reference's own variance. */
                    se += (tx->mean[c] - r) * (tx->mean[c] - r) - rv[k * S * S + t][c];
                    sw += r * r;
                }
            }
        fprintf(out, "%.3f |%s", sqrt(fmax(se, 0) / sw), f < 3 ? " " : "");
    }
    fprintf(out, "\n");
    free(ref);
    free(rv);
    lr_cpu_maps_destroy(m);
    lr_scene_destroy(s);
    return 0;
}

static int run(FILE *out)
{
    lr_scene *s = load("candle");
    if (!s)
        return 1;
    const lr_scene_object *o = lr_scene_object_at(s, 0);
    rate_ctx c = {.o = o, .l = lr_scene_light_at(s, 0), .key = 1};
    if (!lr_first_surface(o, lr_v3(0, -200, 60), lr_v3(0, 1, 0), 0, &c.xo, &c.no)) {
        lr_scene_destroy(s);
        return 1;
    }
    int cpu = lrb_pin_to_current_cpu();
    char name[256];
    lrb_cpu_name(name, sizeof name);
    double rates[32];
    fprintf(out, "### CPU twin and reference (render/cpu)\n\n");
    fprintf(out, "| estimator | band-samples/s, one core (median of 5) |\n|---|---|\n");
    for (int mode = 0; mode < 2; mode++) {
        c.mode = mode ? LR_CPU_REFERENCE : LR_CPU_PASS;
        double r = lrb_measure_rate(rate_body, &c, 0.3, 5, rates);
        fprintf(out, "| %s | %.3g |\n", mode ? "reference (mixture, untruncated)" : "pass (twin)", r);
    }
    fprintf(out, "\nCandle, x_o on the side of the pillar; thread CPU time on %s (cpu %d).\n\n", name,
            cpu);
    lr_scene_destroy(s);
    fprintf(out, "Twin's radiosity maps (K 4, 24^2, N 16) against the converged reference at the "
                 "same texels (2048 samples/band), B-weighted RMS relative error:\n\n"
                 "| scene | 1 frame | 4 | 16 | 64 |\n|---|---|---|---|---|\n");
    int rc = progressive(out, "candle");
    rc |= progressive(out, "lampshade");
    fprintf(out, "\n");
    return rc;
}

const lrb_section lrb_cpu_section = {
    .name = "cpu",
    .summary = "CPU twin/reference: estimator rates, twin map error vs frames",
    .run = run,
};
