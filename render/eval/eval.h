/* lamprig — the error of a rendering against a reference, and the speed-against-error front
 * (issue 6: `lamprig-bench sweep`, tools/bench/README.md, "Speed against error").
 *
 * Images here are linear RGB floats, rows top to bottom (lr_image / lr_ref_image layout).
 * Errors are relative RMSEs in linear light over a pixel mask, all three bands pooled:
 *
 *     rel_rmse(g, r) = sqrt( sum_mask sum_band (g - r)^2 / sum_mask sum_band r^2 )
 *
 * so one number weighs bright pixels as the eye-independent energy measure does, and a
 * uniform scale error s gives exactly |s - 1|.
 */
#ifndef LR_EVAL_H
#define LR_EVAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "render/base/err.h"
#include "render/gl/gl.h"
#include "render/renderer.h"
#include "render/scene/scene.h"

/* ---- metrics ------------------------------------------------------------------------------ */

/* rel_rmse above over the n pixels where mask is non-zero (mask NULL: all). NaN when the
 * reference is zero on the mask. */
double lr_eval_rel_rmse(const float *img, const float *ref, const unsigned char *mask, size_t n);
/* Relative standard error of a Monte Carlo image from its variance image (variance of each
 * pixel's mean): sqrt(sum var / sum ref^2) over the mask. It is what a perfect image's
 * rel_rmse against this reference would be, on average: E[rel_rmse^2] = true^2 + this^2. */
double lr_eval_rel_stderr(const float *var, const float *ref, const unsigned char *mask,
                          size_t n);
/* Sum of img over the mask and bands, divided by the same sum of ref (a units check: 1 when
 * the two agree in scale). NaN when ref sums to zero. */
double lr_eval_sum_ratio(const float *img, const float *ref, const unsigned char *mask,
                         size_t n);

/* ---- masks -------------------------------------------------------------------------------- */

/* Which pixels of the scene's camera image see an object and which a receiver, by casting
 * the camera ray of each pixel centre (lr_cpu_camera_ray) against every object's and
 * receiver's BVH: the nearest hit decides. Pixels that see neither are in neither mask, nor
 * are those whose ray meets an area light's surface first (the physical reference shows the
 * emitter there, the real-time renderer the surface behind it). */
typedef struct lr_eval_masks {
    int width, height;
    unsigned char *object, *receivers; /* width * height, 1 = in the mask */
    long object_px, receiver_px;
} lr_eval_masks;

int lr_eval_masks_create(const lr_scene *s, int width, int height, lr_eval_masks *out,
                         lr_err *e);
/* Whether an area light's surface (quad or disk, either side) lies in front of the nearest
 * object or receiver for any of 4 x 4 sub-pixel camera rays of pixel (x, y), py from the top:
 * the reference sees the emitter (or its dark back) over part of that pixel. */
bool lr_eval_emitter_in_pixel(const lr_scene *s, int width, int height, int x, int y);
void lr_eval_masks_free(lr_eval_masks *m);

/* ---- regions (issue 12: where the model loses light) ----------------------------------------
 *
 * Each pixel of the camera image, by its centre ray (as the masks), gets one region from the
 * scene's geometry ("up" is +z, as in every scene and the physical reference; an object's
 * axis is the line along up through its bounding-sphere centre, its radius r the largest
 * distance of a vertex from that axis; d is a receiver point's distance from the nearest
 * object's axis, in units of that object's r):
 *   object outer  a hit on an object facet whose plane supports the object's vertex set (all
 *                 vertices on its inner side, within 1e-3 r): the convex hull's surface, seen
 *                 from outside: a candle's sides and top rim, a shade's outer wall;
 *   object inner  any other object hit: a melt pool, a shade's or votive's inner wall;
 *   pool          a receiver point with d <= LR_EVAL_POOL_R: the light pool around the
 *                 object's footprint;
 *   table near    a receiver facing up (n.up >= 0.7), LR_EVAL_POOL_R < d <= LR_EVAL_NEAR_R;
 *   table far     the same with d > LR_EVAL_NEAR_R;
 *   wall          a vertical receiver (|n.up| < 0.3) outside the pool;
 *   other         any other receiver point (a ceiling, a slanted board). */
enum lr_eval_region {
    LR_EVAL_REGION_NONE = 0, /* background */
    LR_EVAL_REGION_OBJ_OUTER,
    LR_EVAL_REGION_OBJ_INNER,
    LR_EVAL_REGION_POOL,
    LR_EVAL_REGION_TABLE_NEAR,
    LR_EVAL_REGION_TABLE_FAR,
    LR_EVAL_REGION_WALL,
    LR_EVAL_REGION_OTHER,
    LR_EVAL_REGION_COUNT
};
#define LR_EVAL_POOL_R 2.0 /* the footprint and one more radius around it */
#define LR_EVAL_NEAR_R 4.0

