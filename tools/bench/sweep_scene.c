/* One scene's sweep: the physical reference (cached), the masks, then every setting's GPU
 * frame series measured against it. */
#include "tools/bench/sweep.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "firmware/plan_scene.h"
#include "render/base/paths.h"
#include "render/image/image.h"
#include "render/plan/limits.h"
#include "render/reference/reference.h"

static int set_int(lr_scene *s, const char *key, int v, lr_err *e)
{
    char val[32];
    snprintf(val, sizeof val, "%d", v);
    return lr_scene_set(s, key, val, NULL, e);
}

/* Whether object o cannot take model m: its geometry (the multipole needs thickness_mm) or
 * the model's validity limits for its material (render/plan/limits.h: the grid on the lamp
 * shade's porcelain is 6 diffusion lengths per cell, where its solve diverges). *why: the
 * reason. The models section (models_bench.c) skips the same. */
static bool object_refuses(const lr_scene_object *o, enum lr_sss_model m, char *why,
                           size_t cap)
{
    const char *w = lr_scene_object_model_unmet(o, m);
    if (!w)
        w = lr_plan_model_limit(o, m, why, cap);
    if (w && w != why)
        snprintf(why, cap, "%s", w);
    return w != NULL;
}

/* The shipped setting's models: where the scene has a quality budget, the plan's model per
 * object from the committed table (lr_plan_scene with models_only, as `lamprig render
 * --plan-models` with a fresh build directory); else the file's, left as they are. */
static int apply_shipped_models(lr_scene *s, lr_err *e)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/bench/front.csv", lr_configs_dir());
    lr_plan_scene_result *res = calloc(1, sizeof *res);
    int rc = res ? lr_plan_scene(s, path, true, res, e)
                 : lr_err_set(e, LR_ENOMEM, "out of memory");
    free(res);
    return rc ? lr_err_prefix(e, "shipped setting: the plan") : LR_OK;
}

int lrb_sweep_apply(lr_scene *s, const lrb_setting *st, lr_err *e)
{
    int rc;
    /* K 0 (the shipped setting): the file's render.K, the maps the product renders with. */
    if ((st->K > 0 && (rc = set_int(s, "render.K", st->K, e))) ||
        (rc = set_int(s, "render.N", st->N, e)) ||
        (st->N_vpl > 0 && (rc = set_int(s, "render.N_vpl", st->N_vpl, e))) ||
        (rc = set_int(s, "render.map_size", st->map_size, e)) ||
        (rc = set_int(s, "render.gbuffer_size", st->gbuffer_size, e)))
        return rc;
    /* LRB_SWEEP_LPV=32: every setting with the light-propagation volume (render.lpv). */
    const char *lpv = getenv("LRB_SWEEP_LPV");
    if (lpv && *lpv && (rc = lr_scene_set(s, "render.lpv", lpv, NULL, e)))
        return rc;
    /* LRB_SWEEP_SET="render.vpl_visibility=true;render.lpv=32": scene assignments applied to
     * every setting (';'-separated, as --set takes them). */
    const char *sets = getenv("LRB_SWEEP_SET");
    for (const char *p = sets; p && *p;) {
        const char *q = strchr(p, ';');
        size_t n = q ? (size_t)(q - p) : strlen(p);
        char a[256];
        if (n >= sizeof a)
            return lr_err_set(e, LR_EINVAL, "LRB_SWEEP_SET: assignment longer than %zu", sizeof a);
        memcpy(a, p, n);
        a[n] = 0;
        if (n && (rc = lr_scene_set_assignment(s, a, NULL, e)))
            return lr_err_prefix(e, "LRB_SWEEP_SET");
        p = q ? q + 1 : p + n;
    }
    if (!st->model)
        return apply_shipped_models(s, e);
    /* The model is per object; the sweep switches every object that can take it (the
     * multipole needs thickness_mm; the grid a material within its validity limit);
     * lrb_sweep_takes says whether any can. */
    enum lr_sss_model m;
    if (!lr_sss_model_parse(st->model, &m))
        return lr_err_set(e, LR_EINVAL, "sweep setting %s: unknown model '%s'", st->label,
                          st->model);
    for (int k = 0; k < lr_scene_object_count(s); k++) {
        char why[160];
        if (object_refuses(lr_scene_object_at(s, k), m, why, sizeof why))
            continue;
        char key[64];
        snprintf(key, sizeof key, "objects[%d].model", k);
        if ((rc = lr_scene_set(s, key, st->model, NULL, e)))
            return rc;
    }
    /* A row measures what the plan would render with it: where the scene has a budget (it is
     * planned), the light transport the plan turns on for these models (render/plan/plan.h,
     * lr_plan_transport_decide; the file's and LRB_SWEEP_SET's values stay). */
    lr_plan_budget b;
    if (lr_plan_budget_from_scene(s, &b)) {
        lr_plan_transport t;
        if ((rc = lr_plan_transport_decide(s, NULL, &t, e)) ||
            (rc = lr_plan_transport_apply(&t, s, NULL, e)))
            return lr_err_prefix(e, "sweep setting %s", st->label);
    }
    return LR_OK;
}

