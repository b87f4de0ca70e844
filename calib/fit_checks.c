#include "calib/fit_checks.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

/* The model's domain (calib/fit.c's SIGMA_MIN, SIGMA_MAX), a factor 10 inside. */
#define BOUND_LO 1e-5
#define BOUND_HI 1e2

static void add(char *msg, size_t cap, const char *fmt, ...)
{
    if (!msg || !cap)
        return;
    size_t n = strlen(msg);
    if (n + 1 >= cap)
        return;
    if (n)
        msg[n++] = ' ', msg[n] = 0;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg + n, cap - n, fmt, ap);
    va_end(ap);
}

long lr_fit_min_pixels(lr_fit_mode mode)
{
    /* m - p >= 50 values per run: SIGMA 2 parameters on m values; SCALE 2 on 3 m */
    return mode == LR_FIT_SCALE ? (2 + 50 + 2) / 3 : 2 + 50;
}

unsigned lr_fit_check_data(lr_fit_mode mode, long object_pixels, long used_pixels, char *msg,
                           size_t cap)
{
    if (msg && cap)
        msg[0] = 0;
    unsigned bits = 0;
    long need = lr_fit_min_pixels(mode);
    if (used_pixels < need) {
        bits |= LR_FIT_WEAK_PIXELS;
        add(msg, cap,
            "pixels: %ld usable object pixels, at least %ld needed to fit %s (2 parameters "
            "plus 50 to estimate the noise).",
            used_pixels, need, mode == LR_FIT_SCALE ? "two scales" : "sigma_a and sigma_s' per band");
    }
    if (object_pixels > 0 && 2 * (object_pixels - used_pixels) > object_pixels) {
        bits |= LR_FIT_WEAK_CLIPPED;
        add(msg, cap,
            "clipped: %ld of the object's %ld pixels are clipped in every capture (more than "
            "half): only its dim part is left to fit.",
            object_pixels - used_pixels, object_pixels);
    }
    return bits;
}

unsigned lr_fit_check_result(lr_fit_mode mode, const lr_fit_result *r, char *msg, size_t cap)
{
    unsigned bits = lr_fit_check_data(mode, r->object_pixels, r->mask_pixels, msg, cap);
    static const char *band[3] = {"R", "G", "B"};
    int runs = mode == LR_FIT_SCALE ? 1 : 3;
    double worst_se = 0, worst_cond = 0;
    int wse = 0, wcond = 0, wpar = 0;
    for (int g = 0; g < runs; g++) {
        for (int k = 0; k < 2; k++)
            if (!(r->stderr_log[g][k] <= worst_se)) { /* NaN and inf count as worst */
                worst_se = r->stderr_log[g][k];
                wse = g, wpar = k;
            }
        if (!(r->cond[g] <= worst_cond))
            worst_cond = r->cond[g], wcond = g;
    }
    static const char *par[2][2] = {{"log sigma_a", "log sigma_s'"}, {"log s_a", "log s_s"}};
    const char *who = mode == LR_FIT_SCALE ? "" : band[wse];
    if (!(worst_se <= LR_FIT_MAX_STDERR_LOG)) {
        bits |= LR_FIT_WEAK_FLAT;
        add(msg, cap,
            "flat: the residual barely changes around the optimum: standard error of %s%s%s "
            "+-%.2g (at most %.2g).",
            par[mode == LR_FIT_SCALE][wpar], *who ? " in " : "", who, worst_se,
            LR_FIT_MAX_STDERR_LOG);
    }
    if (!(worst_cond <= LR_FIT_MAX_COND)) {
        bits |= LR_FIT_WEAK_FLAT;
        add(msg, cap,
            "flat: J^T J%s%s has condition number %.3g (at most %.0e): one combination of "
            "sigma_a and sigma_s' is not determined.",
            mode == LR_FIT_SCALE ? "" : " in ", mode == LR_FIT_SCALE ? "" : band[wcond],
            worst_cond, LR_FIT_MAX_COND);
    }
    for (int b = 0; b < 3; b++) {
        const double v[2] = {r->sigma_a[b], r->sigma_s_prime[b]};
        for (int k = 0; k < 2; k++)
            if (!(v[k] > BOUND_LO && v[k] < BOUND_HI)) {
                bits |= LR_FIT_WEAK_BOUND;
                add(msg, cap,
                    "bound: %s %s = %.3g mm^-1 is at the edge of the model's range "
                    "(%.0e..%.0e within a factor 10).",
                    k ? "sigma_s'" : "sigma_a", band[b], v[k], BOUND_LO, BOUND_HI);
                b = 3;
                break;
            }
    }
    double floor_rel = sqrt(r->noise_rel * r->noise_rel + LR_FIT_CAPTURE_NOISE * LR_FIT_CAPTURE_NOISE);
    if (!(r->rel_rmse_all <= LR_FIT_MAX_RESIDUAL_RATIO * floor_rel)) {
        bits |= LR_FIT_WEAK_RESIDUAL;
        add(msg, cap,
            "residual: relative RMSE %.3f is over %.0fx the noise floor %.3f (model noise "
            "%.3f, capture %.2f): the model does not explain the captures.",
            r->rel_rmse_all, LR_FIT_MAX_RESIDUAL_RATIO, floor_rel, r->noise_rel,
            LR_FIT_CAPTURE_NOISE);
    }
    return bits;
}

void lr_fit_check_names(unsigned bits, char *out, size_t cap)
{
    static const char *names[] = {"pixels", "clipped", "flat", "bound", "residual"};
    if (!cap)
        return;
    out[0] = 0;
    for (int i = 0; i < 5; i++)
        if (bits & (1u << i)) {
            size_t n = strlen(out);
            snprintf(out + n, cap - n, "%s%s", n ? ", " : "", names[i]);
        }
}
