/* lamprig firmware — the "preview" view: a CPU stand-in for the renderer (see view.h). */
#include <GLES3/gl31.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "firmware/rig/view.h"
#include "render/image/image.h"

typedef struct preview {
    lr_gl *gl;
    lr_scene *scene;
    int w, h;
    double ref;      /* sum of the lights' intensities at create (the "1" of the glow) */
    double rgb[3];   /* glow centre, linear, after tone mapping */
    unsigned dirty;
    bool have_frame;
    int index;
} preview;

static double light_sum(const lr_scene *s, double rgb[3])
{
    double sum = 0;
    rgb[0] = rgb[1] = rgb[2] = 0;
    for (int i = 0; i < lr_scene_light_count(s); i++) {
        double c[3];
        lr_light_rgb(lr_scene_light_at(s, i), c);
        for (int k = 0; k < 3; k++)
            rgb[k] += c[k];
        sum += lr_scene_light_at(s, i)->intensity;
    }
    return sum;
}

static int p_create(const lr_rig_view_desc *d, void **impl, lr_err *e)
{
    preview *p = calloc(1, sizeof *p);
    if (!p)
        return lr_err_set(e, LR_ENOMEM, "out of memory");
    p->gl = d->gl;
    p->scene = d->scene;
    p->w = d->width;
    p->h = d->height;
    double rgb[3];
    p->ref = light_sum(d->scene, rgb);
    if (!(p->ref > 0))
        p->ref = 1;
    p->dirty = ~0u;
    *impl = p;
    return LR_OK;
}

static void p_destroy(void *impl) { free(impl); }

static uint64_t p_invalidate(void *impl, unsigned dirty)
{
    ((preview *)impl)->dirty |= dirty;
    return 0;
}

static bool p_needs_frame(const void *impl)
{
    const preview *p = impl;
    return p->dirty != 0 || !p->have_frame;
}

static int p_frame(void *impl, lr_frame_stats *st, lr_rig_frame_info *info, lr_err *e)
{
    (void)info; /* shows everything: lr_rig_view_frame's preset */
    (void)e;
    preview *p = impl;
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    double rgb[3];
    light_sum(p->scene, rgb);
    for (int k = 0; k < 3; k++)
        p->rgb[k] = 1.0 - exp(-rgb[k] / p->ref);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    memset(st, 0, sizeof *st);
    st->index = p->index++;
    st->passes = p->have_frame ? lr_dirty_passes(p->dirty) : 0xfu;
    st->total_ms = st->ms[3] = (double)(t1.tv_sec - t0.tv_sec) * 1e3 +
                               (double)(t1.tv_nsec - t0.tv_nsec) * 1e-6;
    st->samples = 1;
    st->converged = true;
    p->dirty = 0;
    p->have_frame = true;
    return LR_OK;
}

static int p_read(void *impl, unsigned char *rgba, lr_err *e)
{
    (void)e;
    preview *p = impl;
    for (int y = 0; y < p->h; y++)
        for (int x = 0; x < p->w; x++) {
            double dx = (x + 0.5) / p->w - 0.5, dy = (y + 0.5) / p->h - 0.5;
            double g = exp(-(dx * dx + dy * dy) / 0.08);
            unsigned char *o = rgba + 4 * ((size_t)y * (size_t)p->w + (size_t)x);
            for (int k = 0; k < 3; k++) {
                float v = lr_srgb_encode((float)(p->rgb[k] * g));
                o[k] = (unsigned char)lrintf(v * 255.0f);
            }
            o[3] = 255;
        }
    return LR_OK;
}

static int p_present(void *impl, lr_err *e)
{
    preview *p = impl;
    if (!p->gl)
        return LR_OK;
    lr_gl_bind_default(p->gl);
    glClearColor((float)p->rgb[0], (float)p->rgb[1], (float)p->rgb[2], 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    return lr_gl_present(p->gl, e);
}

const lr_rig_view_ops lr_rig_view_preview = {
    .name = "preview",
    .needs_gl = false,
    .create = p_create,
    .destroy = p_destroy,
    .invalidate = p_invalidate,
    .needs_frame = p_needs_frame,
    .frame = p_frame,
    .read_rgba8 = p_read,
    .present = p_present,
};
