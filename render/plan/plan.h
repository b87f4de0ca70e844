/* lamprig — the planner: per object, the cheapest measured model and parameters (K, N, N_vpl,
 * map sizes) that meet the scene's quality budget, from measured speed/error tables, saying
 * what it chose; and what the scene does not need (docs/ARCHITECTURE.md "The planner",
 * render/plan/README.md).
 *
 * Three parts, pure C (no GL):
 *   table    the measured speed/error front: a CSV written by the bench sweep
 *            (build/bench/results.csv, committed as configs/bench/front.csv), one row per
 *            measured (scene, model, settings); columns are found by their header name.
 *   analysis what each object of a scene needs, from its geometry: whether any receiver
 *            sees it (else its VPLs light nothing), whether it is convex, how many radiosity
 *            maps cover its surface (Algorithm 1 of seed 003 composes a point from the maps
 *            that see it), and the features used to match a scene the table does not hold.
 *   plan     per object, the chosen row, its predicted error and time, and reasons; the
 *            scene-wide settings the renderer takes (one settings block for all objects).
 */
#ifndef LR_PLAN_H
#define LR_PLAN_H

#include <stdbool.h>
#include <stddef.h>

#include "render/base/err.h"
#include "render/scene/scene.h"

/* ---- The measured table --------------------------------------------------------------- */

#define LR_PLAN_TEXT_MAX 64

/* One measured setting. Errors are relative RMSE against the physical reference after
 * `frames` accumulation frames; optional columns absent from the file (or empty cells) are
 * NaN. */
typedef struct lr_plan_row {
    int line; /* in the CSV file, for messages */
    char scene[LR_PLAN_TEXT_MAX]; /* scene file base name ("candle") */
    char model[LR_PLAN_TEXT_MAX]; /* an lr_sss_model name (lr_sss_model_name) */
    char params[LR_PLAN_TEXT_MAX];
    double frame_ms;            /* median ms of one accumulation frame */
    double rel_rmse;            /* whole image */
    double rel_rmse_object, rel_rmse_receivers;
    int K, N, N_vpl, map_size, gbuffer_size, frames;
    bool vpl;
    double ms_gbuffer, ms_radiosity, ms_vpl, ms_compose; /* optional */
    double bias_object, bias_receivers, noise_object, noise_receivers; /* optional */
    int width, height; /* optional, 0 when absent */
    /* Optional: the bench's pixel filter (issue 12). s >= 2: the model was rendered at s x s
     * the size and box-filtered like the physical reference's pixels, so the error columns
     * are the fair ones; 0 (absent) or 1: pixel-centre samples (a table from before issue
     * 12, whose errors are biased high where a light pool is a few pixels tall). */
    int supersample;
    /* Optional: render.lpv of the row (the light-propagation volume's cells per axis, 0 or
     * absent: off), and the volume's build on the first frame, ms (its pass, counted once in
     * the time to converge). */
    int lpv;
    double ms_lpv;
    /* Not a column of this table: the time from a material edit to the next shown frame for
     * the row's scene and model (models.csv, `lamprig-bench models`: a σ edit at its fixed
     * settings, the model's own rebuild included: translucent radiosity's F and S, the
     * grid's re-solve); NaN when not measured. */
    double ms_change;
    /* Optional (issue 12, what a person sees; NaN when absent): the setting's converged image
     * against the reference: the median |ln ratio| over object pixels, the same between two
     * references (the floor), and the worst region-band power ratio beyond its 2 se
     * (lr_eval_ratio_excess). */
    double median_ln_object, median_ln_floor, band_excess;
    /* LR_PLAN_UNDER_* bits: the columns whose cell read "<FLOOR" (the bench's debiased error
     * came out under the reference's noise, tools/bench): the field holds that floor, an
     * upper bound on the error ("at most the floor", never 0). */
    unsigned under_floor;
} lr_plan_row;

enum {
    LR_PLAN_UNDER_REL_RMSE = 1u << 0,
    LR_PLAN_UNDER_REL_RMSE_OBJECT = 1u << 1,
    LR_PLAN_UNDER_REL_RMSE_RECEIVERS = 1u << 2,
    LR_PLAN_UNDER_BIAS_OBJECT = 1u << 3,
    LR_PLAN_UNDER_BIAS_RECEIVERS = 1u << 4,
};

typedef struct lr_plan_table lr_plan_table;

