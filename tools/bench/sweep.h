/* Section "sweep": speed against error for every scene in configs/scenes/ (issue 6 items 2
 * and 4; tools/bench/README.md, "Speed against error"). Internal to the bench; the metrics, masks,
 * Pareto
 * front, CSV and GPU frame series are in render/eval/eval.h (unit-tested there). */
#ifndef LRB_SWEEP_H_INCLUDED
#define LRB_SWEEP_H_INCLUDED

#include <stdbool.h>

#include "render/eval/eval.h"
#include "tools/bench/bench.h"

/* Bench resolution and the physical reference's sample count (see sweep.c for why). */
enum { LRB_SWEEP_W = 64, LRB_SWEEP_H = 48, LRB_SWEEP_SPP = 512 };
/* A scene whose reference is too noisy at LRB_SWEEP_SPP for the typical pixel (issue 12: the
 * candle's deep wax, where a few long walks carry most of a pixel) has one of more samples
 * committed: the reference is read from the cache at the most samples found, LRB_SWEEP_SPP_MAX
 * halved down to twice LRB_SWEEP_SPP, and only else rendered at LRB_SWEEP_SPP. */
enum { LRB_SWEEP_SPP_MAX = 16384 };
/* Where the references are cached (committed: generating them takes longer than the bench). */
#define LRB_SWEEP_REF_DIR "configs/bench/references"
/* The model's pixel filter (issue 12): every setting is rendered at LRB_SWEEP_SS times the
 * bench's size and box-filtered back, so its pixels are box integrals as the reference's are
 * (the chosen factor and its convergence check: tools/bench/README.md, "A fair bench").
 * LRB_SWEEP_SUPERSAMPLE=s overrides it; LRB_SWEEP_SS_CHECK=1,2,4,8 adds, per scene, the base
 * setting's converged bias at each listed factor. */
enum { LRB_SWEEP_SS = 4 };
/* The second, independent reference (the noise floor of median |ln ratio|): seed
 * LRB_SWEEP_SEED2, read from the cache at the most samples committed as the first (a measured
 * floor where both are), else at LRB_SWEEP_SPP or else LRB_SWEEP_SPP2 samples,
 * rendered at LRB_SWEEP_SPP2 when neither is cached (LRB_SWEEP_REF2=cached: left out instead). */
enum { LRB_SWEEP_SEED2 = 1, LRB_SWEEP_SPP2 = 128, LRB_SWEEP_SS_MAX = 6 };

/* One setting of the sweep: the base with at most one parameter changed. */
typedef struct lrb_setting {
    const char *label; /* "base", "K=4", ... */
    int K, N, N_vpl, map_size, gbuffer_size;
    bool vpl;
    /* An objects[].model name (lr_sss_model_name); NULL: the scene as it ships
     * (lrb_sweep_shipped), each object's model and render.N_vpl as the product renders the
     * scene file. */
    const char *model;
    int checkpoints[4], ncheck;
    int converge_frames;
} lrb_setting;

/* The settings (sweep_settings.c): the base, then one-at-a-time changes. Returns the count. */
int lrb_sweep_settings(lrb_setting *out, int cap);
/* The "shipped" setting: the base's K, N, map and G-buffer sizes and frame series, each
 * object's model as `lamprig render --plan-models` renders the scene (the committed table's
 * plan, configs/bench/front.csv, where the scene has a quality budget; else the file's) and
 * the file's render.N_vpl and other render settings (model NULL, N_vpl 0). Issue 12's figures
 * for what ships. */
lrb_setting lrb_sweep_shipped(void);

/* Issue 12's figures on one setting's converged, box-filtered image. */
typedef struct lrb_fair {
    double frame_ms; /* accumulation frame at the bench's size */
    double bias_object, bias_receivers, mal; /* mal: median |ln(model / reference)|, objects */
    lr_eval_ratio receiver_ratio;            /* all receiver pixels, pooled */
    lr_eval_ratio region_ratio[LR_EVAL_REGION_COUNT][4]; /* bands R, G, B, then all pooled */
} lrb_fair;

/* The scene as it ships (lrb_sweep_shipped) and its figures. */
typedef struct lrb_shipped {
    bool ok;
    char models[160]; /* "multipole" or "obj: model, obj: model" */
    int N_vpl;
    int K;            /* the file's render.K: the shipped setting keeps it */
    bool planned;     /* the models are the plan's */
    bool as_base;     /* the same models, N_vpl and K as the base: its figures, not run again */
    lrb_fair fig;
} lrb_shipped;

