/* build/bench/results.csv (eval.h): one line per (scene, model, setting, frames). */
#include "render/eval/eval.h"

#include <math.h>

#include "render/base/atomic_file.h"

void lr_eval_row_params(const lr_eval_row *r, char *buf, size_t cap)
{
    snprintf(buf, cap, "K=%d N=%d N_vpl=%d map=%d gbuf=%d frames=%d vpl=%s", r->K, r->N, r->N_vpl,
             r->map_size, r->gbuffer_size, r->frames, r->vpl ? "on" : "off");
}

/* %g with NaN spelt "nan" on every libc. */
static void num(FILE *f, double v, const char *fmt)
{
    if (isnan(v))
        fputs(",nan", f);
    else {
        fputc(',', f);
        fprintf(f, fmt, v);
    }
}

/* A debiased error: "<FLOOR" where it came out 0 under a noise floor (at most the floor:
 * the planner reads it so, render/plan/table.c), else as num. */
static void err_num(FILE *f, double v, double floor)
{
    if (v == 0.0 && isfinite(floor) && floor > 0.0)
        fprintf(f, ",<%.5f", floor);
    else
        num(f, v, "%.5f");
}

void lr_eval_csv_print(FILE *f, const lr_eval_row *rows, int n)
{
    bool lpv = false, seen = false;
    for (int i = 0; i < n; i++) {
        lpv |= rows[i].lpv > 0;
        /* A measured median over real pixels is > 0 (a zero-initialised row has none). */
        seen |= isfinite(rows[i].median_ln_object) && rows[i].median_ln_object > 0.0;
    }
    fputs(LR_EVAL_CSV_HEADER, f);
    fputs(lpv ? ",lpv,ms_lpv" : "", f);
    fputs(seen ? ",median_ln_object,median_ln_floor,band_excess\n" : "\n", f);
    for (int i = 0; i < n; i++) {
        const lr_eval_row *r = &rows[i];
        char params[160];
        lr_eval_row_params(r, params, sizeof params);
        /* Scene and model names are identifiers (no commas or quotes); params has none. */
        fprintf(f, "%s,%s,%s", r->scene, r->model, params);
        num(f, r->frame_ms, "%.3f");
        err_num(f, r->rel_rmse, r->floor_rel_rmse);
        err_num(f, r->rel_rmse_object, r->floor_rel_rmse_object);
        err_num(f, r->rel_rmse_receivers, r->floor_rel_rmse_receivers);
        fprintf(f, ",%d,%d,%d,%d,%d,%d,%s", r->K, r->N, r->N_vpl, r->map_size, r->gbuffer_size,
                r->frames, r->vpl ? "on" : "off");
        for (int p = 0; p < LR_EVAL_CSV_PASSES; p++)
            num(f, r->ms[p], "%.3f");
        err_num(f, r->bias_object, r->floor_bias_object);
        err_num(f, r->bias_receivers, r->floor_bias_receivers);
        num(f, r->noise_object, "%.5f");
        num(f, r->noise_receivers, "%.5f");
        fprintf(f, ",%d,%d,%d", r->width, r->height, r->supersample);
        if (lpv) {
            fprintf(f, ",%d", r->lpv);
            num(f, r->lpv > 0 ? r->ms[7] : NAN, "%.3f"); /* LR_PASS_LPV's bit index */
        }
        if (seen) {
            num(f, r->median_ln_object, "%.5f");
            num(f, r->median_ln_floor, "%.5f");
            num(f, r->band_excess, "%.5f");
        }
        fputc('\n', f);
    }
}

int lr_eval_csv_write(const char *path, const lr_eval_row *rows, int n, lr_err *e)
{
    lr_atomic_file *af;
    int rc = lr_atomic_file_open(path, &af, e);
    if (rc)
        return rc;
    lr_eval_csv_print(lr_atomic_file_stream(af), rows, n);
    return lr_atomic_file_commit(af, e);
}