/* The parts of a row's predicted error, each a relative error (NaN where the table lacks it):
 * - rmse: sqrt(bias^2 + noise^2) from the bench's split, the larger of objects and receivers;
 *   rel_rmse for rows without the split;
 * - median: the typical object pixel's |ln ratio| beyond the references' own,
 *   max(0, median_ln_object - median_ln_floor) (the whole median without a floor);
 * - band: band_excess, the worst region-band's power off by more than the reference's 2 se.
 * A bias under the reference's noise ("<FLOOR" in the table) counts as its floor: the error
 * it predicts is then at most that (rmse_at_most), and never 0. */
typedef struct lr_plan_error_parts {
    double rmse, median, band;
    /* The rmse part is a noise floor (lr_plan_row.under_floor): the error is at most it. */
    bool rmse_at_most;
} lr_plan_error_parts;
lr_plan_error_parts lr_plan_row_error_parts(const lr_plan_row *r);

/* The error the planner predicts for a row: the largest of its parts. The RMSE alone is
 * decided by a few bright pixels (the candles' six rim pixels by the flame are 94 % of
 * candle_spot's squared error), so a model that renders a whole wall at 0.7 of its light can
 * rank first on it; the median and the worst band are what a person sees (issue 12's
 * targets), and none of the three may be over the budget. Rows without the median and band
 * columns (tables from before them, hand-made tables) predict the RMSE part alone. */
double lr_plan_row_error(const lr_plan_row *r);

/* A region a person sees as unlit: the worst region-band power ratio R at a tenth of the
 * reference's light or less, beyond its noise (band_excess = max(0, |ln R| - 2 se / R) over
 * ln 10). Why a tenth: the eye's response to luminance is about logarithmic (lightness
 * L* ~ Y^(1/3) puts Y = 0.1 at L* 38 against 100, the step from a lit wall to one in shadow),
 * so a region at 0.1 of its light reads as not lit by the lamp, while the lit rows of the
 * committed table stay inside e^-1.8 = 0.17 (jar_candle's sh_translucency) and the VPL-free
 * row that drops the wall's bounce reads e^-8.03. band_excess holds |ln R| only, so a region
 * ten times too bright counts too: it is as far from what the lamp gives. */
#define LR_PLAN_DARK_LN 2.302585092994046 /* ln 10 */

/* Whether the row leaves a region dark: band_excess inf (a region with no light at all, the
 * wall of a row without VPLs) or above LR_PLAN_DARK_LN. Such a row never wins while a
 * receiver sees the object and never meets a budget, a frame-only one included. */
bool lr_plan_row_dark(const lr_plan_row *r);

/* Parses CSV text. The first line is the header; columns are looked up by name, in any order;
 * unknown columns are ignored. Required: scene, model, frame_ms, rel_rmse, K, N, N_vpl,
 * map_size, gbuffer_size, frames, vpl. Errors name "NAME:LINE: column 'C': what" (a missing
 * column names line 1). Blank lines and lines starting with '#' are skipped. */
int lr_plan_table_parse(const char *text, size_t len, const char *name, lr_plan_table **out,
                        lr_err *e);
/* Reads a table file and merges the change costs (lr_plan_row.ms_change) of the models table
 * models.csv beside it, then of CONFIGS/bench/models.csv for the (scene, model) pairs that one
 * lacks; either may be missing. */
int lr_plan_table_load(const char *path, lr_plan_table **out, lr_err *e);
/* Merges models-table CSV text (columns scene, model, material_ms; others ignored) into the
 * rows of t that have no change cost yet. Errors name "NAME:LINE: column 'C'". */
int lr_plan_table_merge_changes(lr_plan_table *t, const char *text, size_t len, const char *name,
                                lr_err *e);
void lr_plan_table_destroy(lr_plan_table *t);
int lr_plan_table_count(const lr_plan_table *t);
const lr_plan_row *lr_plan_table_row(const lr_plan_table *t, int i);
const char *lr_plan_table_name(const lr_plan_table *t);
/* Whether any row measures `scene`. */
bool lr_plan_table_has_scene(const lr_plan_table *t, const char *scene);

/* The default table: ROOT/build/bench/results.csv when it exists and is at least as new as
 * CONFIGS/bench/front.csv (or that one is missing), else CONFIGS/bench/front.csv, where
 * CONFIGS is lr_configs_dir() and ROOT its parent (the source tree). Writes the path to buf
 * and a short reason ("newest bench run" | "committed front") to *why. LR_EIO when neither
 * exists. */
int lr_plan_default_table(char *buf, size_t cap, const char **why, lr_err *e);

/* ---- Scene analysis ------------------------------------------------------------------- */

