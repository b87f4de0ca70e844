/* CPU radiosity maps and Algorithm 1; see maps.h. */
#include "render/cpu/maps.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/area/frames.h"
#include "render/base/parallel.h"
#include "render/base/rng.h"
#include "render/transrad/tr_scene.h"
#include "render/optics/sh_translucency.h"

struct lr_cpu_maps {
    const lr_scene_object *obj;
    lr_light light;
    int K, S, N, frames, threads;
    double r_max, eps_bias, eps_comb, texel;
    const lr_scene_object *const *others;
    int n_others;
    enum lr_cpu_sampler sampler;
    const lr_tr_scene *tr;
    int tr_object, tr_light;
    unsigned seed;
    lr_dfield_view dfield; /* the caller's; must outlive the maps */
    bool has_sh;
    lr_sh_env sh;
    lr_vec3 *dir, *eye, *right, *up;
    lr_cpu_texel *tex; /* K * S * S, map-major, row j then column i */
};

static lr_cpu_texel *texel_at(const lr_cpu_maps *m, int k, int i, int j)
{
    return m->tex + ((size_t)k * m->S + (size_t)j) * m->S + (size_t)i;
}

static void place_views(lr_cpu_maps *m)
{
    const lr_scene_object *o = m->obj;
    for (int k = 0; k < m->K; k++) {
        lr_vec3 d = lr_halton_sphere((unsigned)k + 1);
        lr_vec3 up0 = fabs(d.z) > 0.99 ? lr_v3(0, 1, 0) : lr_v3(0, 0, 1);
        lr_vec3 right = lr_v3_normalize(lr_v3_cross(up0, d));
        m->dir[k] = d;
        m->right[k] = right;
        m->up[k] = lr_v3_cross(d, right);
        m->eye[k] = lr_v3_add(o->center, lr_v3_scale(d, 2.0 * o->radius));
    }
}

typedef struct raster_ctx {
    lr_cpu_maps *m;
} raster_ctx;

static void raster_item(void *p, long item)
{
    lr_cpu_maps *m = ((raster_ctx *)p)->m;
    long per = (long)m->S * m->S;
    int k = (int)(item / per), j = (int)(item % per / m->S), i = (int)(item % m->S);
    double R = m->obj->radius, h = m->texel;
    lr_vec3 org = lr_v3_add(m->eye[k], lr_v3_add(lr_v3_scale(m->right[k], (i + 0.5) * h - R),
                                                 lr_v3_scale(m->up[k], (j + 0.5) * h - R)));
    lr_cpu_texel *t = texel_at(m, k, i, j);
    memset(t, 0, sizeof *t);
    lr_vec3 x, n;
    lr_vec3 back = lr_v3_scale(m->dir[k], -1.0);
    if (lr_first_surface(m->obj, org, back, 0.0, &x, &n)) {
        if (!m->obj->closed && lr_v3_dot(n, m->dir[k]) < 0.0)
            n = lr_v3_scale(n, -1.0); /* two-sided open surface: the side the map sees */
        t->valid = true;
        t->x = x;
        t->n = n;
        t->depth = lr_v3_dot(lr_v3_sub(m->eye[k], x), m->dir[k]);
    }
}

int lr_cpu_maps_create(const lr_cpu_maps_desc *d, lr_cpu_maps **out, lr_err *e)
{
    if (!d || !d->object || !d->light || !out)
        return lr_err_set(e, LR_EINVAL, "cpu maps: NULL %s",
                          !d ? "descriptor" : !d->object ? "object" : !d->light ? "light" : "out");
    if (d->K < 0 || d->map_size < 0 || d->N < 0 || d->K > 1024 || d->map_size > 4096)
        return lr_err_set(e, LR_EINVAL, "cpu maps: K = %d, map_size = %d, N = %d out of range",
                          d->K, d->map_size, d->N);
    lr_cpu_maps *m = calloc(1, sizeof *m);
    if (!m)
        return lr_err_set(e, LR_ENOMEM, "cpu maps: out of memory");
    m->obj = d->object;
    m->light = *d->light;
    m->K = d->K ? d->K : 16;
    m->S = d->map_size ? d->map_size : 256;
    m->N = d->N ? d->N : 16;
    m->r_max = d->r_max;
    m->others = d->others;
    m->dfield = d->dfield;
    m->n_others = d->n_others;
    m->sampler = d->sampler;
    m->tr = lr_tr_scene_vertex_B(d->tr, d->tr_object, d->tr_light) ? d->tr : NULL;
    m->tr_object = d->tr_object;
    m->tr_light = d->tr_light;
    m->seed = d->seed ? d->seed : 1;
    m->has_sh = d->sh_env != NULL;
    if (d->sh_env)
        m->sh = *d->sh_env;
    m->threads = d->threads;
    m->texel = 2.0 * m->obj->radius / m->S;
    m->eps_bias = d->eps_bias > 0.0 ? d->eps_bias : 2.0 * m->texel;
    m->eps_comb = d->eps_comb > 0.0 ? d->eps_comb : m->texel;
    m->dir = calloc((size_t)m->K, sizeof *m->dir);
    m->eye = calloc((size_t)m->K, sizeof *m->eye);
    m->right = calloc((size_t)m->K, sizeof *m->right);
    m->up = calloc((size_t)m->K, sizeof *m->up);
    m->tex = calloc((size_t)m->K * m->S * m->S, sizeof *m->tex);
    if (!m->dir || !m->eye || !m->right || !m->up || !m->tex) {
        lr_cpu_maps_destroy(m);
        return lr_err_set(e, LR_ENOMEM, "cpu maps: out of memory for %d maps of %d^2", d->K,
                          d->map_size);
    }
    place_views(m);
    raster_ctx rc = {m};
    lr_parallel_for((long)m->K * m->S * m->S, m->threads, raster_item, &rc);
    *out = m;
    return LR_OK;
}

