/* The control-space cache (render/async/cache.h). */
#include "render/async/cache.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_ENTRIES 64
#define MAX_REAP MAX_ENTRIES

typedef struct entry {
    bool live;
    lr_state_tag tag;
    lr_tex *tex;
    int n;
    float scale[LR_SCENE_MAX_LIGHTS];
    size_t bytes;
    uint64_t used; /* the lookup clock when last used */
    int pins;
    bool stale;    /* flushed while pinned: dropped at its last unpin */
} entry;

struct lr_state_cache {
    lr_cache_key keys[LR_CACHE_MAX_KEYS];
    int n_keys;
    size_t budget, bytes;
    entry e[MAX_ENTRIES];
    lr_tex *reap[MAX_REAP];
    int n_reap;
    uint64_t clock;
    lr_state_cache_stats st;
};

int lr_state_tag_of(const lr_scene *s, const lr_cache_key *keys, int n, lr_state_tag *out,
                    lr_err *e)
{
    if (n < 0 || n > LR_CACHE_MAX_KEYS)
        return lr_err_set(e, LR_EINVAL, "state cache: %d keys; at most %d", n, LR_CACHE_MAX_KEYS);
    out->n = n;
    for (int i = 0; i < n; i++) {
        int rc = lr_scene_get(s, keys[i].name, out->value[i], sizeof out->value[i], e);
        if (rc)
            return lr_err_prefix(e, "state cache: key '%s'", keys[i].name);
    }
    return LR_OK;
}

bool lr_state_tag_equal(const lr_state_tag *a, const lr_state_tag *b)
{
    if (a->n != b->n)
        return false;
    for (int i = 0; i < a->n; i++)
        if (strcmp(a->value[i], b->value[i]) != 0)
            return false;
    return true;
}

int lr_state_cache_create(const lr_cache_key *keys, int n_keys, size_t budget_bytes,
                          lr_state_cache **out, lr_err *e)
{
    *out = NULL;
    if (n_keys < 0 || n_keys > LR_CACHE_MAX_KEYS)
        return lr_err_set(e, LR_EINVAL, "state cache: %d keys; at most %d", n_keys,
                          LR_CACHE_MAX_KEYS);
    lr_state_cache *c = calloc(1, sizeof *c);
    if (!c)
        return lr_err_set(e, LR_ENOMEM, "state cache: out of memory");
    for (int i = 0; i < n_keys; i++)
        c->keys[i] = keys[i];
    c->n_keys = n_keys;
    c->budget = budget_bytes;
    c->st.budget = budget_bytes;
    *out = c;
    return LR_OK;
}

void lr_state_cache_reap(lr_state_cache *c)
{
    for (int i = 0; i < c->n_reap; i++)
        lr_tex_destroy(c->reap[i]);
    c->n_reap = 0;
}

static void drop(lr_state_cache *c, entry *x)
{
    if (c->n_reap < MAX_REAP)
        c->reap[c->n_reap++] = x->tex;
    else
        lr_tex_destroy(x->tex); /* cannot happen: at most MAX_ENTRIES live textures */
    c->bytes -= x->bytes;
    *x = (entry){0};
}

void lr_state_cache_destroy(lr_state_cache *c)
{
    if (!c)
        return;
    for (int i = 0; i < MAX_ENTRIES; i++)
        if (c->e[i].live)
            drop(c, &c->e[i]);
    lr_state_cache_reap(c);
    free(c);
}

const lr_cache_key *lr_state_cache_keys(const lr_state_cache *c, int *n)
{
    if (n)
        *n = c->n_keys;
    return c->keys;
}

bool lr_state_cache_has_key(const lr_state_cache *c, const char *key)
{
    for (int i = 0; i < c->n_keys; i++)
        if (strcmp(c->keys[i].name, key) == 0)
            return true;
    return false;
}

static int find_exact(const lr_state_cache *c, const lr_state_tag *tag)
{
    for (int i = 0; i < MAX_ENTRIES; i++)
        if (c->e[i].live && !c->e[i].stale && lr_state_tag_equal(&c->e[i].tag, tag))
            return i;
    return -1;
}

bool lr_state_cache_holds(const lr_state_cache *c, const lr_state_tag *tag)
{
    return find_exact(c, tag) >= 0;
}

/* Up to three numbers per band ("0.5" or "0.5,1,2"); false when the text is not that. */
static bool bands(const char *text, double v[3])
{
    char tail;
    int n = sscanf(text, "%lf , %lf , %lf %c", &v[0], &v[1], &v[2], &tail);
    if (n == 1) {
        v[1] = v[2] = v[0];
        return isfinite(v[0]);
    }
    return n == 3 && isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
}

/* The entries equal to tag in every key but `axis`: per band the nearest at or below and at
 * or above the tag's value. */
