/* lamprig tests — Monte Carlo comparisons for the physical reference. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "render/reference/ref_priv.h"
#include "tests/support/mc.h"

lr_ref_estimate lrt_mean_se(double s1, double s2, double n)
{
    double m = s1 / n;
    return (lr_ref_estimate){m, sqrt(fmax(0.0, s2 / n - m * m) / (n - 1.0))};
}

void lrt_assert_agree(const char *what, lr_ref_estimate a, lr_ref_estimate b)
{
    double se = sqrt(a.se * a.se + b.se * b.se);
    printf("  %-44s %.5g +- %.2g vs %.5g +- %.2g (%+.2f SE)\n", what, a.value, a.se, b.value,
           b.se, se > 0.0 ? (a.value - b.value) / se : 0.0);
    assert_true(fabs(a.value - b.value) <= 4.0 * se);
}

#define BATCHES 64

typedef struct outflow {
    const lr_ref_scene *s;
    double R;
    int n; /* paths per batch */
    uint64_t seed;
    double sum[BATCHES], sum2[BATCHES];
    lr_ref_stats st[BATCHES];
} outflow;

static void outflow_batch(int b, void *user)
{
    outflow *j = user;
    lr_ref_rng rng;
    lr_ref_rng_seed(&rng, j->seed, (uint64_t)b);
    double A = 4.0 * LR_REF_PI * j->R * j->R;
    for (int i = 0; i < j->n; i++) {
        double z = 1.0 - 2.0 * lr_ref_rng_uniform(&rng);
        double phi = 2.0 * LR_REF_PI * lr_ref_rng_uniform(&rng), r = sqrt(fmax(0.0, 1 - z * z));
        lr_vec3 n = lr_v3(r * cos(phi), r * sin(phi), z);
        lr_vec3 x = lr_v3_scale(n, j->R);
        double u1 = lr_ref_rng_uniform(&rng), u2 = lr_ref_rng_uniform(&rng);
        lr_vec3 w = lr_ref_cosine_sample(n, u1, u2);
        /* From 5 % of R outside: clear of a faceted sphere inscribed in the analytic one. */
        lr_vec3 o = lr_v3_add(x, lr_v3_scale(w, 0.05 * j->R));
        double L[3] = {0, 0, 0};
        lr_ref_radiance(j->s, o, lr_v3_scale(w, -1.0), 0, &rng, &j->st[b], L);
        double f = A * LR_REF_PI * L[0] / (4.0 * LR_REF_PI);
        j->sum[b] += f;
        j->sum2[b] += f * f;
    }
}

lr_ref_estimate lrt_camera_outflow(const lr_ref_scene *s, double R, int paths, uint64_t seed,
                                   lr_ref_stats *stats)
{
    outflow *j = calloc(1, sizeof *j);
    assert_non_null(j);
    *j = (outflow){.s = s, .R = R, .n = paths / BATCHES, .seed = seed};
    assert_int_equal(lr_ref_parallel(BATCHES, 0, outflow_batch, j, NULL), LR_OK);
    double s1 = 0, s2 = 0;
    lr_ref_stats st = {0};
    for (int b = 0; b < BATCHES; b++) {
        s1 += j->sum[b];
        s2 += j->sum2[b];
        lr_ref_stats_add(&st, &j->st[b]);
    }
    if (stats)
        *stats = st;
    lr_ref_estimate e = lrt_mean_se(s1, s2, (double)j->n * BATCHES);
    free(j);
    return e;
}