bool lrb_sweep_takes(const lr_scene *s, const lrb_setting *st, char *why, size_t cap)
{
    enum lr_sss_model m;
    if (!st->model) /* the scene's own models */
        return true;
    snprintf(why, cap, "unknown model");
    if (!lr_sss_model_parse(st->model, &m))
        return false;
    for (int k = 0; k < lr_scene_object_count(s); k++)
        if (!object_refuses(lr_scene_object_at(s, k), m, why, cap))
            return true;
    return false;
}

/* The error against an unbiased Monte Carlo reference, with the reference's own noise taken
 * out: E[rmse^2] = true^2 + se^2 for independent reference noise of relative standard error
 * se (eval.h), so sqrt(max(0, rmse^2 - se^2)) estimates the error against the exact image. */
static double debias(double rmse, double se)
{
    if (!isfinite(rmse))
        return rmse;
    double v = rmse * rmse - (isfinite(se) ? se * se : 0.0);
    return v > 0.0 ? sqrt(v) : 0.0;
}

/* The noise debias takes out of an error: the floor an error of 0 is under (lr_eval_row's
 * floor_* columns, written "<FLOOR"). se2 may be NaN (none). */
static double noise_floor(double se, double se2)
{
    double v = (isfinite(se) ? se * se : 0.0) + (isfinite(se2) ? se2 * se2 : 0.0);
    return sqrt(v);
}

int lrb_sweep_supersample(void)
{
    const char *v = getenv("LRB_SWEEP_SUPERSAMPLE");
    int s = v ? atoi(v) : LRB_SWEEP_SS;
    return s >= 1 && s <= 16 ? s : LRB_SWEEP_SS;
}

/* LRB_SWEEP_SEED: the renderer's seed (0 or unset: its default), for a second run of the
 * same rows whose converged figures differ by the model's own residual noise alone. */
static unsigned sweep_seed(void)
{
    const char *v = getenv("LRB_SWEEP_SEED");
    long n = v ? strtol(v, NULL, 10) : 0;
    return n > 0 && n < 1000000000 ? (unsigned)n : 0u;
}

static int run_series(lr_gl *gl, lr_scene *s, const lrb_setting *st, int ss, lr_eval_series *ser,
                      lr_err *e)
{
    int rc = lrb_sweep_apply(s, st, e);
    if (!rc)
        rc = lr_eval_series_run(&(lr_eval_series_desc){.gl = gl, .scene = s, .width = LRB_SWEEP_W,
                                                       .height = LRB_SWEEP_H, .no_vpl = !st->vpl,
                                                       .checkpoints = st->checkpoints,
                                                       .ncheck = st->ncheck,
                                                       .converge_frames = st->converge_frames,
                                                       .supersample = ss,
                                                       .seed = sweep_seed()},
                                &ser[0], e);
    if (rc)
        lr_err_prefix(e, "setting %s (supersampled %d)", st->label, ss);
    return rc;
}

/* Bias of a series's converged image C against the physical reference: the reference's noise
 * (se) and C's own (its last checkpoint's noise about C, sigma^2 / F, scaled to sigma^2 / C)
 * taken out in quadrature; floor (may be NULL): the two noises together, objects then
 * receivers, under which a bias of 0 lies. */
