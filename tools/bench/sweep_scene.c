/* One scene's sweep: the physical reference (cached), the masks, then every setting's GPU
 * frame series measured against it. */
#include "tools/bench/sweep.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/paths.h"
#include "render/reference/reference.h"

static int set_int(lr_scene *s, const char *key, int v, lr_err *e)
{
    char val[32];
    snprintf(val, sizeof val, "%d", v);
    return lr_scene_set(s, key, val, NULL, e);
}

int lrb_sweep_apply(lr_scene *s, const lrb_setting *st, lr_err *e)
{
    int rc;
    if ((rc = set_int(s, "render.K", st->K, e)) || (rc = set_int(s, "render.N", st->N, e)) ||
        (rc = set_int(s, "render.N_vpl", st->N_vpl, e)) ||
        (rc = set_int(s, "render.map_size", st->map_size, e)) ||
        (rc = set_int(s, "render.gbuffer_size", st->gbuffer_size, e)))
        return rc;
    /* The model is per object; the sweep switches every object at once. */
    for (int k = 0; k < lr_scene_object_count(s); k++) {
        char key[64];
        snprintf(key, sizeof key, "objects[%d].model", k);
        if ((rc = lr_scene_set(s, key, st->model, NULL, e)))
            return rc;
    }
    return LR_OK;
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

int lrb_sweep_scene(lr_gl *gl, const char *name, lr_eval_row *rows, int *nrows, int cap,
                    lrb_scene_result *res)
{
    *res = (lrb_scene_result){.units_ratio = NAN, .units_se = NAN, .direct_ratio = NAN,
                              .direct_se = NAN, .row0 = *nrows};
    snprintf(res->name, sizeof res->name, "%s", name);
    const int w = LRB_SWEEP_W, h = LRB_SWEEP_H;
    const size_t n = (size_t)w * h;
    char path[1024], refdir[1024];
    snprintf(path, sizeof path, "%s/scenes/%s.json", lr_configs_dir(), name);
    snprintf(refdir, sizeof refdir, "%s/bench/references", lr_configs_dir());
    lr_err e = {0};
    lr_scene *s = NULL;
    lr_ref_scene *rs = NULL;
    lr_ref_image mean = {0}, var = {0};
    lr_eval_masks m = {0};
    unsigned char *both = NULL, *direct = NULL;
    int rc;
    double t0 = lrb_now();
    if ((rc = lr_scene_load(path, NULL, &s, &e)))
        goto done;
    lr_ref_camera cam;
    if ((rc = lr_ref_scene_from_scene(s, &rs, &cam, &e)))
        goto done;
    lr_ref_render_desc rd = {.width = w, .height = h, .spp = LRB_SWEEP_SPP};
    fprintf(stderr, "bench sweep: %s: reference %dx%d, %d spp ...\n", name, w, h, rd.spp);
    if ((rc = lr_ref_render_cached(rs, &cam, &rd, refdir, NULL, NULL, &mean, &var, &res->ref_hit,
                                   &e)))
        goto done;
    res->ref_s = lrb_now() - t0;
    if ((rc = lr_eval_masks_create(s, w, h, &m, &e)))
        goto done;
    both = malloc(n);
    direct = calloc(n, 1);
    if (!both || !direct) {
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
        lr_eval_series ser = {0};
        if ((rc = lrb_sweep_apply(s, st, &e)) ||
            (rc = lr_eval_series_run(&(lr_eval_series_desc){.gl = gl, .scene = s, .width = w,
                                                            .height = h, .no_vpl = !st->vpl,
                                                            .checkpoints = st->checkpoints,
                                                            .ncheck = st->ncheck,
                                                            .converge_frames =
                                                                st->converge_frames},
                                     &ser, &e))) {
            lr_err_prefix(&e, "setting %s", st->label);
            goto done;
        }
        const float *C = ser.converged;
        const double Cf = st->converge_frames;
        /* Noise of the converged image itself, from the last checkpoint's: sigma^2 / F
         * scales to sigma^2 / C. */
        int Fl = st->checkpoints[st->ncheck - 1];
        double fix_l = 1.0 / sqrt(1.0 - Fl / Cf);
        double nC_obj = lr_eval_rel_rmse(ser.image[st->ncheck - 1], C, m.object, n) * fix_l *
                        sqrt(Fl / Cf);
        double nC_rec = lr_eval_rel_rmse(ser.image[st->ncheck - 1], C, m.receivers, n) * fix_l *
                        sqrt(Fl / Cf);
        /* Bias: converged model vs physical, without the reference's and the converged
         * image's own noise. */
        double bias_obj = debias(debias(lr_eval_rel_rmse(C, mean.rgb, m.object, n),
                                        res->ref_se_object), nC_obj);
        double bias_rec = debias(debias(lr_eval_rel_rmse(C, mean.rgb, m.receivers, n),
                                        res->ref_se_receivers), nC_rec);
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
                .width = w, .height = h,
            };
            snprintf(r.scene, sizeof r.scene, "%s", name);
            snprintf(r.model, sizeof r.model, "%s", st->model);
            memcpy(r.ms, ser.ms, sizeof r.ms);
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
    res->sweep_s = lrb_now() - t1;
    lrb_sweep_units(gl, name, &res->units_ratio, &res->units_se, &res->units_px);
    res->ok = true;
done:
    if (rc)
        snprintf(res->error, sizeof res->error, "%s", e.msg);
    res->nrows = *nrows - res->row0;
    free(both);
    free(direct);
    lr_eval_masks_free(&m);
    lr_ref_image_free(&mean);
    lr_ref_image_free(&var);
    lr_ref_scene_destroy(rs);
    lr_scene_destroy(s);
    return rc;
}