#define LR_PLAN_MAX_OBJECTS 8
#define LR_PLAN_KMAX 32 /* the renderer's map limit */

typedef struct lr_plan_features {
    bool enclosed;   /* lights[0] lies inside the object's hull or material */
    bool shell;      /* thin wall: mean thickness 2 V / A below radius / 10, or open */
    bool convex;
    double size_tr;  /* bounding radius x mean sigma_tr: the object's size in diffusion lengths */
} lr_plan_features;

typedef struct lr_plan_analysis {
    lr_plan_features features;
    /* Receivers with an unoccluded line of sight to the object's surface, both sides facing
     * each other: a bit per receiver. 0: the object's VPLs light nothing. */
    unsigned receivers_seeing;
    int receivers_checked;
    /* Fraction of the surface (area samples) the first k maps see, k = 1..LR_PLAN_KMAX:
     * coverage[k-1]. A point is seen by map k when its normal faces d_k (n.d_k > 0.1) and the
     * ray toward d_k leaves the object without a hit (the map's depth test). */
    double coverage[LR_PLAN_KMAX];
    /* The fewest maps whose coverage is within 0.2 % (2 of the 1024 samples:
     * sampling noise, not a hole) of what all LR_PLAN_KMAX maps see. */
    int K_cover;
    double convex_violation_mm; /* largest distance of a vertex outside a face plane */
} lr_plan_analysis;

/* Analyses object `index` of the scene. Deterministic (fixed quasi-random samples). */
int lr_plan_analyze(const lr_scene *s, int index, lr_plan_analysis *out, lr_err *e);
/* The features alone (no sampling): for matching scenes. */
void lr_plan_features_of(const lr_scene *s, int index, lr_plan_features *out);
/* The one feature that depends on the material: bounding radius x mean sigma_tr. */
double lr_plan_size_tr(const lr_scene_object *o);
/* All vertices on the inner side of every face plane, within tol (mm); closed meshes only
 * (an open surface is a shell, never convex). *violation receives the largest distance of a
 * vertex beyond a face plane (within tol of 0 when convex; 0 for an open mesh). */
bool lr_plan_mesh_convex(const lr_mesh *m, bool closed, double tol, double *violation);

#define LR_PLAN_REASONS 10
#define LR_PLAN_REASON_MAX 320

/* ---- The light transport a scene needs ----------------------------------------------- */

/* Three render settings carry light paths beyond seed 003's (issue 12), each off by default
 * (each costs time; render/bounce, render/openings, render/README.md "VPL visibility"). The
 * planner turns one on where the scene's geometry shows the path matters and the scene does
 * not set it itself (lr_scene_render_given; the file's or --set's value always stays). */
enum lr_plan_transport_kind {
    LR_PLAN_RECEIVER_BOUNCE, /* render.receiver_bounce: receivers that face each other or an
                              * object exchange light */
    LR_PLAN_OPENING_LIGHT,   /* render.opening_light: an object with inner faces (where its
                              * VPLs do not stand) sends light out through its openings */
    LR_PLAN_VPL_VISIBILITY,  /* render.vpl_visibility: the objects block a share of the VPLs'
                              * light on the receivers (a light in a deep pool: its VPLs on
                              * the pool would light the wall through the rim) */
    LR_PLAN_TRANSPORT_COUNT
};

/* Inner faces at least this share of an object's area (lr_openings_inner_fraction): its
 * openings' light is worth its pass. The candles' pools give 0, the jar's deep pool 0.16,
 * the shades and the votive 0.4-0.5. */
#define LR_PLAN_INNER_MIN 0.01
/* The objects block at least this share of the VPLs' light on the receivers: VPL
 * visibility is worth its march. The candles (8 mm pool, flame 3 mm below the rim) 0.03,
 * the jar (35 mm pool) 0.16, the shades and the votive under 0.01; a convex object alone 0
 * (a segment leaving a convex body never re-enters it). */
#define LR_PLAN_BLOCKED_MIN 0.05

typedef struct lr_plan_transport {
    bool needed[LR_PLAN_TRANSPORT_COUNT]; /* the geometry shows the path matters */
    bool given[LR_PLAN_TRANSPORT_COUNT];  /* the scene sets it: its value stays */
    bool on[LR_PLAN_TRANSPORT_COUNT];     /* what applying turns on: needed, not given, off */
    double inner_fraction; /* the largest lr_openings_inner_fraction of an eligible object */
    double vpl_blocked;    /* the share of the VPLs' light on the receivers the objects block */
    char why[LR_PLAN_TRANSPORT_COUNT][LR_PLAN_REASON_MAX];
} lr_plan_transport;