static void series_bias(const lr_eval_series *ser, const lrb_setting *st, const float *ref,
                        const lr_eval_masks *m, const lrb_scene_result *res, double *bo,
                        double *br, double floor[2])
{
    const size_t n = (size_t)LRB_SWEEP_W * LRB_SWEEP_H;
    const float *C = ser->converged, *I = ser->image[st->ncheck - 1];
    const double Cf = st->converge_frames, Fl = st->checkpoints[st->ncheck - 1];
    const double k = sqrt(Fl / Cf) / sqrt(1.0 - Fl / Cf);
    const double own_o = lr_eval_rel_rmse(I, C, m->object, n) * k;
    const double own_r = lr_eval_rel_rmse(I, C, m->receivers, n) * k;
    *bo = debias(debias(lr_eval_rel_rmse(C, ref, m->object, n), res->ref_se_object), own_o);
    *br = debias(debias(lr_eval_rel_rmse(C, ref, m->receivers, n), res->ref_se_receivers), own_r);
    if (floor) {
        floor[0] = noise_floor(res->ref_se_object, own_o);
        floor[1] = noise_floor(res->ref_se_receivers, own_r);
    }
}

/* Whether the cache in dir holds the reference d describes. */
static bool cached(const lr_ref_scene *rs, const lr_ref_camera *cam, const char *dir,
                   const lr_ref_render_desc *d)
{
    char key[17], path[1200];
    lr_ref_cache_key(rs, cam, d, key);
    snprintf(path, sizeof path, "%s/%s.pfm", dir, key);
    return !access(path, R_OK);
}

/* The most samples at which the cache in dir holds d's reference, from LRB_SWEEP_SPP_MAX
 * halving down to LRB_SWEEP_SPP; 0 when none. */
static int most_cached(const lr_ref_scene *rs, const lr_ref_camera *cam, const char *dir,
                       lr_ref_render_desc d)
{
    for (d.spp = LRB_SWEEP_SPP_MAX; d.spp >= LRB_SWEEP_SPP; d.spp /= 2)
        if (cached(rs, cam, dir, &d))
            return d.spp;
    return 0;
}

/* The first reference (seed 0): from the cache at the most samples committed
 * (LRB_SWEEP_SPP_MAX), else at LRB_SWEEP_SPP, rendered and cached when not there. */
static int first_reference(const lr_ref_scene *rs, const lr_ref_camera *cam, const char *dir,
                           lr_ref_image *mean, lr_ref_image *var, int *spp, bool *hit,
                           lr_err *e)
{
    lr_ref_render_desc rd = {.width = LRB_SWEEP_W, .height = LRB_SWEEP_H, .spp = LRB_SWEEP_SPP};
    int most = most_cached(rs, cam, dir, rd);
    rd.spp = most ? most : LRB_SWEEP_SPP;
    *spp = rd.spp;
    return lr_ref_render_cached(rs, cam, &rd, dir, NULL, NULL,
                                &(const lr_warn_sink){lr_warn_stderr, "lamprig-bench"}, mean, var,
                                hit, e);
}

/* The second reference (seed LRB_SWEEP_SEED2): from the cache at the most samples committed
 * (as the first: so that the floor is measured between references of the same count where
 * both were rendered, not scaled), else at LRB_SWEEP_SPP, else at LRB_SWEEP_SPP2, else
 * rendered at LRB_SWEEP_SPP2 and cached beside the first. */
static int second_reference(const lr_ref_scene *rs, const lr_ref_camera *cam, const char *dir,
                            lr_ref_image *mean, lr_ref_image *var, int *spp, bool *hit,
                            lr_err *e)
{
    lr_ref_render_desc rd = {.width = LRB_SWEEP_W, .height = LRB_SWEEP_H,
                             .seed = LRB_SWEEP_SEED2, .spp = LRB_SWEEP_SPP};
    int most = most_cached(rs, cam, dir, rd);
    rd.spp = most ? most : LRB_SWEEP_SPP2;
    bool found = most || cached(rs, cam, dir, &rd);
    *spp = rd.spp;
    const char *mode = getenv("LRB_SWEEP_REF2");
    if (!found && mode && !strcmp(mode, "cached"))
        return lr_err_set(e, LR_EIO, "no seed-%d reference at %d or %d spp in %s "
                          "(LRB_SWEEP_REF2=cached)", LRB_SWEEP_SEED2, LRB_SWEEP_SPP,
                          LRB_SWEEP_SPP2, dir);
    return lr_ref_render_cached(rs, cam, &rd, dir, NULL, NULL,
                                &(const lr_warn_sink){lr_warn_stderr, "lamprig-bench"}, mean, var,
                                hit, e);
}

