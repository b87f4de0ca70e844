/* lamprig firmware — the "passes_inline" view: render/renderer.h on the loop's own thread
 * (seed 003's passes on GLES 3.1): every frame's transport runs inside the loop. */
#include "firmware/rig/view.h"

#include <stdlib.h>

static int v_create(const lr_rig_view_desc *d, void **impl, lr_err *e)
{
    if (!d->gl)
        return lr_err_set(e, LR_EINVAL, "renderer 'passes' needs a GL context");
    lr_renderer_desc rd = {.gl = d->gl, .scene = d->scene, .width = d->width,
                           .height = d->height, .no_vpl = d->no_vpl,
                           .gpu_budget_mb = d->gpu_budget_mb};
    lr_renderer *r;
    int rc = lr_renderer_create(&rd, &r, e);
    if (rc)
        return rc;
    *impl = r;
    return LR_OK;
}

static void v_destroy(void *impl) { lr_renderer_destroy(impl); }
static uint64_t v_invalidate(void *impl, unsigned dirty)
{
    lr_renderer_invalidate(impl, dirty);
    return 0; /* the next frame shows it */
}
static bool v_needs_frame(const void *impl) { return lr_renderer_needs_frame(impl); }
static void v_set_time(void *impl, double t) { lr_renderer_set_time(impl, t); }

static int v_frame(void *impl, lr_frame_stats *st, lr_rig_frame_info *info, lr_err *e)
{
    (void)info; /* shows everything: lr_rig_view_frame's preset */
    return lr_renderer_frame(impl, st, e);
}

static int v_read(void *impl, unsigned char *rgba, lr_err *e)
{
    return lr_renderer_read_rgba8(impl, rgba, e);
}

static int v_present(void *impl, lr_err *e) { return lr_renderer_present(impl, e); }

const lr_rig_view_ops lr_rig_view_inline = {
    .name = "passes_inline",
    .needs_gl = true,
    .create = v_create,
    .destroy = v_destroy,
    .invalidate = v_invalidate,
    .needs_frame = v_needs_frame,
    .set_time = v_set_time,
    .frame = v_frame,
    .read_rgba8 = v_read,
    .present = v_present,
};