typedef struct lr_eval_regions {
    int width, height;
    unsigned char *label; /* width * height, enum lr_eval_region */
    long count[LR_EVAL_REGION_COUNT];
} lr_eval_regions;

/* "object outer", "object inner", "pool", "table near", "table far", "wall", "other",
 * "background"; "?" out of range. */
const char *lr_eval_region_name(int region);
int lr_eval_regions_create(const lr_scene *s, int width, int height, lr_eval_regions *out,
                           lr_err *e);
void lr_eval_regions_free(lr_eval_regions *r);
/* mask[i] = (label[i] == region); returns the count. */
long lr_eval_regions_mask(const lr_eval_regions *r, int region, unsigned char *mask);

/* ---- power ratios and the median log ratio ------------------------------------------------ */

/* A power ratio model / reference over a mask, with its standard error from the reference's
 * variance image: R = sum g / sum r, and since the pixels' means are independent,
 * Var(sum r) = sum var, so (delta method, the model's own noise neglected: it is converged)
 *
 *     se = R sqrt(sum var) / sum r.
 *
 * A ratio "cannot be told from 1" when |R - 1| <= 2 se. NaN ratio and se when sum r <= 0. */
typedef struct lr_eval_ratio {
    double ratio, se;
} lr_eval_ratio;

/* Band b alone (0..2), or all three bands pooled (b = -1). */
lr_eval_ratio lr_eval_power_ratio(const float *img, const float *ref, const float *var,
                                  const unsigned char *mask, size_t n, int band);
/* |R - 1| > 2 se (finite values only). */
bool lr_eval_ratio_differs(lr_eval_ratio r);
/* How far R is from 1 beyond what the reference can tell, in log units: |ln R| less two
 * standard errors of ln R (2 se / R, the delta method), 0 when within them; NaN when R or se
 * is not finite or R <= 0 (a model that renders none of the light: +Inf). The planner ranks by
 * the worst region-band's excess (issue 12: "no band outside 0.85-1.15 where the reference
 * can tell"), which does not jump where a band crosses the 2 se line. */
double lr_eval_ratio_excess(lr_eval_ratio r);

/* The median over masked pixels of |ln(sum_b a / sum_b b)| (band sums per pixel). Pixels
 * where both sums are zero are skipped; where one of them is zero |ln| is +Inf and counts
 * (it ranks last). NaN when no pixel counts. */
double lr_eval_median_abs_log(const float *a, const float *b, const unsigned char *mask,
                              size_t n);

/* Two references of the same samples per pixel and independent seeds as one of twice the
 * samples: mean = (mean + mean2) / 2 and, where both variances are given, var = (var + var2)
 * / 4 (the variance of the mean of two independent estimates), over 3 n floats, in place.
 * The median |ln| between two such means is that between two single references over sqrt 2
 * (the log's standard deviation goes as 1/sqrt(spp); tests/base/test_eval.c checks it on
 * simulated references). */
void lr_eval_mean_references(float *mean, float *var, const float *mean2, const float *var2,
                             size_t n);

/* ---- Pareto front --------------------------------------------------------------------------- */

/* Marks on_front[i] for each point that no other point dominates (another point with
 * cost <= and error <=, one of them strictly). Points with a non-finite coordinate are never on
 * the front and dominate nothing. Of exact duplicates, the first is kept. Returns the number of
 * points on the front. */
int lr_eval_pareto(const double *cost, const double *error, int n, bool *on_front);

/* ---- results table (build/bench/results.csv) ------------------------------------------------- */

