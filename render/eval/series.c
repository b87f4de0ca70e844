/* A GPU frame series for the bench (eval.h): full updates timed, then accumulation up to
 * convergence with the image read at the checkpoints. */
#include "render/eval/eval.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/image/image.h"

enum { FULL_UPDATES = 3 };

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, int n)
{
    if (n < 1)
        return NAN;
    qsort(v, (size_t)n, sizeof v[0], cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* The renderer's HDR (rows bottom up, w x h) into a new top-down buffer, box-filtered by
 * factor ss (w and h are multiples of it). */
static int read_top_down(lr_renderer *r, int w, int h, int ss, float *tmp, float **out,
                         lr_err *e)
{
    int rc = lr_renderer_read_hdr(r, tmp, e);
    if (rc)
        return rc;
    size_t row = (size_t)w * 3;
    lr_image full = {0}, small = {0};
    if ((rc = lr_image_alloc(&full, w, h, e)))
        return rc;
    for (int y = 0; y < h; y++)
        memcpy(full.rgb + (size_t)y * row, tmp + (size_t)(h - 1 - y) * row, row * sizeof *tmp);
    if (ss <= 1) {
        *out = full.rgb; /* taken over */
        return LR_OK;
    }
    rc = lr_image_downsample_box(&full, ss, &small, e);
    lr_image_free(&full);
    if (!rc)
        *out = small.rgb; /* taken over */
    return rc;
}

void lr_eval_series_free(lr_eval_series *s)
{
    for (int i = 0; i < 8; i++)
        free(s->image[i]);
    free(s->converged);
    *s = (lr_eval_series){0};
}

int lr_eval_series_run(const lr_eval_series_desc *d, lr_eval_series *out, lr_err *e)
{
    *out = (lr_eval_series){0};
    if (d->ncheck < 0 || d->ncheck > 8 || d->converge_frames < 4)
        return lr_err_set(e, LR_EINVAL, "series: %d checkpoints (at most 8), %d frames (at "
                          "least 4: three accumulation frames to time)", d->ncheck,
                          d->converge_frames);
    for (int i = 0; i < d->ncheck; i++)
        if (d->checkpoints[i] < 1 || d->checkpoints[i] > d->converge_frames ||
            (i && d->checkpoints[i] <= d->checkpoints[i - 1]))
            return lr_err_set(e, LR_EINVAL, "series: checkpoints must ascend within 1..%d",
                              d->converge_frames);
    char val[32];
    snprintf(val, sizeof val, "%d", d->converge_frames);
    int rc = lr_scene_set(d->scene, "render.frames", val, NULL, e);
    if (rc)
        return rc;
    if (d->supersample < 0 || d->supersample > 16 || d->width < 1 || d->height < 1)
        return lr_err_set(e, LR_EINVAL, "series: %dx%d supersampled %d (1..16)", d->width,
                          d->height, d->supersample);
    /* Supersampling renders the composition at ss times the size: the light-space maps do not
     * depend on the image size, so only the per-pixel passes see more pixels. */
    const int ss = d->supersample > 1 ? d->supersample : 1;
    const int w = d->width * ss, h = d->height * ss;
    float *tmp = malloc((size_t)w * h * 3 * sizeof *tmp);
    double *acc[LR_PASS_COUNT + 1] = {0}, full[FULL_UPDATES], full_lpv[FULL_UPDATES];
    for (int p = 0; p <= LR_PASS_COUNT; p++)
        acc[p] = malloc((size_t)d->converge_frames * sizeof(double));
    lr_renderer *r = NULL;
    bool oom = !tmp;
    for (int p = 0; p <= LR_PASS_COUNT; p++)
        oom |= !acc[p];
    if (oom) {
        rc = lr_err_set(e, LR_ENOMEM, "series: out of memory");
        goto done;
    }
    if ((rc = lr_renderer_create(&(lr_renderer_desc){.gl = d->gl, .scene = d->scene, .width = w,
                                                      .height = h, .no_vpl = d->no_vpl,
                                                      .seed = d->seed},
                                 &r, e)))
        goto done;
    lr_frame_stats st = {0};
    /* Full updates: each restarts the maps, so after the last one they hold one frame. */
    for (int i = 0; i < FULL_UPDATES; i++) {
        if (i)
            lr_renderer_invalidate(r, LR_DIRTY_LIGHT_GEOMETRY);
        if ((rc = lr_renderer_frame(r, &st, e)))
            goto done;
        full[i] = (st.passes & 1u) ? st.ms[0] : NAN;
        full_lpv[i] = (st.passes & LR_PASS_LPV) ? st.ms[7] : NAN; /* render.lpv's pass */
    }
    int next = 0, nacc = 0;
    for (;;) {
        if (next < d->ncheck && st.samples == d->checkpoints[next]) {
            if ((rc = read_top_down(r, w, h, ss, tmp, &out->image[next], e)))
                goto done;
            next++;
        }
        if (st.samples >= d->converge_frames)
            break;
        if (st.index > 2 * d->converge_frames + FULL_UPDATES) {
            rc = lr_err_set(e, LR_EINVAL, "series: accumulation stalled at %d frames",
                            st.samples);
            goto done;
        }
        if ((rc = lr_renderer_frame(r, &st, e)))
            goto done;
        for (int p = 0; p < LR_PASS_COUNT; p++)
            acc[p][nacc] = (st.passes & (1u << p)) ? st.ms[p] : NAN;
        acc[LR_PASS_COUNT][nacc] = st.total_ms;
        nacc++;
    }
    if (next < d->ncheck) {
        rc = lr_err_set(e, LR_EINVAL, "series: checkpoint %d frames never reached",
                        d->checkpoints[next]);
        goto done;
    }
    if ((rc = read_top_down(r, w, h, ss, tmp, &out->converged, e)))
        goto done;
    out->ms[0] = median(full, FULL_UPDATES);
    for (int p = 1; p < LR_PASS_COUNT; p++) {
        int m = 0;
        for (int i = 0; i < nacc; i++)
            if (isfinite(acc[p][i]))
                acc[p][m++] = acc[p][i];
        out->ms[p] = median(acc[p], m);
    }
    out->frame_ms = median(acc[LR_PASS_COUNT], nacc);
    /* The volume is built on full updates only (its pass is due on the changes they make). */
    out->ms[7] = isfinite(full_lpv[0]) ? median(full_lpv, FULL_UPDATES) : NAN;
    out->accum_frames = nacc;
done:
    lr_renderer_destroy(r);
    free(tmp);
    for (int p = 0; p <= LR_PASS_COUNT; p++)
        free(acc[p]);
    if (rc)
        lr_eval_series_free(out);
    return rc;
}
