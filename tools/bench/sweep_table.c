/* summary.md's 640x480 table (issue 6 item 4): per-pass frame times of the sweep's base
 * setting at 640x480, the accumulation frame, and the dimmer-only frame (a light.intensity
 * change: compose alone) with its speed-up over a full update. */
#include "tools/bench/sweep.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/paths.h"

enum { FULL = 3, ACCUM = 4, DIMMER = 5 };

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, int n)
{
    int m = 0;
    for (int i = 0; i < n; i++)
        if (isfinite(v[i]))
            v[m++] = v[i];
    if (!m)
        return NAN;
    qsort(v, (size_t)m, sizeof v[0], cmp_double);
    return m % 2 ? v[m / 2] : 0.5 * (v[m / 2 - 1] + v[m / 2]);
}

int lrb_sweep_time_640(lr_gl *gl, const char *name, lrb_timing_640 *out)
{
    *out = (lrb_timing_640){.w = 640, .h = 480};
    snprintf(out->scene, sizeof out->scene, "%s", name);
    lrb_setting base;
    lrb_sweep_settings(&base, 1);
    char path[1024];
    snprintf(path, sizeof path, "%s/scenes/%s.json", lr_configs_dir(), name);
    lr_err e = {0};
    lr_scene *s = NULL;
    lr_renderer *r = NULL;
    int rc = lr_scene_load(path, &(const lr_warn_sink){lr_warn_stderr, "lamprig-bench"}, &s, &e);
    char v[32];
    /* Accumulation converges after the last accumulation frame, so the dimmer frames run
     * compose alone. */
    snprintf(v, sizeof v, "%d", 1 + ACCUM);
    if (!rc)
        rc = lrb_sweep_apply(s, &base, &e);
    if (!rc)
        rc = lr_scene_set(s, "render.frames", v, NULL, &e);
    if (!rc)
        rc = lr_renderer_create(&(lr_renderer_desc){.gl = gl, .scene = s, .width = out->w,
                                                     .height = out->h},
                                &r, &e);
    double full[LR_PASS_COUNT][FULL], tot[FULL], acc[ACCUM], dim[DIMMER];
    lr_frame_stats st;
    for (int i = 0; !rc && i < FULL; i++) {
        lr_renderer_invalidate(r, LR_DIRTY_LIGHT_GEOMETRY);
        if (!(rc = lr_renderer_frame(r, &st, &e))) {
            for (int p = 0; p < LR_PASS_COUNT; p++)
                full[p][i] = (st.passes & (1u << p)) ? st.ms[p] : NAN;
            tot[i] = st.total_ms;
        }
    }
    for (int i = 0; !rc && i < ACCUM; i++)
        if (!(rc = lr_renderer_frame(r, &st, &e)))
            acc[i] = st.total_ms;
    double I0 = rc ? 0.0 : lr_scene_light_at(s, 0)->intensity;
    for (int i = 0; !rc && i < DIMMER; i++) {
        unsigned dirty = 0;
        snprintf(v, sizeof v, "%.17g", i % 2 ? I0 : 0.5 * I0);
        if ((rc = lr_scene_set(s, "light.intensity", v, &dirty, &e)))
            break;
        lr_renderer_invalidate(r, dirty);
        if ((rc = lr_renderer_frame(r, &st, &e)))
            break;
        if (st.passes != LR_PASS_BLEND) /* linear in intensity: the blend pass alone */
            fprintf(stderr, "bench sweep: dimmer frame ran passes 0x%x, not the blend alone\n",
                    st.passes);
        dim[i] = st.total_ms;
    }
    if (!rc) {
        for (int p = 0; p < LR_PASS_COUNT; p++)
            out->pass_ms[p] = median(full[p], FULL);
        out->full_ms = median(tot, FULL);
        out->accum_ms = median(acc, ACCUM);
        out->dimmer_ms = median(dim, DIMMER);
        out->ok = true;
    } else
        fprintf(stderr, "bench sweep: %s 640x480: %s\n", name, e.msg);
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
    return rc;
}