/* The render key of each kind ("receiver_bounce", ...). */
const char *lr_plan_transport_key(enum lr_plan_transport_kind k);

/* Decides, from the geometry, which paths scene s needs with each object i rendered by
 * models[i] (NULL: the scene's own models): none without a point or spot light or a plane
 * receiver, or with render.lpv (its volumes carry the receivers' light); the bounce and the
 * openings' light not with translucent radiosity (its F has the receivers); VPL visibility
 * from LR_PLAN_VPL_SAMPLES VPLs per object (lr_vpl_place) against 16 x 16 points per
 * plane receiver, each VPL weighted by the lights' irradiance at it ignoring the body (light
 * leaves the wax near where it entered), each pair by the VPL kernel's cos cos / d^2.
 * Deterministic. LR_ENOMEM only. */
int lr_plan_transport_decide(const lr_scene *s, const enum lr_sss_model *models,
                             lr_plan_transport *out, lr_err *e);
/* Sets render.KEY = true for each kind t->on says, ORing dirty flags. */
int lr_plan_transport_apply(const lr_plan_transport *t, lr_scene *s, unsigned *dirty,
                            lr_err *e);
/* "plan: SCENE: transport: receiver_bounce on (why); opening_light kept (the scene sets it);
 * vpl_visibility not needed (why)\n". Returns the length it needed, without the NUL. */
size_t lr_plan_transport_format(const lr_plan_transport *t, const char *scene, char *buf,
                                size_t cap);

#define LR_PLAN_VPL_SAMPLES 128

/* ---- The plan --------------------------------------------------------------------------- */

typedef struct lr_plan_budget {
    double max_error; /* relative RMSE; 0: none */
    double frame_ms;  /* ms per accumulation frame; 0: none */
    /* Longest wait, ms, from a material change (a preset button, a translucency knob) to the
     * next frame: models whose measured change cost (lr_plan_row.ms_change) is over it are
     * left out while any other model remains; 0: none. Not a budget by itself. */
    double change_ms;
    /* ms from a change to the converged image: the row's ms_gbuffer + frames x frame_ms
     * (lr_plan_choice.predicted_converge_ms), what a designer waits after turning a control in
     * the rig; 0: none. */
    double converge_ms;
} lr_plan_budget;


typedef struct lr_plan_choice {
    char object[LR_SCENE_NAME_MAX];
    char table_scene[LR_PLAN_TEXT_MAX]; /* the measured scene the rows come from */
    bool scene_matched;                 /* the scene itself is in the table */
    lr_plan_row row;                    /* the chosen measured row */
    bool vpl;                           /* VPL pass for this object */
    double predicted_error;             /* lr_plan_row_error of the row */
    double predicted_frame_ms;          /* the row's frame_ms (less ms_vpl when VPLs are cut) */
    double predicted_converge_ms;       /* ms_gbuffer (0 when not measured) + frames x
                                         * predicted_frame_ms */
    bool feasible;                      /* meets every budget given */
    lr_plan_analysis analysis;
    int nreasons;
    char reasons[LR_PLAN_REASONS][LR_PLAN_REASON_MAX];
} lr_plan_choice;

typedef struct lr_plan {
    char scene[LR_SCENE_NAME_MAX];
    lr_plan_budget budget;
    int nobjects;
    lr_plan_choice objects[LR_PLAN_MAX_OBJECTS];
    /* What the renderer takes (one settings block for every object): the largest K, N,
     * N_vpl, map and G-buffer sizes and frames of the choices; VPLs off only when no object
     * needs them. */
    lr_render_settings settings;
    bool vpl;
    bool feasible; /* every object's choice meets the budget */
    /* The light transport the scene needs with the chosen models; lr_plan_apply and
     * lr_plan_apply_models turn on what it says. */
    lr_plan_transport transport;
} lr_plan;

/* Models the planner may choose: bit LR_PLAN_MODEL_BIT(m) for each enum lr_sss_model m
 * (objects[i].model). The default is every model the renderer runs; an object that cannot
 * take a model (lr_scene_object_model_unmet: the multipole without thickness_mm) skips its
 * rows. `lamprig plan --models directional_dipole,multipole` restricts the choice. */
