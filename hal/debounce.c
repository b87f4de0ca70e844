#include "hal/debounce.h"

void lr_debounce_init(lr_debounce *d, int64_t window_ns, int level)
{
    d->window_ns = window_ns > 0 ? window_ns : 5000000;
    d->locked_until = INT64_MIN;
    d->raw_t = INT64_MIN;
    d->stable = d->raw = level ? 1 : 0;
    d->pending = false;
    d->ignored = 0;
}

static int change(lr_debounce *d, uint8_t level, int64_t lock_from, int64_t t, int64_t *t_out)
{
    d->stable = level;
    d->locked_until = lock_from + d->window_ns;
    d->pending = false;
    if (t_out)
        *t_out = t;
    return level ? 1 : -1;
}

int lr_debounce_edge(lr_debounce *d, int level, int64_t t_ns, int64_t *t_out)
{
    uint8_t l = level ? 1 : 0;
    d->raw = l;
    d->raw_t = t_ns;
    if (t_ns < d->locked_until) {
        d->ignored++;
        d->pending = true;
        return 0;
    }
    if (l == d->stable) {
        /* Same level as debounced: the edge that left it was lost or ignored; nothing to say. */
        return 0;
    }
    return change(d, l, t_ns, t_ns, t_out);
}

int64_t lr_debounce_deadline(const lr_debounce *d)
{
    return d->pending ? d->locked_until : INT64_MAX;
}

int lr_debounce_tick(lr_debounce *d, int64_t now_ns, int64_t *t_out)
{
    if (!d->pending || now_ns < d->locked_until)
        return 0;
    d->pending = false;
    if (d->raw == d->stable)
        return 0;
    /* The contact settled in the other state during the window. A new window starts now, so
     * bounce of this second change is ignored too. */
    return change(d, d->raw, now_ns, d->raw_t, t_out);
}
