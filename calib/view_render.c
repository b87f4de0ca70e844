#include "calib/view_render.h"

#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "render/cpu/frame.h"
#include "render/gl/gl.h"
#include "render/renderer.h"

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static int render_gpu(const lr_view_render_desc *d, int w, int h, lr_image *pin, double *secs,
                      lr_err *e)
{
    lr_gl *gl = NULL;
    lr_renderer *r = NULL;
    float *rgb = NULL;
    int rc = lr_gl_create(NULL, &gl, e);
    if (!rc)
        rc = lr_renderer_create(&(lr_renderer_desc){.gl = gl, .scene = d->scene, .width = w,
                                                    .height = h, .seed = d->seed},
                                &r, e);
    double t0 = now_s();
    /* until converged: render.frames accumulated (lr_renderer_needs_frame) */
    int total = d->frames ? d->frames : lr_scene_render(d->scene)->frames;
    if (!rc)
        lr_progress_report(d->progress, "render frame", 0, total);
    for (int i = 0; !rc; i++) {
        if (d->frames ? i >= d->frames : !lr_renderer_needs_frame(r))
            break;
        lr_frame_stats st;
        rc = lr_renderer_frame(r, &st, e);
        if (!rc)
            lr_progress_report(d->progress, "render frame", i + 1, total);
    }
    if (!rc && !(rgb = malloc((size_t)w * h * 3 * sizeof *rgb)))
        rc = lr_err_set(e, LR_ENOMEM, "out of memory");
    if (!rc)
        rc = lr_renderer_read_hdr(r, rgb, e);
    *secs = now_s() - t0;
    if (!rc)
        rc = lr_image_alloc(pin, w, h, e);
    if (!rc) /* GL rows bottom up, lr_image top down */
        for (int y = 0; y < h; y++)
            memcpy(pin->rgb + (size_t)y * w * 3, rgb + (size_t)(h - 1 - y) * w * 3,
                   (size_t)w * 3 * sizeof *rgb);
    free(rgb);
    lr_renderer_destroy(r);
    lr_gl_destroy(gl);
    return rc;
}

int lr_view_render(const lr_view_render_desc *d, lr_image *out, double *seconds, lr_err *e)
{
    memset(out, 0, sizeof *out);
    int w, h;
    lr_camview_render_size(d->view, &w, &h);
    int rc = lr_camview_apply(d->view, d->scene, NULL, e);
    if (rc)
        return rc;
    lr_image pin = {0};
    double secs = 0;
    if (d->cpu) {
        lr_cpu_render_desc cd = {.scene = d->scene, .width = w, .height = h,
                                 .mode = LR_CPU_PASS, .frames = d->frames, .seed = d->seed,
                                 .threads = d->threads, .progress = d->progress};
        lr_cpu_render_stats st = {0};
        rc = lr_cpu_render(&cd, &pin, NULL, &st, e);
        secs = st.seconds;
    } else {
        rc = render_gpu(d, w, h, &pin, &secs, e);
    }
    if (!rc)
        rc = lr_camview_remap(d->view, &pin, out, e);
    lr_image_free(&pin);
    if (seconds)
        *seconds = secs;
    return rc;
}