void lr_cpu_maps_destroy(lr_cpu_maps *m)
{
    if (!m)
        return;
    free(m->dir);
    free(m->eye);
    free(m->right);
    free(m->up);
    free(m->tex);
    free(m);
}

typedef struct acc_ctx {
    lr_cpu_maps *m;
    int frame;
    lr_light light; /* the frame's: an area light at its frame sample (render/area/frames.h) */
} acc_ctx;

static void acc_item(void *p, long item)
{
    acc_ctx *a = p;
    lr_cpu_maps *m = a->m;
    long per = (long)m->S * m->S;
    int k = (int)(item / per);
    long texel = item % per;
    lr_cpu_texel *t = m->tex + item;
    if (!t->valid)
        return;
    if (m->tr) {
        /* Translucent radiosity: the solved B, the same every frame (no variance). */
        lr_closest cl;
        double B[3] = {0, 0, 0};
        if (lr_bvh_closest(m->obj->bvh, t->x, INFINITY, &cl))
            lr_tr_scene_B_at(m->tr, m->tr_object, m->tr_light, cl.triangle, cl.w, B);
        for (int c = 0; c < 3; c++) {
            t->mean[c] = B[c];
            t->var[c] = 0;
        }
        t->samples += m->N;
        return;
    }
    lr_cpu_radiosity_desc d = {.N = m->N, .sampler = m->sampler, .r_max = m->r_max,
                               .others = m->others, .n_others = m->n_others,
                               .dfield = m->dfield,
                               .sh_env = m->has_sh ? &m->sh : NULL};
    lr_cpu_estimate est;
    lr_cpu_radiosity(m->obj, &a->light, t->x, t->n, &d,
                     lr_rng_key(m->seed, (uint64_t)k, (uint64_t)texel, (uint64_t)a->frame), &est);
    /* Running mean and pooled variance (Chan et al.'s pairwise update). */
    long na = t->samples, nb = est.n, n = na + nb;
    for (int c = 0; c < 3; c++) {
        double m2a = t->var[c] * (na > 1 ? na - 1 : 0), m2b = est.var[c] * (nb - 1);
        double delta = est.mean[c] - t->mean[c];
        double mean = t->mean[c] + delta * nb / n;
        double m2 = m2a + m2b + delta * delta * (double)na * nb / n;
        t->mean[c] = mean;
        t->var[c] = n > 1 ? m2 / (n - 1) : 0.0;
    }
    t->samples = n;
}

void lr_cpu_maps_accumulate(lr_cpu_maps *m, int frames)
{
    for (int f = 0; f < frames; f++) {
        acc_ctx a = {m, m->frames, m->light};
        lr_light_at_frame(&m->light, m->frames, &a.light);
        lr_parallel_for((long)m->K * m->S * m->S, m->threads, acc_item, &a);
        m->frames++;
    }
}

int lr_cpu_maps_frames(const lr_cpu_maps *m) { return m->frames; }
int lr_cpu_maps_count(const lr_cpu_maps *m) { return m->K; }
int lr_cpu_maps_size(const lr_cpu_maps *m) { return m->S; }
lr_vec3 lr_cpu_maps_direction(const lr_cpu_maps *m, int k) { return m->dir[k]; }