/* One setting of one scene after `frames` accumulated frames. */
typedef struct lr_eval_row {
    char scene[64]; /* scene file base name: "candle" */
    char model[32]; /* "directional_dipole" or "standard_dipole" */
    int K, N, N_vpl, map_size, gbuffer_size, frames;
    bool vpl;
    double frame_ms; /* median ms of one accumulation frame (radiosity + vpl + compose) */
    double rel_rmse, rel_rmse_object, rel_rmse_receivers; /* against the physical reference */
    double ms[LR_PASS_COUNT]; /* per pass: gbuffer (full update), radiosity, vpl, compose, blend
                               * (the CSV has the first LR_EVAL_CSV_PASSES: the blend is in
                               * frame_ms) */
    double bias_object, bias_receivers;   /* converged model vs physical reference */
    double noise_object, noise_receivers; /* `frames` frames vs converged model */
    /* The noise floor under each debiased error above: rel_rmse* have the reference's noise
     * taken out in quadrature (sqrt(rmse^2 - se^2)), the bias also the converged image's own,
     * and an error under that noise comes out 0, which says only that it is at most the
     * noise. The bench sets each to the noise taken out (sqrt(se^2 [+ its own^2])); the CSV
     * writes an error of 0 with a floor > 0 as "<FLOOR" (lr_eval_csv_print), never as 0.
     * 0 (a zero-initialised row): none known. */
    double floor_rel_rmse, floor_rel_rmse_object, floor_rel_rmse_receivers;
    double floor_bias_object, floor_bias_receivers;
    int width, height; /* where the errors are measured (the reference's size) */
    /* The pixel filter (issue 12): 1 = pixel centres; s >= 2 = rendered at s*width x
     * s*height and box-filtered, as the reference's pixels are (the times are then those of
     * the larger image). */
    int supersample;
    /* render.lpv of the run (0: off). The CSV gets two more columns, lpv and ms_lpv (the
     * volume's pass on a full update, ms[7]), when any row has it on; a table without the
     * volume keeps the columns above. */
    int lpv;
    /* What a person sees (issue 12), on the setting's converged image like the bias columns;
     * NaN when not measured. The CSV gets three more columns, median_ln_object,
     * median_ln_floor, band_excess, when any row has a median (> 0):
     * - median_ln_object: median |ln(model / reference)| over object pixels
     *   (lr_eval_median_abs_log), the typical pixel;
     * - median_ln_floor: the same between two independent references of the scene: what the
     *   reference's own noise gives;
     * - band_excess: the worst region-band power ratio's lr_eval_ratio_excess (regions of
     *   lr_eval_regions, bands R, G, B and all), 0 when every one is within its 2 se of 1. */
    double median_ln_object, median_ln_floor, band_excess;
} lr_eval_row;

/* Pass columns of the CSV: ms_gbuffer .. ms_compose. */
enum { LR_EVAL_CSV_PASSES = 4 };

/* The columns, in order (the planner reads them by name; the first seven are issue 6's). */
#define LR_EVAL_CSV_HEADER                                                                   \
    "scene,model,params,frame_ms,rel_rmse,rel_rmse_object,rel_rmse_receivers,K,N,N_vpl,"     \
    "map_size,gbuffer_size,frames,vpl,ms_gbuffer,ms_radiosity,ms_vpl,ms_compose,bias_object," \
    "bias_receivers,noise_object,noise_receivers,width,height,supersample"

/* "K=16 N=16 N_vpl=64 map=256 gbuf=256 frames=16 vpl=on". */
void lr_eval_row_params(const lr_eval_row *r, char *buf, size_t cap);
/* Writes the header and one line per row (NaN as "nan"). */
void lr_eval_csv_print(FILE *f, const lr_eval_row *rows, int n);
/* The same into path, atomically. */
int lr_eval_csv_write(const char *path, const lr_eval_row *rows, int n, lr_err *e);

/* ---- a GPU frame series ---------------------------------------------------------------------- */

/* Renders the scene at its current settings: three full updates (every pass; the maps restart
 * each time, so the third leaves one frame in the maps), then accumulation frames until
 * `converge_frames` are in the maps (render.frames is set to that). The HDR image is read
 * after each checkpoint frame count (ascending, each <= converge_frames) and at the end. */
typedef struct lr_eval_series_desc {
    lr_gl *gl;
    lr_scene *scene; /* render.frames is changed */
    int width, height;
    bool no_vpl;
    const int *checkpoints;
    int ncheck; /* at most 8 */
    int converge_frames;
    unsigned seed; /* lr_renderer_desc.seed: 0 = the renderer's default */
    /* 0 or 1: one sample at each pixel centre. s > 1: rendered at s*width x s*height and
     * box-filtered back (lr_image_downsample_box), so each pixel is the mean over its area as
     * in the physical reference; the frame times are then those of the larger image. */
    int supersample;
} lr_eval_series_desc;

typedef struct lr_eval_series {
    float *image[8];  /* per checkpoint, width x height, rows top to bottom */
    float *converged; /* after converge_frames */
    double ms[LR_PASS_COUNT]; /* medians: gbuffer over the full updates, the others over the
                               * accumulation frames */
    double frame_ms;  /* median total of the accumulation frames */
    int accum_frames; /* how many accumulation frames the medians are over */
} lr_eval_series;

int lr_eval_series_run(const lr_eval_series_desc *d, lr_eval_series *out, lr_err *e);
void lr_eval_series_free(lr_eval_series *s);

#endif