/* Two references of the same count (independent seeds) are one reference of twice the
 * samples: the model is judged against their mean, whose per-pixel variance is a quarter of
 * the two variances' sum, and the floor becomes what two such means would differ by: the
 * log's standard deviation, hence the median |ln| of a ratio, goes as 1/sqrt(spp), so the
 * floor measured between the two is divided by sqrt(2). Where a scene's references differ by
 * more than its model (the candle's lower body at 4096 spp: per-pixel SE 0.4-1), a single
 * reference's noise would decide its median. LRB_SWEEP_REF_SINGLE=1 keeps seed 0 alone. */
static void average_references(lr_ref_image *mean, lr_ref_image *var, const lr_ref_image *mean2,
                               const lr_ref_image *var2, size_t n, lrb_scene_result *res)
{
    lr_eval_mean_references(mean->rgb, var->rgb, mean2->rgb, var2->rgb, n);
    res->refs = 2;
    res->mal_floor /= sqrt(2.0);
}

/* Issue 12's figures on the base setting's converged, box-filtered image C: power ratios per
 * region and band with the reference's standard error, the receivers' power ratio and the
 * median |ln ratio| over object pixels. */
static void fair_figures(const float *C, const lr_ref_image *mean, const lr_ref_image *var,
                         const lr_eval_regions *rg, const lr_eval_masks *m, unsigned char *mask,
                         long region_px[LR_EVAL_REGION_COUNT], lrb_fair *out)
{
    const size_t n = (size_t)LRB_SWEEP_W * LRB_SWEEP_H;
    for (int r = 0; r < LR_EVAL_REGION_COUNT; r++) {
        region_px[r] = lr_eval_regions_mask(rg, r, mask);
        for (int b = 0; b < 4; b++)
            out->region_ratio[r][b] =
                lr_eval_power_ratio(C, mean->rgb, var->rgb, mask, n, b < 3 ? b : -1);
    }
    out->receiver_ratio = lr_eval_power_ratio(C, mean->rgb, var->rgb, m->receivers, n, -1);
    out->mal = lr_eval_median_abs_log(C, mean->rgb, m->object, n);
}

/* The models of a scene's objects as text: "multipole" when they agree, else "name: model"
 * per object; whether they, render.N_vpl and render.K are the base setting's. */
static void describe_models(const lr_scene *s, const lrb_setting *base, lrb_shipped *out)
{
    out->models[0] = 0;
    out->N_vpl = lr_scene_render(s)->N_vpl;
    out->K = lr_scene_render(s)->K;
    bool same = true, as_base = out->N_vpl == base->N_vpl && out->K == base->K;
    const int no = lr_scene_object_count(s);
    const char *m0 = no ? lr_sss_model_name(lr_scene_object_at(s, 0)->sss_model) : "";
    for (int k = 0; k < no; k++) {
        const char *mk = lr_sss_model_name(lr_scene_object_at(s, k)->sss_model);
        same &= !strcmp(mk, m0);
        as_base &= !strcmp(mk, base->model);
    }
    if (same)
        snprintf(out->models, sizeof out->models, "%s", m0);
    for (int k = 0; !same && k < no; k++) {
        size_t len = strlen(out->models);
        snprintf(out->models + len, sizeof out->models - len, "%s%s: %s", k ? ", " : "",
                 lr_scene_object_at(s, k)->name,
                 lr_sss_model_name(lr_scene_object_at(s, k)->sss_model));
    }
    out->as_base = as_base;
}


