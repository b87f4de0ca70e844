#include "hal/event.h"

#include <stdlib.h>
#include <string.h>

const char *lr_event_kind_name(lr_event_kind kind)
{
    switch (kind) {
    case LR_EV_DELTA: return "delta";
    case LR_EV_ABSOLUTE: return "absolute";
    case LR_EV_PRESS: return "press";
    case LR_EV_RELEASE: return "release";
    }
    return "?";
}

int lr_event_kind_parse(const char *name, lr_event_kind *out)
{
    static const lr_event_kind kinds[] = {LR_EV_DELTA, LR_EV_ABSOLUTE, LR_EV_PRESS, LR_EV_RELEASE};
    for (size_t i = 0; i < sizeof kinds / sizeof kinds[0]; i++) {
        if (strcmp(name, lr_event_kind_name(kinds[i])) == 0) {
            *out = kinds[i];
            return LR_OK;
        }
    }
    return LR_EPARSE;
}

static void copy_name(char dst[LR_EVENT_NAME_MAX], const char *src)
{
    size_t n = src ? strnlen(src, LR_EVENT_NAME_MAX - 1) : 0;
    if (n)
        memcpy(dst, src, n);
    dst[n] = '\0';
}

void lr_event_set(lr_event *ev, const char *source, const char *control, lr_event_kind kind,
                  double value, int64_t t_ns)
{
    copy_name(ev->source, source);
    copy_name(ev->control, control);
    ev->kind = kind;
    ev->value = value;
    ev->t_ns = t_ns;
}

struct lr_event_ring {
    lr_event *buf;
    size_t cap, head, count;
    uint64_t dropped;
};

int lr_event_ring_create(size_t capacity, lr_event_ring **out, lr_err *e)
{
    *out = NULL;
    if (capacity == 0)
        capacity = 256;
    lr_event_ring *r = calloc(1, sizeof *r);
    if (r)
        r->buf = calloc(capacity, sizeof *r->buf);
    if (!r || !r->buf) {
        free(r);
        return lr_err_set(e, LR_ENOMEM, "event ring: cannot allocate %zu events", capacity);
    }
    r->cap = capacity;
    *out = r;
    return LR_OK;
}

void lr_event_ring_destroy(lr_event_ring *ring)
{
    if (!ring)
        return;
    free(ring->buf);
    free(ring);
}

void lr_event_ring_push(void *user, const lr_event *ev)
{
    lr_event_ring *r = user;
    if (r->count == r->cap) {
        /* Drop the oldest: for absolute controls the newest value is the one that matters. */
        r->head = (r->head + 1) % r->cap;
        r->count--;
        r->dropped++;
    }
    r->buf[(r->head + r->count) % r->cap] = *ev;
    r->count++;
}

lr_event_sink lr_event_ring_sink(lr_event_ring *ring)
{
    lr_event_sink s = {lr_event_ring_push, ring};
    return s;
}

bool lr_event_ring_pop(lr_event_ring *r, lr_event *out)
{
    if (r->count == 0)
        return false;
    *out = r->buf[r->head];
    r->head = (r->head + 1) % r->cap;
    r->count--;
    return true;
}

size_t lr_event_ring_count(const lr_event_ring *r) { return r->count; }
uint64_t lr_event_ring_dropped(const lr_event_ring *r) { return r->dropped; }
