/* lamprig firmware — the view table (see view.h). */
#include "firmware/rig/view.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* Default first. */
static const lr_rig_view_ops *const views[] = {&lr_rig_view_passes, &lr_rig_view_inline,
                                               &lr_rig_view_preview};
#define N_VIEWS ((int)(sizeof views / sizeof views[0]))

struct lr_rig_view {
    const lr_rig_view_ops *ops;
    void *impl;
    int width, height;
};

const char *lr_rig_view_names(void) { return "passes, passes_inline, preview"; }

static const lr_rig_view_ops *find(const char *name)
{
    if (!name || !*name)
        return views[0];
    for (int i = 0; i < N_VIEWS; i++)
        if (strcmp(views[i]->name, name) == 0)
            return views[i];
    return NULL;
}

bool lr_rig_view_needs_gl(const char *name)
{
    const lr_rig_view_ops *o = find(name);
    return o && o->needs_gl;
}

int lr_rig_view_create(const lr_rig_view_desc *desc, lr_rig_view **out, lr_err *e)
{
    const lr_rig_view_ops *ops = find(desc->name);
    if (!ops)
        return lr_err_set(e, LR_EUNSUPPORTED, "renderer '%s' is not built in (have: %s)",
                          desc->name, lr_rig_view_names());
    lr_rig_view *v = calloc(1, sizeof *v);
    if (!v)
        return lr_err_set(e, LR_ENOMEM, "out of memory");
    v->ops = ops;
    v->width = desc->width > 0 ? desc->width : 640;
    v->height = desc->height > 0 ? desc->height : 480;
    lr_rig_view_desc d = *desc;
    d.width = v->width;
    d.height = v->height;
    int rc = ops->create(&d, &v->impl, e);
    if (rc) {
        free(v);
        return rc;
    }
    *out = v;
    return LR_OK;
}

void lr_rig_view_destroy(lr_rig_view *v)
{
    if (!v)
        return;
    v->ops->destroy(v->impl);
    free(v);
}

const char *lr_rig_view_name(const lr_rig_view *v) { return v->ops->name; }
uint64_t lr_rig_view_invalidate(lr_rig_view *v, unsigned dirty)
{
    return v->ops->invalidate(v->impl, dirty);
}
bool lr_rig_view_needs_frame(const lr_rig_view *v) { return v->ops->needs_frame(v->impl); }

void lr_rig_view_set_time(lr_rig_view *v, double t_seconds)
{
    if (v->ops->set_time)
        v->ops->set_time(v->impl, t_seconds);
}

int lr_rig_view_frame(lr_rig_view *v, lr_frame_stats *stats, lr_rig_frame_info *info,
                      lr_err *e)
{
    *stats = (lr_frame_stats){0};
    *info = (lr_rig_frame_info){.batch = UINT64_MAX - 1};
    int rc = v->ops->frame(v->impl, stats, info, e);
    if (!rc && !v->ops->busy) {
        /* On the loop: the frame shows every change made before it. */
        info->converged = stats->converged;
        info->stage = stats->converged ? LR_ASYNC_FINAL : LR_ASYNC_REFINING;
    }
    return rc;
}

int lr_rig_view_event_fd(const lr_rig_view *v)
{
    return v->ops->event_fd ? v->ops->event_fd(v->impl) : -1;
}

bool lr_rig_view_busy(const lr_rig_view *v) { return v->ops->busy && v->ops->busy(v->impl); }

int lr_rig_view_error(lr_rig_view *v, lr_err *e)
{
    return v->ops->error ? v->ops->error(v->impl, e) : LR_OK;
}

void lr_rig_view_retire(lr_rig_view *v)
{
    if (v->ops->retire)
        v->ops->retire(v->impl);
}

bool lr_rig_view_retired(const lr_rig_view *v)
{
    return !v->ops->retired || v->ops->retired(v->impl);
}

int lr_rig_view_wait_first(lr_rig_view *v, int timeout_ms, lr_err *e)
{
    return v->ops->wait_first ? v->ops->wait_first(v->impl, timeout_ms, e) : LR_OK;
}

int lr_rig_view_anticipate(lr_rig_view *v, const lr_async_state *states, int n, lr_err *e)
{
    return v->ops->anticipate ? v->ops->anticipate(v->impl, states, n, e) : LR_OK;
}

void lr_rig_view_cache_stats(const lr_rig_view *v, lr_state_cache_stats *st, int *pending)
{
    *st = (lr_state_cache_stats){0};
    if (pending)
        *pending = 0;
    if (v->ops->cache_stats)
        v->ops->cache_stats(v->impl, st, pending);
}

int lr_rig_view_read_rgba8(lr_rig_view *v, unsigned char *rgba, lr_err *e)
{
    return v->ops->read_rgba8(v->impl, rgba, e);
}

int lr_rig_view_present(lr_rig_view *v, lr_err *e) { return v->ops->present(v->impl, e); }

void lr_rig_view_size(const lr_rig_view *v, int *w, int *h)
{
    *w = v->width;
    *h = v->height;
}