/* LRB_SWEEP_DUMP=dir (diagnosis, issue 12): writes dir/<scene>_<what>.pfm: the base setting's
 * converged fair image ("model"), the reference ("ref", "ref_var": the two references' mean
 * when they are averaged, refs 2), the second reference
 * ("ref2") and the region labels ("regions": enum lr_eval_region in every band). Best effort:
 * a failed write is reported on stderr and the sweep goes on. */
static void dump_pfm(const char *scene, const char *what, const float *rgb, int w, int h)
{
    const char *dir = getenv("LRB_SWEEP_DUMP");
    if (!dir || !*dir || !rgb)
        return;
    char path[1200];
    snprintf(path, sizeof path, "%s/%s_%s.pfm", dir, scene, what);
    lr_image img = {.width = w, .height = h, .rgb = (float *)rgb};
    lr_err e = {0};
    if (lr_image_write_pfm(path, &img, &e))
        fprintf(stderr, "bench sweep: dump: %s\n", e.msg);
}

static void dump_regions(const char *scene, const lr_eval_regions *rg, int w, int h)
{
    if (!getenv("LRB_SWEEP_DUMP"))
        return;
    float *lab = malloc((size_t)w * h * 3 * sizeof *lab);
    for (size_t i = 0; lab && i < (size_t)w * h; i++)
        lab[3 * i] = lab[3 * i + 1] = lab[3 * i + 2] = rg->label[i];
    dump_pfm(scene, "regions", lab, w, h);
    free(lab);
}