static bool interpolate(lr_state_cache *c, const lr_state_tag *tag, int axis, lr_cache_mix *mix)
{
    double want[3];
    if (!bands(tag->value[axis], want))
        return false;
    int lo[3] = {-1, -1, -1}, hi[3] = {-1, -1, -1};
    double ulo[3], uhi[3], u[3];
    for (int b = 0; b < 3; b++) {
        u[b] = want[b];
        ulo[b] = -INFINITY;
        uhi[b] = INFINITY;
    }
    for (int i = 0; i < MAX_ENTRIES; i++) {
        const entry *x = &c->e[i];
        if (!x->live || x->stale || x->tag.n != tag->n)
            continue;
        bool same = true;
        for (int k = 0; k < tag->n && same; k++)
            same = k == axis || strcmp(x->tag.value[k], tag->value[k]) == 0;
        double v[3];
        if (!same || !bands(x->tag.value[axis], v))
            continue;
        for (int b = 0; b < 3; b++) {
            double ub = v[b];
            if (ub <= u[b] && ub > ulo[b]) {
                ulo[b] = ub;
                lo[b] = i;
            }
            if (ub >= u[b] && ub < uhi[b]) {
                uhi[b] = ub;
                hi[b] = i;
            }
        }
    }
    lr_cache_mix m = {0};
    for (int b = 0; b < 3; b++) {
        if (lo[b] < 0 || hi[b] < 0)
            return false;
        double t = uhi[b] > ulo[b] ? (u[b] - ulo[b]) / (uhi[b] - ulo[b]) : 0.0;
        const int who[2] = {lo[b], hi[b]};
        const double wt[2] = {1.0 - t, t};
        for (int s = 0; s < 2; s++) {
            if (wt[s] == 0.0)
                continue;
            int k = 0;
            while (k < m.n && m.entry[k] != who[s])
                k++;
            if (k == m.n) {
                m.entry[k] = who[s];
                m.n++;
            }
            m.w[k][b] += wt[s];
        }
    }
    *mix = m;
    return m.n > 0;
}

bool lr_state_cache_find(lr_state_cache *c, const lr_state_tag *tag, lr_cache_mix *mix)
{
    c->clock++;
    *mix = (lr_cache_mix){0};
    int i = find_exact(c, tag);
    if (i >= 0) {
        mix->n = 1;
        mix->entry[0] = i;
        mix->w[0][0] = mix->w[0][1] = mix->w[0][2] = 1.0;
        mix->exact = true;
        c->e[i].used = c->clock;
        c->st.hits_exact++;
        return true;
    }
    if (tag->n == c->n_keys)
        for (int k = 0; k < c->n_keys; k++) {
            if (c->keys[k].interp == LR_CACHE_EXACT || !interpolate(c, tag, k, mix))
                continue;
            for (int j = 0; j < mix->n; j++)
                c->e[mix->entry[j]].used = c->clock;
            c->st.hits_interp++;
            return true;
        }
    c->st.misses++;
    return false;
}

/* The least recently used unpinned entry, or -1. */
static int victim(const lr_state_cache *c)
{
    int v = -1;
    for (int i = 0; i < MAX_ENTRIES; i++)
        if (c->e[i].live && !c->e[i].pins && (v < 0 || c->e[i].used < c->e[v].used))
            v = i;
    return v;
}

bool lr_state_cache_fits(const lr_state_cache *c, size_t bytes)
{
    if (bytes > c->budget)
        return false;
    size_t pinned = 0;
    for (int i = 0; i < MAX_ENTRIES; i++)
        if (c->e[i].live && c->e[i].pins)
            pinned += c->e[i].bytes;
    return pinned + bytes <= c->budget;
}

bool lr_state_cache_store(lr_state_cache *c, const lr_state_tag *tag, lr_tex *tex, int n,
                          const float *scale, size_t bytes)
{
    if (!lr_state_cache_fits(c, bytes) || n < 1 || n > LR_SCENE_MAX_LIGHTS) {
        lr_tex_destroy(tex);
        return false;
    }
    int old = find_exact(c, tag);
    if (old >= 0 && !c->e[old].pins)
        drop(c, &c->e[old]);
    else if (old >= 0)
        c->e[old].stale = true;
    int slot = -1;
    for (;;) {
        slot = -1;
        for (int i = 0; i < MAX_ENTRIES && slot < 0; i++)
            if (!c->e[i].live)
                slot = i;
        if (slot >= 0 && c->bytes + bytes <= c->budget)
            break;
        int v = victim(c);
        if (v < 0) {
            lr_tex_destroy(tex);
            return false;
        }
        drop(c, &c->e[v]);
        c->st.evicted++;
    }
    entry *x = &c->e[slot];
    *x = (entry){.live = true, .tag = *tag, .tex = tex, .n = n, .bytes = bytes,
                 .used = ++c->clock};
    memcpy(x->scale, scale, (size_t)n * sizeof *scale);
    c->bytes += bytes;
    c->st.stored++;
    return true;
}

void lr_state_cache_flush(lr_state_cache *c)
{
    bool any = false;
    for (int i = 0; i < MAX_ENTRIES; i++) {
        entry *x = &c->e[i];
        if (!x->live)
            continue;
        any = true;
        if (x->pins)
            x->stale = true;
        else
            drop(c, x);
    }
    if (any)
        c->st.flushed++;
}

void lr_state_cache_drop_all(lr_state_cache *c)
{
    for (int i = 0; i < MAX_ENTRIES; i++)
        if (c->e[i].live)
            drop(c, &c->e[i]);
    lr_state_cache_reap(c);
}

void lr_state_cache_pin(lr_state_cache *c, const lr_cache_mix *mix)
{
    for (int k = 0; k < mix->n; k++)
        c->e[mix->entry[k]].pins++;
}

void lr_state_cache_unpin(lr_state_cache *c, const lr_cache_mix *mix)
{
    for (int k = 0; k < mix->n; k++) {
        entry *x = &c->e[mix->entry[k]];
        if (x->pins > 0 && --x->pins == 0 && x->stale)
            drop(c, x);
    }
}

const lr_tex *lr_state_cache_images(const lr_state_cache *c, int k, int *n, const float **scale)
{
    if (k < 0 || k >= MAX_ENTRIES || !c->e[k].live)
        return NULL;
    if (n)
        *n = c->e[k].n;
    if (scale)
        *scale = c->e[k].scale;
    return c->e[k].tex;
}

void lr_state_cache_get_stats(const lr_state_cache *c, lr_state_cache_stats *st)
{
    *st = c->st;
    st->bytes = c->bytes;
    st->entries = 0;
    for (int i = 0; i < MAX_ENTRIES; i++)
        st->entries += c->e[i].live && !c->e[i].stale;
}
