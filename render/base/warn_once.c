/* lamprig — say-it-once keys (see warn_once.h). */
#include "render/base/warn_once.h"

static uint64_t fnv1a(const char *s)
{
    uint64_t h = 1469598103934665603ULL;
    for (; *s; s++)
        h = (h ^ (unsigned char)*s) * 1099511628211ULL;
    return h;
}

bool lr_warn_once_first(lr_warn_once *o, const char *key)
{
    if (!o)
        return true;
    uint64_t h = fnv1a(key ? key : "");
    for (int i = 0; i < o->n; i++)
        if (o->key[i] == h)
            return false;
    /* Full: the oldest goes (a rig seeing more than 8 folders fail says some twice). */
    if (o->n == LR_WARN_ONCE_MAX) {
        for (int i = 1; i < o->n; i++)
            o->key[i - 1] = o->key[i];
        o->n--;
    }
    o->key[o->n++] = h;
    return true;
}
