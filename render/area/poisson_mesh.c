/* Poisson-disk samples on a mesh by dart throwing over a hash grid (poisson_mesh.h). */
#include <math.h>
#include <stdlib.h>

#include "render/area/poisson_mesh.h"
#include "render/base/rng.h"
#include "render/mesh/area_pick.h"

/* A hash grid of r_min cells: cell -> chain of sample indices. */
typedef struct grid {
    int *head; /* per bucket, -1: empty */
    int *next; /* per sample */
    size_t buckets;
    double cell;
    lr_vec3 lo;
} grid;

static size_t bucket(const grid *g, long ix, long iy, long iz)
{
    uint64_t h = lr_rng_key((uint64_t)ix, (uint64_t)iy, (uint64_t)iz, 0x6A1D);
    return (size_t)(h % g->buckets);
}

static void cell_of(const grid *g, lr_vec3 p, long c[3])
{
    c[0] = (long)floor((p.x - g->lo.x) / g->cell);
    c[1] = (long)floor((p.y - g->lo.y) / g->cell);
    c[2] = (long)floor((p.z - g->lo.z) / g->cell);
}

static bool far_enough(const grid *g, const lr_surface_sample *s, lr_vec3 p, double r2)
{
    long c[3];
    cell_of(g, p, c);
    for (long dx = -1; dx <= 1; dx++)
        for (long dy = -1; dy <= 1; dy++)
            for (long dz = -1; dz <= 1; dz++)
                for (int i = g->head[bucket(g, c[0] + dx, c[1] + dy, c[2] + dz)]; i >= 0;
                     i = g->next[i]) {
                    lr_vec3 d = lr_v3_sub(p, s[i].p);
                    if (lr_v3_dot(d, d) < r2)
                        return false;
                }
    return true;
}

int lr_poisson_mesh(const lr_mesh *m, double r_min, int cap, int max_fails, uint64_t seed,
                    lr_poisson_set *out, lr_err *e)
{
    *out = (lr_poisson_set){0};
    if (!m || !(r_min > 0.0) || !isfinite(r_min) || cap < 1 || max_fails < 1)
        return lr_err_set(e, LR_EINVAL, "Poisson-disk samples: need a mesh, r_min > 0, cap and "
                          "max_fails >= 1 (got %g, %d, %d)", r_min, cap, max_fails);
    size_t nt = lr_mesh_triangle_count(m);
    double *cdf = malloc(nt * sizeof *cdf);
    grid g = {.buckets = (size_t)cap * 2 + 1, .cell = r_min};
    g.head = malloc(g.buckets * sizeof *g.head);
    g.next = malloc((size_t)cap * sizeof *g.next);
    lr_surface_sample *s = malloc((size_t)cap * sizeof *s);
    if (!cdf || !g.head || !g.next || !s) {
        free(cdf);
        free(g.head);
        free(g.next);
        free(s);
        return lr_err_set(e, LR_ENOMEM, "Poisson-disk samples: out of memory for %d samples",
                          cap);
    }
    for (size_t b = 0; b < g.buckets; b++)
        g.head[b] = -1;
    lr_vec3 hi;
    lr_mesh_bounds(m, &g.lo, &hi);
    double total = 0.0;
    for (size_t t = 0; t < nt; t++)
        cdf[t] = total += lr_mesh_triangle_area(m, t);
    lr_rng rng = lr_rng_init(lr_rng_key(seed, 0x7D05, nt, 0));
    double r2 = r_min * r_min;
    int n = 0, fails = 0;
    while (n < cap && fails < max_fails) {
        size_t t = lr_cdf_pick(cdf, nt, lr_rng_next(&rng) * total);
        lr_vec3 q[3];
        lr_mesh_triangle(m, t, q);
        /* Uniform in the triangle: the square root folds the unit square onto it. */
        double a = sqrt(lr_rng_next(&rng)), b = lr_rng_next(&rng);
        lr_vec3 p = lr_v3_add(lr_v3_scale(q[0], 1.0 - a),
                              lr_v3_add(lr_v3_scale(q[1], a * (1.0 - b)),
                                        lr_v3_scale(q[2], a * b)));
        if (!far_enough(&g, s, p, r2)) {
            fails++;
            continue;
        }
        fails = 0;
        s[n] = (lr_surface_sample){.p = p, .n = lr_mesh_triangle_normal(m, t),
                                   .tri = (uint32_t)t};
        long c[3];
        cell_of(&g, p, c);
        size_t bk = bucket(&g, c[0], c[1], c[2]);
        g.next[n] = g.head[bk];
        g.head[bk] = n;
        n++;
    }
    for (int i = 0; i < n; i++)
        s[i].area = total / n;
    free(cdf);
    free(g.head);
    free(g.next);
    out->s = s;
    out->n = n;
    return LR_OK;
}

void lr_poisson_set_free(lr_poisson_set *set)
{
    if (!set)
        return;
    free(set->s);
    *set = (lr_poisson_set){0};
}
