#include "hal/dmx_merge.h"

#include <string.h>

void lr_dmx_merge_init(lr_dmx_merge *m, const lr_dmx_merge_cfg *cfg)
{
    memset(m, 0, sizeof *m);
    m->cfg = *cfg;
    if (m->cfg.max_sources < 1)
        m->cfg.max_sources = 1;
    if (m->cfg.max_sources > LR_DMX_MAX_SOURCES)
        m->cfg.max_sources = LR_DMX_MAX_SOURCES;
    m->priority = -1;
}

static void recompute(lr_dmx_merge *m)
{
    memset(m->out, 0, sizeof m->out);
    m->n_out = 0;
    m->priority = -1;
    for (int i = 0; i < m->n; i++)
        if (m->src[i].priority > m->priority)
            m->priority = m->src[i].priority;
    if (m->cfg.mode == LR_DMX_LTP) {
        const lr_dmx_source *latest = NULL;
        for (int i = 0; i < m->n; i++)
            if (m->src[i].priority == m->priority && (!latest || m->src[i].order > latest->order))
                latest = &m->src[i];
        if (latest) {
            memcpy(m->out, latest->slots, (size_t)latest->n_slots);
            m->n_out = latest->n_slots;
        }
        return;
    }
    for (int i = 0; i < m->n; i++) {
        const lr_dmx_source *s = &m->src[i];
        if (s->priority != m->priority)
            continue;
        for (int k = 0; k < s->n_slots; k++)
            if (s->slots[k] > m->out[k])
                m->out[k] = s->slots[k];
        if (s->n_slots > m->n_out)
            m->n_out = s->n_slots;
    }
}

static int find(const lr_dmx_merge *m, const uint8_t *key)
{
    for (int i = 0; i < m->n; i++)
        if (memcmp(m->src[i].key, key, LR_DMX_KEY_LEN) == 0)
            return i;
    return -1;
}

static void remove_at(lr_dmx_merge *m, int i)
{
    m->src[i] = m->src[m->n - 1];
    m->n--;
}

lr_dmx_take lr_dmx_merge_put(lr_dmx_merge *m, const uint8_t key[LR_DMX_KEY_LEN], int priority,
                             int seq, const uint8_t *slots, int n, int64_t now_ns)
{
    if (n < 0)
        n = 0;
    if (n > LR_DMX_SLOTS)
        n = LR_DMX_SLOTS;
    int i = find(m, key);
    if (i < 0) {
        if (m->n >= m->cfg.max_sources)
            return LR_DMX_FULL;
        i = m->n++;
        memset(&m->src[i], 0, sizeof m->src[i]);
        memcpy(m->src[i].key, key, LR_DMX_KEY_LEN);
    } else if (m->cfg.check_sequence && seq >= 0 && m->src[i].last_seq >= 0) {
        /* E1.31 6.7.2: (new - last) as int8: > 0 is newer, <= -20 a restarted source. */
        int8_t d = (int8_t)(uint8_t)(seq - m->src[i].last_seq);
        if (d <= 0 && d > -20)
            return LR_DMX_SEQUENCE;
    }
    lr_dmx_source *s = &m->src[i];
    s->priority = priority;
    s->last_seq = seq;
    s->last_ns = now_ns;
    s->order = ++m->order;
    s->n_slots = n;
    if (n)
        memcpy(s->slots, slots, (size_t)n);
    recompute(m);
    return LR_DMX_TAKEN;
}

bool lr_dmx_merge_terminate(lr_dmx_merge *m, const uint8_t key[LR_DMX_KEY_LEN])
{
    int i = find(m, key);
    if (i < 0)
        return false;
    remove_at(m, i);
    recompute(m);
    return true;
}

int lr_dmx_merge_expire(lr_dmx_merge *m, int64_t now_ns)
{
    int removed = 0;
    for (int i = m->n - 1; i >= 0; i--)
        if (now_ns - m->src[i].last_ns >= m->cfg.timeout_ns) {
            remove_at(m, i);
            removed++;
        }
    if (removed)
        recompute(m);
    return removed;
}

int64_t lr_dmx_merge_next_expiry(const lr_dmx_merge *m)
{
    int64_t t = INT64_MAX;
    for (int i = 0; i < m->n; i++)
        if (m->src[i].last_ns + m->cfg.timeout_ns < t)
            t = m->src[i].last_ns + m->cfg.timeout_ns;
    return t;
}

int lr_dmx_merge_count(const lr_dmx_merge *m) { return m->n; }

int lr_dmx_merge_get(const lr_dmx_merge *m, const uint8_t **slots)
{
    *slots = m->out;
    return m->n_out;
}

int lr_dmx_merge_priority(const lr_dmx_merge *m) { return m->priority; }