void lr_cpu_maps_basis(const lr_cpu_maps *m, int k, lr_vec3 *eye, lr_vec3 *right, lr_vec3 *up)
{
    *eye = m->eye[k];
    *right = m->right[k];
    *up = m->up[k];
}

const lr_cpu_texel *lr_cpu_maps_texel(const lr_cpu_maps *m, int k, int i, int j)
{
    if (k < 0 || k >= m->K || i < 0 || i >= m->S || j < 0 || j >= m->S)
        return NULL;
    return texel_at(m, k, i, j);
}

/* Bilinear 2x2 taps of map k around point p: a tap counts when p is no deeper than its depth +
 * eps_bias and its normal faces the same side as no. Adds w*B, w^2*var/n and w into the sums. */
static void taps(const lr_cpu_maps *m, int k, lr_vec3 p, lr_vec3 no, double sum[3],
                 double var[3], double *wsum)
{
    double R = m->obj->radius;
    lr_vec3 rel = lr_v3_sub(p, m->eye[k]);
    double u = (lr_v3_dot(rel, m->right[k]) + R) / m->texel - 0.5;
    double v = (lr_v3_dot(rel, m->up[k]) + R) / m->texel - 0.5;
    double depth = -lr_v3_dot(rel, m->dir[k]);
    if (!(u > -1.0 && v > -1.0 && u < m->S && v < m->S))
        return;
    int i0 = (int)floor(u), j0 = (int)floor(v);
    double fu = u - i0, fv = v - j0;
    for (int dj = 0; dj < 2; dj++)
        for (int di = 0; di < 2; di++) {
            const lr_cpu_texel *t = lr_cpu_maps_texel(m, k, i0 + di, j0 + dj);
            if (!t || !t->valid || t->samples == 0)
                continue;
            if (!(depth <= t->depth + m->eps_bias))
                continue;
            /* Beyond Algorithm 1 (as the GLSL pass): the texel's surface must face the same
             * side as x_o, or a shell thinner than eps_bias mixes its two sides' radiosity. */
            if (!(lr_v3_dot(t->n, no) > 0.0))
                continue;
            double w = (di ? fu : 1.0 - fu) * (dj ? fv : 1.0 - fv);
            for (int c = 0; c < 3; c++) {
                sum[c] += w * t->mean[c];
                var[c] += w * w * t->var[c] / t->samples;
            }
            *wsum += w;
        }
}

void lr_cpu_maps_compose(const lr_cpu_maps *m, lr_vec3 xo, lr_vec3 no, double B[3],
                         double var_mean[3], bool *fallback)
{
    double sum[3] = {0}, var[3] = {0}, wsum = 0.0;
    int best = 0;
    double best_cos = -2.0;
    for (int k = 0; k < m->K; k++) {
        double cs = lr_v3_dot(no, m->dir[k]);
        if (cs > best_cos) {
            best_cos = cs;
            best = k;
        }
        cs = cs < 0.0 ? 0.0 : cs > 1.0 ? 1.0 : cs;
        /* seed 003 Algorithm 1: x_o - eps_comb (n_o - cos(theta) d_k). */
        lr_vec3 xb = lr_v3_sub(xo, lr_v3_scale(lr_v3_sub(no, lr_v3_scale(m->dir[k], cs)),
                                              m->eps_comb));
        taps(m, k, xb, no, sum, var, &wsum);
    }
    bool fb = false;
    if (!(wsum > 1e-6)) {
        /* No map sees x_o: the map facing it most, nearest texel, no visibility test. */
        fb = true;
        double R = m->obj->radius;
        lr_vec3 rel = lr_v3_sub(xo, m->eye[best]);
        int i = (int)floor((lr_v3_dot(rel, m->right[best]) + R) / m->texel);
        int j = (int)floor((lr_v3_dot(rel, m->up[best]) + R) / m->texel);
        i = i < 0 ? 0 : i >= m->S ? m->S - 1 : i;
        j = j < 0 ? 0 : j >= m->S ? m->S - 1 : j;
        const lr_cpu_texel *t = texel_at(m, best, i, j);
        for (int c = 0; c < 3; c++) {
            sum[c] = t->valid ? t->mean[c] : 0.0;
            var[c] = t->valid && t->samples ? t->var[c] / t->samples : 0.0;
        }
        wsum = 1.0;
    }
    for (int c = 0; c < 3; c++) {
        B[c] = wsum > 0.0 ? sum[c] / wsum : 0.0;
        if (var_mean)
            var_mean[c] = wsum > 0.0 ? var[c] / (wsum * wsum) : 0.0;
    }
    if (fallback)
        *fallback = fb;
}
