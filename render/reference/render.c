/* The progressive renderer: camera rays through pixels plus light tracing (lighttrace.c),
 * accumulated pass by pass.
 *
 * Camera paths: each pixel keeps the sum and the sum of squares of its per-sample radiance, so
 * the mean and the variance of the mean are available after any pass. Sample j of pixel i
 * draws from the random stream (seed, i << 32 | j).
 * Light tracing: sample index j also traces LT_PER_PIXEL photons per pixel (streams
 * (seed', j << 32 | photon)); their splats, divided by that count, are one estimate of the
 * light-traced image per sample index, and the variance of its mean comes from the spread of
 * those estimates. Splats are collected per fixed batch and applied in batch order.
 * So the image depends on the seed and the sample count only, not on the thread count, tile
 * order or pass size. The mean is the sum of the two images; the variance the sum of their
 * variances (independent streams). */
#include "render/reference/ref_priv.h"

#include <stdlib.h>
#include <string.h>

#define TILE 16
#define LT_BATCH 4096 /* photons per light-tracing batch */
/* Light-tracing photons per pixel and sample. Photons whose light end camera paths cover stop
 * at their first vertex (a few ray casts), so several per camera path cost little and keep
 * the sparse splats of reflected light from dominating a pixel's noise. */
#define LT_PER_PIXEL 4

struct lr_ref_render {
    const lr_ref_scene *s;
    lr_ref_render_desc d;
    double *sum, *sum2; /* width * height * 3 */
    int spp_done;
    int pass_n; /* samples added by the pass in progress */
    int tiles_x, tiles_y;
    lr_ref_stats *tile_stats;
    lr_ref_stats stats;
    /* light tracing */
    lr_ref_pinhole pin;
    bool trace_lights;   /* the scene has point or spot lights */
    double *lt_sum, *lt_sum2, *lt_cur; /* per pixel and band */
    int lt_batches;
    lr_ref_splats *lt_splats;          /* per batch */
    lr_ref_stats *lt_stats;            /* per batch */
    uint64_t lt_j;                     /* sample index being light-traced */
};

lr_ref_render_desc lr_ref_render_desc_resolve(const lr_ref_render_desc *in)
{
    lr_ref_render_desc d = in ? *in : (lr_ref_render_desc){0};
    if (d.width == 0)
        d.width = 160;
    if (d.height == 0)
        d.height = 120;
    if (d.spp == 0)
        d.spp = 64;
    if (d.spp_per_pass == 0)
        d.spp_per_pass = 4;
    return d;
}

lr_ref_camera lr_ref_camera_resolve(const lr_ref_camera *in)
{
    lr_ref_camera c = *in;
    if (lr_v3_len(c.up) == 0.0)
        c.up = lr_v3(0.0, 0.0, 1.0);
    if (c.fov_y_deg == 0.0)
        c.fov_y_deg = 40.0;
    return c;
}

int lr_ref_render_create(const lr_ref_scene *s, const lr_ref_camera *cam,
                         const lr_ref_render_desc *desc, lr_ref_render **out, lr_err *e)
{
    *out = NULL;
    if (!s->finished)
        return lr_err_set(e, LR_EINVAL, "reference: render of an unfinished scene");
    lr_ref_render_desc d = lr_ref_render_desc_resolve(desc);
    lr_ref_camera c = lr_ref_camera_resolve(cam);
    if (d.width < 1 || d.height < 1 || d.width > 16384 || d.height > 16384 || d.spp < 1 ||
        d.spp_per_pass < 1)
        return lr_err_set(e, LR_EINVAL, "reference: render %dx%d, spp %d, spp_per_pass %d: "
                          "sizes must be 1..16384 and counts >= 1", d.width, d.height, d.spp,
                          d.spp_per_pass);
    lr_vec3 fwd = lr_v3_sub(c.look_at, c.position);
    lr_vec3 right = lr_v3_cross(fwd, c.up);
    if (!lr_v3_isfinite(c.position) || !lr_v3_isfinite(fwd) || !(lr_v3_len(fwd) > 0.0) ||
        !(lr_v3_len(right) > 0.0) || !(c.fov_y_deg > 0.0 && c.fov_y_deg < 180.0))
        return lr_err_set(e, LR_EINVAL, "reference: camera needs distinct position and "
                          "look_at, an up vector not along the view, and 0 < fov_y_deg < 180");
    lr_ref_render *r = calloc(1, sizeof *r);
    size_t npix = (size_t)d.width * (size_t)d.height, n = npix * 3;
    bool lt = false;
    for (int i = 0; i < s->n_lights; i++)
        lt = lt || s->delta_pick[i] > 0.0;
    if (r) {
        r->sum = calloc(n, sizeof *r->sum);
        r->sum2 = calloc(n, sizeof *r->sum2);
        r->tiles_x = (d.width + TILE - 1) / TILE;
        r->tiles_y = (d.height + TILE - 1) / TILE;
        r->tile_stats = calloc((size_t)r->tiles_x * (size_t)r->tiles_y, sizeof *r->tile_stats);
        r->trace_lights = lt;
        r->lt_batches = (int)((LT_PER_PIXEL * npix + LT_BATCH - 1) / LT_BATCH);
        if (lt) {
            r->lt_sum = calloc(n, sizeof *r->lt_sum);
            r->lt_sum2 = calloc(n, sizeof *r->lt_sum2);
            r->lt_cur = calloc(n, sizeof *r->lt_cur);
            r->lt_splats = calloc((size_t)r->lt_batches, sizeof *r->lt_splats);
            r->lt_stats = calloc((size_t)r->lt_batches, sizeof *r->lt_stats);
        }
    }
    if (!r || !r->sum || !r->sum2 || !r->tile_stats ||
        (lt && (!r->lt_sum || !r->lt_sum2 || !r->lt_cur || !r->lt_splats || !r->lt_stats))) {
        lr_ref_render_destroy(r);
        return lr_err_set(e, LR_ENOMEM, "reference: out of memory for a %dx%d render", d.width,
                          d.height);
    }
    r->s = s;
    r->d = d;
    lr_ref_pinhole_init(&r->pin, &c, d.width, d.height, lr_ref_scene_medium_at(s, c.position));
    *out = r;
    return LR_OK;
}