/* What one scene's sweep produced. */
typedef struct lrb_scene_result {
    char name[64];
    bool ok;
    char error[512];
    double ref_se_object, ref_se_receivers, ref_se_all; /* reference's relative standard error */
    bool ref_hit;
    int ref_spp; /* the reference's samples per pixel (LRB_SWEEP_SPP_MAX) */
    /* 2 when the second reference has as many samples as the first: the reference is then
     * their mean (ref_spp each, 2 ref_spp in all) and mal_floor what two such means differ
     * by (the two's floor / sqrt 2); else 1 (seed 0's alone). */
    int refs;
    double ref_s;
    long object_px, receiver_px;
    /* Units check (lrb_sweep_units); NaN when it failed. */
    double units_ratio, units_se;
    long units_px;
    /* GPU without VPLs (converged) / reference on the receiver pixels the light reaches
     * directly in the full scene: how much of the receivers' light the VPL-free model has. */
    double direct_ratio, direct_se;
    long direct_px;
    double sweep_s;
    int row0, nrows; /* the scene's rows in the table */
    /* Issue 12's fair figures, from the base setting's converged image (C frames). */
    int supersample;                                  /* the sweep's pixel filter */
    double centre_bias_object, centre_bias_receivers; /* pixel-centre samples: the old bench */
    lrb_fair fair; /* box-filtered: the base row's bias and the figures above */
    double mal_centre; /* median |ln(model / reference)| over object pixels */
    /* The same between the two references (seeds 0 and LRB_SWEEP_SEED2): raw, and scaled to
     * two references of ref_spp samples each (x sqrt(2 / (1 + spp / spp2))), or, when they
     * are averaged (refs 2), to two such means (raw / sqrt 2). NaN when the second reference
     * failed. */
    double mal_floor_raw, mal_floor;
    int ref2_spp;
    bool ref2_hit;
    long region_px[LR_EVAL_REGION_COUNT];
    lr_eval_ratio centre_receiver_ratio; /* all receiver pixels, pooled */
    lrb_shipped shipped; /* the scene as it ships (lrb_sweep_shipped) */
    /* LRB_SWEEP_SS_CHECK: base setting converged at each factor. */
    int nss, ss[LRB_SWEEP_SS_MAX];
    double ss_bias_object[LRB_SWEEP_SS_MAX], ss_bias_receivers[LRB_SWEEP_SS_MAX],
        ss_mal[LRB_SWEEP_SS_MAX];
} lrb_scene_result;


/* The supersampling factor of this run (LRB_SWEEP_SS or LRB_SWEEP_SUPERSAMPLE). */
int lrb_sweep_supersample(void);
/* Per scene, the fair figures as markdown: the summary table (one line per scene) and the
 * region table (sweep_fair.c). */
void lrb_sweep_fair_md(FILE *f, const lrb_scene_result *scenes, int nscenes);
/* The worst region-band power ratio's lr_eval_ratio_excess over the regions (background left
 * out) and bands R, G, B, all: the results' band_excess column; 0 when every one is within
 * two standard errors of 1, NaN when none is measured. */
double lrb_band_excess(const lr_eval_ratio rr[LR_EVAL_REGION_COUNT][4]);

/* Applies a setting to a scene (render.* and every object's model; for the shipped setting
 * the sizes and the plan's models, on a scene as loaded from its file). */
int lrb_sweep_apply(lr_scene *s, const lrb_setting *st, lr_err *e);
/* Whether any object of s can take the setting's model (lr_scene_object_model_unmet, and the
 * model's validity limits for the object's material: render/plan/limits.h); when none can,
 * why (cap bytes) says why and the sweep skips the setting for that scene. */
bool lrb_sweep_takes(const lr_scene *s, const lrb_setting *st, char *why, size_t cap);

/* Frame times of the base setting at 640x480 (sweep_table.c). */
typedef struct lrb_timing_640 {
    char scene[64];
    bool ok;
    int w, h;
    double pass_ms[LR_PASS_COUNT]; /* full update, median of 3 */
    double full_ms, accum_ms, dimmer_ms; /* medians of 3, 4, 5 frames */
} lrb_timing_640;
int lrb_sweep_time_640(lr_gl *gl, const char *name, lrb_timing_640 *out);

/* The units check (sweep_units.c): GPU / reference on the receivers lit by the light alone
 * (objects moved away, receivers' albedo 0.05), with the reference's standard error. */
int lrb_sweep_units(lr_gl *gl, const char *name, double *ratio, double *se, long *px);

/* Runs every setting on one scene, appending rows (at most cap in all). */
int lrb_sweep_scene(lr_gl *gl, const char *name, lr_eval_row *rows, int *nrows, int cap,
                    lrb_scene_result *res);

/* build/bench/pareto.png (sweep_plot.c). */
int lrb_sweep_plot(const char *path, const lr_eval_row *rows, int nrows,
                   const lrb_scene_result *scenes, int nscenes, lr_err *e);
/* build/bench/summary.md (sweep_summary.c); load[0..2] before and after the run. */
int lrb_sweep_summary(const char *path, const lr_eval_row *rows, int nrows,
                      const lrb_scene_result *scenes, int nscenes, const lrb_timing_640 *t640,
                      int nt640, const double load[2][3], double total_s, const char *renderer,
                      lr_err *e);

/* The 640x480 table (markdown) with the base rows' errors. */
void lrb_sweep_table_md(FILE *f, const lr_eval_row *rows, int nrows, const lrb_timing_640 *t,
                        int nt);

/* Time to reach a row's error: its frames times the accumulation frame time, ms. */
double lrb_sweep_time_ms(const lr_eval_row *r);

#endif