int lrb_sweep_scene(lr_gl *gl, const char *name, lr_eval_row *rows, int *nrows, int cap,
                    lrb_scene_result *res)
{
    *res = (lrb_scene_result){.units_ratio = NAN, .units_se = NAN, .direct_ratio = NAN,
                              .direct_se = NAN, .row0 = *nrows,
                              .supersample = lrb_sweep_supersample(),
                              .centre_bias_object = NAN, .centre_bias_receivers = NAN,
                              .fair = {.frame_ms = NAN, .bias_object = NAN,
                                       .bias_receivers = NAN, .mal = NAN,
                                       .receiver_ratio = {NAN, NAN}},
                              .mal_centre = NAN, .mal_floor_raw = NAN, .mal_floor = NAN,
                              .refs = 1,
                              .centre_receiver_ratio = {NAN, NAN}};
    res->shipped.fig = res->fair;
    snprintf(res->name, sizeof res->name, "%s", name);
    const int w = LRB_SWEEP_W, h = LRB_SWEEP_H;
    const size_t n = (size_t)w * h;
    char path[1024], refdir[1024];
    snprintf(path, sizeof path, "%s/scenes/%s.json", lr_configs_dir(), name);
    snprintf(refdir, sizeof refdir, "%s/bench/references", lr_configs_dir());
    lr_err e = {0};
    lr_scene *s = NULL;
    lr_ref_scene *rs = NULL;
    lr_ref_image mean = {0}, var = {0}, mean2 = {0}, var2 = {0};
    lr_eval_masks m = {0};
    lr_eval_regions rg = {0};
    unsigned char *both = NULL, *direct = NULL, *mask = NULL;
    const int ss = res->supersample;
    int rc;
    double t0 = lrb_now();
    if ((rc = lr_scene_load(path, &(const lr_warn_sink){lr_warn_stderr, "lamprig-bench"}, &s, &e)))
        goto done;
    lr_ref_camera cam;
    if ((rc = lr_ref_scene_from_scene(s, &rs, &cam, &e)))
        goto done;
    fprintf(stderr, "bench sweep: %s: reference %dx%d ...\n", name, w, h);
    if ((rc = first_reference(rs, &cam, refdir, &mean, &var, &res->ref_spp, &res->ref_hit, &e)))
        goto done;
    fprintf(stderr, "bench sweep: %s: reference at %d spp %s\n", name, res->ref_spp,
            res->ref_hit ? "from the cache" : "rendered");
    res->ref_s = lrb_now() - t0;
    if ((rc = second_reference(rs, &cam, refdir, &mean2, &var2, &res->ref2_spp, &res->ref2_hit,
                               &e))) {
        /* The floor is optional: the errors stand without it. */
        fprintf(stderr, "bench sweep: %s: second reference: %s\n", name, e.msg);
        e = (lr_err){0};
        rc = LR_OK;
    }
    if ((rc = lr_eval_masks_create(s, w, h, &m, &e)) ||
        (rc = lr_eval_regions_create(s, w, h, &rg, &e)))
        goto done;
    if (mean2.rgb) {
        /* Median |ln| of a ratio of two means scales with the standard deviation of the log,
         * which goes as 1/sqrt(spp): two references of spp and spp2 samples differ like two
         * of spp samples times sqrt((1/spp + 1/spp2) / (2/spp)). */
        res->mal_floor_raw = lr_eval_median_abs_log(mean.rgb, mean2.rgb, m.object, n);
        res->mal_floor = res->mal_floor_raw *
                         sqrt(2.0 / (1.0 + (double)res->ref_spp / res->ref2_spp));
        if (res->ref2_spp == res->ref_spp && !getenv("LRB_SWEEP_REF_SINGLE"))
            average_references(&mean, &var, &mean2, &var2, n, res);
    }
    both = malloc(n);
    direct = calloc(n, 1);
    mask = malloc(n);
    if (!both || !direct || !mask) {
        rc = lr_err_set(&e, LR_ENOMEM, "out of memory");
        goto done;
    }
    for (size_t i = 0; i < n; i++)
        both[i] = m.object[i] | m.receivers[i];
    res->object_px = m.object_px;
    res->receiver_px = m.receiver_px;
    res->ref_se_object = lr_eval_rel_stderr(var.rgb, mean.rgb, m.object, n);
    res->ref_se_receivers = lr_eval_rel_stderr(var.rgb, mean.rgb, m.receivers, n);
    res->ref_se_all = lr_eval_rel_stderr(var.rgb, mean.rgb, both, n);

    lrb_setting set[32];
    int nset = lrb_sweep_settings(set, 32);
    double t1 = lrb_now();
    for (int k = 0; k < nset; k++) {
        const lrb_setting *st = &set[k];
        /* LRB_SWEEP_SETTINGS=K=4,N=16 restricts the variants (the base always runs: the fair
         * figures come from it). */
        if (k && getenv("LRB_SWEEP_SETTINGS") && !lrb_listed(getenv("LRB_SWEEP_SETTINGS"),
                                                            st->label))
            continue;
        char why[160];
        if (!lrb_sweep_takes(s, st, why, sizeof why)) {
            fprintf(stderr, "lamprig-bench: sweep: %s: setting %s skipped: no object can take it (%s)\n",
                    lr_scene_name(s), st->label, why);
            continue;
        }
        lr_eval_series ser = {0};
        if ((rc = run_series(gl, s, st, ss, &ser, &e)))
            goto done;
        const float *C = ser.converged;
        const double Cf = st->converge_frames;
        /* Bias: converged model vs physical, without the reference's and the converged
         * image's own noise. */
        double bias_obj, bias_rec, bias_floor[2];
        series_bias(&ser, st, mean.rgb, &m, res, &bias_obj, &bias_rec, bias_floor);
        /* What a person sees on this setting's converged image (the rows' last columns). */
        lrb_fair seen = {0};
        fair_figures(C, &mean, &var, &rg, &m, mask, res->region_px, &seen);
        if (k == 0) { /* the base setting */
            res->fair = seen;
            res->fair.bias_object = bias_obj;
            res->fair.bias_receivers = bias_rec;
            res->fair.frame_ms = ser.frame_ms;
            dump_pfm(name, "model", C, w, h);
            dump_pfm(name, "ref", mean.rgb, w, h);
            dump_pfm(name, "ref_var", var.rgb, w, h);
            dump_pfm(name, "ref2", mean2.rgb, w, h);
            dump_regions(name, &rg, w, h);
        }
        for (int c = 0; c < st->ncheck && *nrows < cap; c++) {
            const float *I = ser.image[c];
            int F = st->checkpoints[c];
            /* The converged image contains the first F frames: Var(mean_F - mean_C) =
             * sigma^2 (1/F - 1/C), hence the factor to the noise about the model's mean. */
            double fix = 1.0 / sqrt(1.0 - F / Cf);
            lr_eval_row r = {
                .K = st->K, .N = st->N, .N_vpl = st->N_vpl, .map_size = st->map_size,
                .gbuffer_size = st->gbuffer_size, .frames = F, .vpl = st->vpl,
                .frame_ms = ser.frame_ms,
                .rel_rmse = debias(lr_eval_rel_rmse(I, mean.rgb, both, n), res->ref_se_all),
                .rel_rmse_object = debias(lr_eval_rel_rmse(I, mean.rgb, m.object, n),
                                          res->ref_se_object),
                .rel_rmse_receivers = debias(lr_eval_rel_rmse(I, mean.rgb, m.receivers, n),
                                             res->ref_se_receivers),
                .bias_object = bias_obj, .bias_receivers = bias_rec,
                .noise_object = lr_eval_rel_rmse(I, C, m.object, n) * fix,
                .noise_receivers = lr_eval_rel_rmse(I, C, m.receivers, n) * fix,
                /* Under its floor, an error reads "<FLOOR" in the table, not 0. */
                .floor_rel_rmse = noise_floor(res->ref_se_all, NAN),
                .floor_rel_rmse_object = noise_floor(res->ref_se_object, NAN),
                .floor_rel_rmse_receivers = noise_floor(res->ref_se_receivers, NAN),
                .floor_bias_object = bias_floor[0], .floor_bias_receivers = bias_floor[1],
                .width = w, .height = h, .supersample = ss,
                .median_ln_object = seen.mal, .median_ln_floor = res->mal_floor,
                .band_excess = lrb_band_excess(seen.region_ratio),
            };
            snprintf(r.scene, sizeof r.scene, "%s", name);
            snprintf(r.model, sizeof r.model, "%s", st->model);
            memcpy(r.ms, ser.ms, sizeof r.ms);
            r.lpv = lr_scene_render(s)->lpv;
            rows[(*nrows)++] = r;
        }
        /* On the VPL-free run: receiver pixels the light reaches directly (non-zero without
         * VPLs); the reference adds the emergent light and interreflection there. */
        if (!st->vpl) {
            double vs = 0.0, rs_sum = 0.0;
            for (size_t i = 0; i < n; i++) {
                direct[i] = m.receivers[i] && (C[3 * i] > 0.0f || C[3 * i + 1] > 0.0f ||
                                               C[3 * i + 2] > 0.0f);
                res->direct_px += direct[i];
                for (int b = 0; direct[i] && b < 3; b++)
                    vs += var.rgb[3 * i + b], rs_sum += mean.rgb[3 * i + b];
            }
            res->direct_ratio = lr_eval_sum_ratio(C, mean.rgb, direct, n);
            res->direct_se = rs_sum > 0.0 ? res->direct_ratio * sqrt(vs) / rs_sum : NAN;
        }
        fprintf(stderr, "bench sweep: %s %-10s frame %.1f ms, error after %d frames %.4f\n",
                name, st->label, ser.frame_ms, st->checkpoints[st->ncheck - 1],
                rows[*nrows - 1].rel_rmse);
        lr_eval_series_free(&ser);
    }
    /* The scene as it ships, from its file again (the settings above changed s). Where its
     * models, N_vpl and K are the base's, the base's figures are its own. LRB_SWEEP_SETTINGS
     * without "shipped" leaves it out. */
    if (!getenv("LRB_SWEEP_SETTINGS") || lrb_listed(getenv("LRB_SWEEP_SETTINGS"), "shipped")) {
        const lrb_setting sh = lrb_sweep_shipped();
        lrb_shipped *f = &res->shipped;
        lr_scene *s2 = NULL;
        lr_eval_series ser = {0};
        /* The same file again: its warnings were printed at the first load. */
        if ((rc = lr_scene_load(path, NULL, &s2, &e)) || (rc = lrb_sweep_apply(s2, &sh, &e))) {
            lr_scene_destroy(s2);
            goto done;
        }
        describe_models(s2, &set[0], f);
        f->planned = lr_plan_budget_from_scene(s2, &(lr_plan_budget){0});
        if (f->as_base) {
            f->fig = res->fair;
        } else if ((rc = run_series(gl, s2, &sh, ss, &ser, &e))) {
            lr_scene_destroy(s2);
            goto done;
        } else {
            long px[LR_EVAL_REGION_COUNT];
            series_bias(&ser, &sh, mean.rgb, &m, res, &f->fig.bias_object,
                        &f->fig.bias_receivers, NULL);
            fair_figures(ser.converged, &mean, &var, &rg, &m, mask, px, &f->fig);
            f->fig.frame_ms = ser.frame_ms;
        }
        f->ok = true;
        fprintf(stderr, "bench sweep: %s shipped (%s, K %d, N_vpl %d%s) bias %.4f / %.4f, "
                        "median |ln| %.4f\n",
                name, f->models, f->K, f->N_vpl, f->as_base ? ": the base's" : "",
                f->fig.bias_object,
                f->fig.bias_receivers, f->fig.mal);
        lr_eval_series_free(&ser);
        lr_scene_destroy(s2);
    }
    res->sweep_s = lrb_now() - t1;
    /* The old bench's figures for the same setting: pixel-centre samples (LRB_SWEEP_CENTRE=0
     * leaves them out, nan, to halve a diagnosis run). */
    const char *centre = getenv("LRB_SWEEP_CENTRE");
    if (!centre || strcmp(centre, "0")) {
        lr_eval_series ser = {0};
        if (ss == 1) {
            res->centre_bias_object = res->fair.bias_object;
            res->centre_bias_receivers = res->fair.bias_receivers;
        } else if ((rc = run_series(gl, s, &set[0], 1, &ser, &e)))
            goto done;
        const float *C = ss == 1 ? NULL : ser.converged;
        if (C) {
            series_bias(&ser, &set[0], mean.rgb, &m, res, &res->centre_bias_object,
                        &res->centre_bias_receivers, NULL);
            res->mal_centre = lr_eval_median_abs_log(C, mean.rgb, m.object, n);
            res->centre_receiver_ratio =
                lr_eval_power_ratio(C, mean.rgb, var.rgb, m.receivers, n, -1);
        } else {
            res->mal_centre = res->fair.mal;
            res->centre_receiver_ratio = res->fair.receiver_ratio;
        }
        lr_eval_series_free(&ser);
    }
    /* LRB_SWEEP_SS_CHECK=1,2,4,8: how the base setting's bias converges with the factor. */
    for (const char *p = getenv("LRB_SWEEP_SS_CHECK"); p && *p && res->nss < LRB_SWEEP_SS_MAX;) {
        int f = atoi(p);
        p += strcspn(p, ",");
        p += *p == ',';
        if (f < 1 || f > 16)
            continue;
        lr_eval_series ser = {0};
        if ((rc = run_series(gl, s, &set[0], f, &ser, &e)))
            goto done;
        int j = res->nss++;
        res->ss[j] = f;
        series_bias(&ser, &set[0], mean.rgb, &m, res, &res->ss_bias_object[j],
                    &res->ss_bias_receivers[j], NULL);
        res->ss_mal[j] = lr_eval_median_abs_log(ser.converged, mean.rgb, m.object, n);
        fprintf(stderr, "bench sweep: %s supersampled %dx%d: bias %.4f / %.4f, median |ln| %.4f\n",
                name, f, f, res->ss_bias_object[j], res->ss_bias_receivers[j], res->ss_mal[j]);
        lr_eval_series_free(&ser);
    }
    lrb_sweep_units(gl, name, &res->units_ratio, &res->units_se, &res->units_px);
    res->ok = true;
done:
    if (rc)
        snprintf(res->error, sizeof res->error, "%s", e.msg);
    res->nrows = *nrows - res->row0;
    free(both);
    free(direct);
    free(mask);
    lr_eval_masks_free(&m);
    lr_eval_regions_free(&rg);
    lr_ref_image_free(&mean);
    lr_ref_image_free(&var);
    lr_ref_image_free(&mean2);
    lr_ref_image_free(&var2);
    lr_ref_scene_destroy(rs);
    lr_scene_destroy(s);
    return rc;
}
