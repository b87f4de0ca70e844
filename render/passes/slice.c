/* GPU passes in slices: the wait and the poll at each slice end (slice.h). */
#include "render/passes/slice.h"

#include <GLES3/gl31.h>
#include <stdlib.h>

struct lr_slicer {
    const lr_cancel *cancel;
    long count;
    lr_slice_fn hook;
    void *hook_ctx;
};

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

long lr_slicer_count(const lr_slicer *s) { return s->count; }

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
    return lr_cancel_check_at(s->cancel, level, what, e);
}
