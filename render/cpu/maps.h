/* lamprig — CPU twin of the scattered-radiosity maps (PIPELINE.md pass 2) and of their
 * composition (pass 3, seed 003 Algorithm 1), for one object and one light.
 *
 * Map k looks along -d_k, d_k = lr_halton_sphere(k + 1), from the object's bounding sphere:
 * an orthographic view of [-R, R]^2 around the centre c, map_size^2 texels, texel (i, j) with
 * i along `right`, j along `up` (j = 0 at the bottom, GL order), centre at
 * c + 2R d_k + ((i + 0.5) h - R) right + ((j + 0.5) h - R) up, h = 2R / map_size. The view
 * basis: up0 = +z (or +y when |d_k.z| > 0.99), right = normalize(up0 x d_k), up = d_k x right
 * -- the same as lr_mat4_look_at(c + 2R d_k, c, up0). Each texel holds the first surface
 * along -d_k (x_o, interpolated n_o, depth = distance from the eye plane) and the running mean
 * of B over the frames accumulated so far with its pooled sample variance.
 */
#ifndef LR_CPU_MAPS_H
#define LR_CPU_MAPS_H

#include <stdbool.h>

#include "render/base/err.h"
#include "render/models/twin/radiosity.h"
#include "render/scene/scene.h"

typedef struct lr_cpu_maps lr_cpu_maps;

typedef struct lr_cpu_maps_desc {
    const lr_scene_object *object; /* must outlive the maps */
    const lr_light *light;         /* copied */
    int K;                         /* maps; 0: 16 */
    int map_size;                  /* texels per side; 0: 256 */
    int N;                         /* samples per texel, band and frame; 0: 16 */
    double r_max;                  /* 0: LR_CPU_RMAX_RADII radii (PIPELINE.md) */
    const lr_scene_object *const *others; /* see lr_cpu_radiosity_desc; may be NULL */
    int n_others;
    enum lr_cpu_sampler sampler;   /* LR_CPU_PASS (the twin) or LR_CPU_REFERENCE */
    unsigned seed;                 /* 0: 1 */
    int threads;                   /* 0: all CPUs */
    /* Algorithm 1's biases in mm; 0: eps_bias = 2 texels, eps_comb = 1 texel (as the GPU). */
    double eps_bias, eps_comb;
    /* Translucent radiosity (render/transrad/tr_scene.h): when tr has per-vertex B for object
     * tr_object and light tr_light, every texel takes it, interpolated over the triangle at
     * x_o (the GPU's radiosity.vert does the same), instead of the estimator. */
    const struct lr_tr_scene *tr;
    int tr_object, tr_light;
    lr_dfield_view dfield; /* diffusion_grid objects: the solved field (lr_cpu_radiosity_desc) */
    /* sh_translucency objects: see lr_cpu_radiosity_desc.sh_env (copied). */
    const struct lr_sh_env *sh_env;
} lr_cpu_maps_desc;

typedef struct lr_cpu_texel {
    bool valid;       /* a surface covers the texel centre */
    lr_vec3 x, n;     /* x_o, unit n_o */
    double depth;     /* mm from the eye plane along -d_k */
    double mean[3];   /* B per band, per unit intensity (running mean over frames) */
    double var[3];    /* pooled one-sample variance; of the mean: var / samples */
    long samples;     /* per band: frames * N */
} lr_cpu_texel;

/* Places the K views and finds x_o, n_o of every texel (no samples yet). */
int lr_cpu_maps_create(const lr_cpu_maps_desc *d, lr_cpu_maps **out, lr_err *e);
void lr_cpu_maps_destroy(lr_cpu_maps *m);

/* Adds `frames` frames: frame f (counted from 0 since create) draws N samples per band and
 * texel from key lr_rng_key(seed, k, texel index j * size + i, f). */
void lr_cpu_maps_accumulate(lr_cpu_maps *m, int frames);
int lr_cpu_maps_frames(const lr_cpu_maps *m);

int lr_cpu_maps_count(const lr_cpu_maps *m);
int lr_cpu_maps_size(const lr_cpu_maps *m);
lr_vec3 lr_cpu_maps_direction(const lr_cpu_maps *m, int k);
/* Map k's basis and eye: texel centres as documented above. */
void lr_cpu_maps_basis(const lr_cpu_maps *m, int k, lr_vec3 *eye, lr_vec3 *right, lr_vec3 *up);
const lr_cpu_texel *lr_cpu_maps_texel(const lr_cpu_maps *m, int k, int i, int j);

/* Seed 003 Algorithm 1 at (xo, no): B = sum v_k B_k / sum v_k over the maps that see x_o
 * (x_o moved by eps_comb along -(n_o - cos d_k); 2x2 bilinear taps, each visible when the
 * moved point is no deeper than the texel's depth + eps_bias and, beyond the paper, the
 * texel's normal faces the same side as n_o: shells thinner than eps_bias). When no map sees
 * it (weight <= 1e-6), the nearest texel of the map with the largest n_o . d_k, without
 * visibility (B = 0 if that texel is empty), and *fallback (may be NULL) is set. var_mean
 * (may be NULL): variance of B from the taps' variances of the mean (taps independent). */
void lr_cpu_maps_compose(const lr_cpu_maps *m, lr_vec3 xo, lr_vec3 no, double B[3],
                         double var_mean[3], bool *fallback);

#endif
