/* The geometry interface: a shape is a table of operations and its data. */
#include "render/reference/ref_priv.h"

#include <stdlib.h>

int lr_ref_shape_create(const lr_ref_shape_ops *ops, void *self, lr_ref_shape **out, lr_err *e)
{
    *out = NULL;
    if (!ops || !ops->intersect || !ops->hash) {
        if (ops && ops->destroy)
            ops->destroy(self);
        return lr_err_set(e, LR_EINVAL, "reference: shape ops need intersect and hash");
    }
    lr_ref_shape *s = calloc(1, sizeof *s);
    if (!s) {
        if (ops->destroy)
            ops->destroy(self);
        return lr_err_set(e, LR_ENOMEM, "reference: out of memory for a %s", ops->name);
    }
    s->ops = ops;
    s->self = self;
    *out = s;
    return LR_OK;
}

void lr_ref_shape_destroy(lr_ref_shape *s)
{
    if (!s)
        return;
    if (s->ops->destroy)
        s->ops->destroy(s->self);
    free(s);
}

bool lr_ref_shape_intersect(const lr_ref_shape *s, lr_vec3 origin, lr_vec3 dir, double tmin,
                            double tmax, lr_ref_hit *hit)
{
    return s->ops->intersect(s->self, origin, dir, tmin, tmax, hit);
}