void lr_ref_render_destroy(lr_ref_render *r)
{
    if (!r)
        return;
    free(r->sum);
    free(r->sum2);
    free(r->tile_stats);
    free(r->lt_sum);
    free(r->lt_sum2);
    free(r->lt_cur);
    if (r->lt_splats)
        for (int b = 0; b < r->lt_batches; b++)
            free(r->lt_splats[b].v);
    free(r->lt_splats);
    free(r->lt_stats);
    free(r);
}

static void render_tile(int tile, void *user)
{
    lr_ref_render *r = user;
    int tx = tile % r->tiles_x, ty = tile / r->tiles_x;
    int W = r->d.width, H = r->d.height;
    lr_ref_stats *st = &r->tile_stats[tile];
    for (int y = ty * TILE; y < (ty + 1) * TILE && y < H; y++) {
        for (int x = tx * TILE; x < (tx + 1) * TILE && x < W; x++) {
            size_t pix = (size_t)y * (size_t)W + (size_t)x;
            for (int j = r->spp_done; j < r->spp_done + r->pass_n; j++) {
                lr_ref_rng rng;
                lr_ref_rng_seed(&rng, r->d.seed, ((uint64_t)pix << 32) | (uint64_t)j);
                /* Box filter: a uniform point in the pixel; rows top to bottom. */
                double sx = 2.0 * ((double)x + lr_ref_rng_uniform(&rng)) / W - 1.0;
                double sy = 1.0 - 2.0 * ((double)y + lr_ref_rng_uniform(&rng)) / H;
                const lr_ref_pinhole *p = &r->pin;
                lr_vec3 dir = lr_v3_normalize(lr_v3_add(
                    p->f, lr_v3_add(lr_v3_scale(p->r, sx * p->tx), lr_v3_scale(p->u, sy * p->ty))));
                double L[3] = {0.0, 0.0, 0.0};
                lr_ref_radiance(r->s, p->c, dir, p->medium, &rng, st, L);
                if (!(isfinite(L[0]) && isfinite(L[1]) && isfinite(L[2]))) {
                    st->nonfinite++;
                    continue; /* counted; the sample adds zero */
                }
                for (int b = 0; b < 3; b++) {
                    r->sum[3 * pix + b] += L[b];
                    r->sum2[3 * pix + b] += L[b] * L[b];
                }
            }
        }
    }
}

static void trace_batch(int batch, void *user)
{
    lr_ref_render *r = user;
    uint64_t n = LT_PER_PIXEL * (uint64_t)r->d.width * (uint64_t)r->d.height;
    uint64_t first = (uint64_t)batch * LT_BATCH;
    uint64_t count = first + LT_BATCH <= n ? LT_BATCH : n - first;
    r->lt_splats[batch].n = 0;
    lr_ref_light_trace(r->s, &r->pin, r->d.seed, r->lt_j, first, count, &r->lt_splats[batch],
                       &r->lt_stats[batch]);
}

