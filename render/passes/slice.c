/* GPU passes in slices: the wait and the poll at each slice end (slice.h). */
#include "render/passes/slice.h"

#include <GLES3/gl31.h>
#include <stdlib.h>
#include <time.h>

struct lr_slicer {
    const lr_cancel *cancel;
    long count;
    lr_slice_fn hook;
    void *hook_ctx;
    double budget_ms;                    /* 0: the fixed bands */
    double ms_per_row[LR_SLICE_PASSES];  /* running estimate; 0: none yet */
    int band_pass, band_rows;            /* the band under way; band_rows 0: none */
    double band_t0;
};

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

/* Without a budget: a map whole, a grid in LR_SLICE_ROWS. */
static int fixed_rows(enum lr_slice_pass pass, int total)
{
    return pass == LR_SLICE_IRRADIANCE && total > LR_SLICE_ROWS ? LR_SLICE_ROWS : total;
}

int lr_slicer_create(lr_slicer **out, lr_err *e)
{
    *out = calloc(1, sizeof **out);
    return *out ? LR_OK : lr_err_set(e, LR_ENOMEM, "renderer: out of memory (slicer)");
}

void lr_slicer_destroy(lr_slicer *s) { free(s); }

void lr_slicer_set_cancel(lr_slicer *s, const lr_cancel *cancel) { s->cancel = cancel; }

void lr_slicer_set_hook(lr_slicer *s, lr_slice_fn fn, void *ctx)
{
    s->hook = fn;
    s->hook_ctx = ctx;
}

void lr_slicer_set_budget(lr_slicer *s, double ms) { s->budget_ms = ms > 0 ? ms : 0; }

long lr_slicer_count(const lr_slicer *s) { return s->count; }

int lr_slice_band(lr_slicer *s, enum lr_slice_pass pass, int y, int size)
{
    int total = size - y;
    if (total < 1)
        return 0;
    if (!s || !s->cancel || !(s->budget_ms > 0))
        return fixed_rows(pass, total);
    double per_row = s->ms_per_row[pass];
    int least = (size + LR_SLICE_MAX_BANDS - 1) / LR_SLICE_MAX_BANDS;
    /* No estimate yet (the pass's first band): a small one, which gives it. */
    int rows = LR_SLICE_FIRST_ROWS > least ? LR_SLICE_FIRST_ROWS : least;
    if (per_row > 0) {
        double fit = s->budget_ms / per_row;
        rows = fit >= total ? total : fit < least ? least : (int)fit;
    }
    if (rows > total)
        rows = total;
    s->band_pass = (int)pass;
    s->band_rows = rows;
    s->band_t0 = now_ms();
    return rows;
}

int lr_slice_end(lr_slicer *s, enum lr_cancel_level level, const char *what, lr_err *e)
{
    if (!s)
        return LR_OK;
    s->count++;
    if (s->hook)
        s->hook(s->hook_ctx, s->count);
    if (!s->cancel)
        return LR_OK;
    /* The slice's commands are only queued: a poll now would let the whole pass run on. The
     * caller is the renderer's own thread (the rig's worker), which has nothing else to do
     * while its GPU works; the rig's loop never calls this. */
    glFinish();
    if (s->band_rows > 0) {
        /* The band's time from its first command to its GPU work's end, per row; the mean
         * with the last estimate, so one band slowed by other work on the machine moves the
         * next band's size by half. */
        double per_row = (now_ms() - s->band_t0) / s->band_rows;
        double *est = &s->ms_per_row[s->band_pass];
        *est = *est > 0 ? 0.5 * (*est + per_row) : per_row;
        s->band_rows = 0;
    }
    return lr_cancel_check_at(s->cancel, level, what, e);
}