#define LR_PLAN_MODEL_BIT(m) (1u << (unsigned)(m))
#define LR_PLAN_MODEL_DIRECTIONAL LR_PLAN_MODEL_BIT(LR_SSS_DIRECTIONAL_DIPOLE)
#define LR_PLAN_MODEL_STANDARD LR_PLAN_MODEL_BIT(LR_SSS_STANDARD_DIPOLE)
#define LR_PLAN_MODEL_ALL (LR_PLAN_MODEL_BIT(LR_SSS_MODEL_COUNT) - 1u)

typedef struct lr_plan_options {
    /* Where the scenes the table names are found, to match a scene the table lacks by
     * features: CONFIGS/scenes/NAME.json. NULL: lr_configs_dir(). */
    const char *configs_dir;
    unsigned models; /* lr_plan_models; 0: LR_PLAN_MODEL_ALL */
} lr_plan_options;

/* Chooses, per object, among the rows of the scene (or of the measured scene nearest by
 * features when the table has no row for it):
 *   max_error only: the row with error <= max_error that converges soonest
 *                   (ms_gbuffer + frames x frame_ms), ties to the lower error;
 *   frame_ms or converge_ms only (or both, no max_error): the lowest error with frame_ms
 *                   and time to converge within the budget, ties to the sooner converging;
 *   max_error and a time: the soonest converging row meeting all; none: infeasible, the row
 *                   nearest to all (smallest max(error / max_error, frame_ms / frame budget,
 *                   converge / converge budget)), said in the reasons;
 *   none:           LR_EINVAL (no budget to plan for).
 * Rows with fewer maps than the object's K_cover are left out (the bench measures one view;
 * coverage must hold for every view). VPLs are cut for an object no receiver sees.
 * LR_EINVAL when no row is usable. */
int lr_plan_create(const lr_scene *s, const lr_plan_table *t, const lr_plan_budget *b,
                   const lr_plan_options *opt, lr_plan *out, lr_err *e);

/* The budget of a scene's "quality" block; false when it sets none (no max_error, frame_ms
 * or converge_ms). */
bool lr_plan_budget_from_scene(const lr_scene *s, lr_plan_budget *out);
/* The budget of a command line (`lamprig plan --max-error/--frame-ms/--converge-ms/
 * --change-ms`: fields > 0 given, 0 not) or a rig config's `budget` over the scene's: a
 * max_error, frame_ms or converge_ms given replaces the scene's three (the budget's kind is
 * the one given), change_ms given replaces the scene's, and what is not given is the scene's.
 * False when the result has none of max_error, frame_ms and converge_ms. */
bool lr_plan_budget_resolve(const lr_scene *s, const lr_plan_budget *given, lr_plan_budget *out);

/* Applies plan->settings to the scene through lr_scene_set (render.K, N, N_vpl, map_size,
 * gbuffer_size, frames, lpv) and each object's chosen model (objects[i].model), ORing dirty
 * flags. */
int lr_plan_apply(const lr_plan *p, lr_scene *s, unsigned *dirty, lr_err *e);
/* Each object's chosen model alone (the scene's render settings stay): what `lamprig render
 * --plan-models` and the bench's "shipped" setting render. */
int lr_plan_apply_models(const lr_plan *p, lr_scene *s, unsigned *dirty, lr_err *e);

/* One line per object, "plan: OBJECT: MODEL K=.. N=.. N_vpl=.. map=.. gbuffer=.. frames=..
 * vpl=on|off, error 0.05, 150 ms/frame, converged in 4.8 s[ [INFEASIBLE]] (reason; ...)",
 * then the scene line (budget met or NOT MET, the settings applied, and that no pass runs
 * after the planned frames until something changes); written to buf (truncated to cap,
 * which may be 0). Returns the length it needed, without the NUL. */
size_t lr_plan_format(const lr_plan *p, char *buf, size_t cap);
/* The plan in one sentence, what `lamprig plan` and `lamprig render` print without
 * --verbose: "plan: SCENE: MODEL K k[ for OBJECT, ...], predicted error E, T ms a frame on
 * this table; the budget (error <= E, <= T ms a frame) holds" or "... is not reachable here,
 * the closest row shown (1.4x over; --verbose: why)". Error and frame time are the worst
 * object's. Returns the length it needed, without the NUL. */
size_t lr_plan_format_brief(const lr_plan *p, char *buf, size_t cap);
/* One object's line of lr_plan_format. */
size_t lr_plan_format_choice(const lr_plan_choice *c, char *buf, size_t cap);
/* The same as one JSON object. */
size_t lr_plan_format_json(const lr_plan *p, char *buf, size_t cap);

#endif