/* Light tracing of sample index j: one more estimate of the light-traced image. */
static int light_trace_sample(lr_ref_render *r, uint64_t j, lr_err *e)
{
    size_t n = (size_t)r->d.width * (size_t)r->d.height * 3;
    double inv = 1.0 / (LT_PER_PIXEL * (double)r->d.width * (double)r->d.height); /* 1/photons */
    r->lt_j = j;
    int rc = lr_ref_parallel(r->lt_batches, r->d.threads, trace_batch, r, e);
    if (rc)
        return rc;
    memset(r->lt_cur, 0, n * sizeof *r->lt_cur);
    for (int b = 0; b < r->lt_batches; b++) {
        const lr_ref_splats *sp = &r->lt_splats[b];
        if (sp->oom)
            return lr_err_set(e, LR_ENOMEM, "reference: out of memory for light-tracing splats");
        for (size_t k = 0; k < sp->n; k++)
            for (int c = 0; c < 3; c++)
                r->lt_cur[3 * (size_t)sp->v[k].pixel + (size_t)c] += sp->v[k].rgb[c] * inv;
    }
    for (size_t i = 0; i < n; i++) {
        double x = r->lt_cur[i];
        if (!isfinite(x)) {
            r->lt_stats[0].nonfinite++;
            continue;
        }
        r->lt_sum[i] += x;
        r->lt_sum2[i] += x * x;
    }
    return LR_OK;
}

int lr_ref_render_pass(lr_ref_render *r, lr_err *e)
{
    int left = r->d.spp - r->spp_done;
    if (left <= 0)
        return LR_OK;
    r->pass_n = left < r->d.spp_per_pass ? left : r->d.spp_per_pass;
    int rc = lr_ref_parallel(r->tiles_x * r->tiles_y, r->d.threads, render_tile, r, e);
    for (int j = r->spp_done; !rc && r->trace_lights && j < r->spp_done + r->pass_n; j++)
        rc = light_trace_sample(r, (uint64_t)j, e);
    if (rc)
        return rc;
    r->spp_done += r->pass_n;
    r->stats = (lr_ref_stats){0};
    for (int t = 0; t < r->tiles_x * r->tiles_y; t++)
        lr_ref_stats_add(&r->stats, &r->tile_stats[t]);
    for (int b = 0; r->trace_lights && b < r->lt_batches; b++)
        lr_ref_stats_add(&r->stats, &r->lt_stats[b]);
    return LR_OK;
}

int lr_ref_render_spp_done(const lr_ref_render *r)
{
    return r->spp_done;
}

int lr_ref_render_spp_total(const lr_ref_render *r)
{
    return r->d.spp;
}

const lr_ref_stats *lr_ref_render_stats(const lr_ref_render *r)
{
    return &r->stats;
}

int lr_ref_render_run(lr_ref_render *r, void (*progress)(const lr_ref_render *r, void *user),
                      void *user, lr_err *e)
{
    while (r->spp_done < r->d.spp) {
        int rc = lr_ref_render_pass(r, e);
        if (rc)
            return rc;
        if (progress)
            progress(r, user);
    }
    return LR_OK;
}

static int image_alloc(const lr_ref_render *r, lr_ref_image *out, lr_err *e)
{
    out->width = r->d.width;
    out->height = r->d.height;
    out->rgb = malloc((size_t)out->width * (size_t)out->height * 3 * sizeof *out->rgb);
    if (!out->rgb)
        return lr_err_set(e, LR_ENOMEM, "reference: out of memory for an image");
    return LR_OK;
}

int lr_ref_render_mean(const lr_ref_render *r, lr_ref_image *out, lr_err *e)
{
    int rc = image_alloc(r, out, e);
    if (rc)
        return rc;
    size_t n = (size_t)out->width * (size_t)out->height * 3;
    double k = r->spp_done > 0 ? 1.0 / r->spp_done : 0.0;
    for (size_t i = 0; i < n; i++)
        out->rgb[i] = (float)((r->sum[i] + (r->trace_lights ? r->lt_sum[i] : 0.0)) * k);
    return LR_OK;
}

int lr_ref_render_variance(const lr_ref_render *r, lr_ref_image *out, lr_err *e)
{
    int rc = image_alloc(r, out, e);
    if (rc)
        return rc;
    size_t n = (size_t)out->width * (size_t)out->height * 3;
    double N = r->spp_done;
    for (size_t i = 0; i < n; i++) {
        /* Unbiased sample variance of the per-sample values, divided by N: the variance of
         * the pixel's mean; the same for the per-sample light-traced estimates, and the two
         * add (independent). Undefined (reported as 0) below two samples. */
        double v = 0.0;
        if (N > 1.0) {
            double mean = r->sum[i] / N;
            v = fmax(0.0, (r->sum2[i] - N * mean * mean) / (N - 1.0)) / N;
            if (r->trace_lights) {
                mean = r->lt_sum[i] / N;
                v += fmax(0.0, (r->lt_sum2[i] - N * mean * mean) / (N - 1.0)) / N;
            }
        }
        out->rgb[i] = (float)v;
    }
    return LR_OK;
}

void lr_ref_image_free(lr_ref_image *img)
{
    if (img)
        lr_image_free(img);
}
