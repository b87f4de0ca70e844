/* lamprig firmware — the control space built ahead (see ahead.h). */
#include "firmware/rig/ahead.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A change that is one blend (a dimmer, colour, flicker or exposure): nothing to cache. */
#define BLEND_ONLY ((unsigned)(LR_DIRTY_INTENSITY | LR_DIRTY_DISPLAY))

/* What a re-plan writes besides the models (render/plan/replan.c write_settings). */
static const char *const plan_settings[] = {"render.K", "render.N", "render.N_vpl",
                                            "render.map_size", "render.gbuffer_size",
                                            "render.frames"};

static bool add_key(lr_cache_key *keys, int max, int *n, const char *name, lr_cache_interp m)
{
    for (int i = 0; i < *n; i++)
        if (strcmp(keys[i].name, name) == 0)
            return true;
    if (*n >= max || strlen(name) >= sizeof keys[0].name)
        return false;
    snprintf(keys[*n].name, sizeof keys[*n].name, "%s", name);
    keys[*n].interp = m;
    (*n)++;
    return true;
}

int lr_rig_ahead_keys(const lr_control_map *map, const lr_scene *scene, lr_cache_key *keys,
                      int max, int *n, lr_err *e)
{
    *n = 0;
    lr_scene *probe = NULL;
    int rc = lr_scene_clone(scene, NULL, &probe, e);
    if (rc)
        return lr_err_prefix(e, "states ahead");
    for (int i = 0; i < lr_control_map_count(map) && !rc; i++) {
        const char *key = lr_control_map_key(map, i);
        if (!key || strcmp(key, "scene") == 0)
            continue;
        char cur[256];
        unsigned d = 0;
        lr_err pe = {0};
        /* Writing the current value back reports the key's flags (lr_scene_set). */
        if (lr_scene_get(probe, key, cur, sizeof cur, &pe) ||
            lr_scene_set(probe, key, cur, &d, &pe) || !(d & ~BLEND_ONLY))
            continue;
        if (!add_key(keys, max, n, key,
                     lr_control_map_is_cycle(map, i) ? LR_CACHE_EXACT : LR_CACHE_LINEAR))
            rc = lr_err_set(e, LR_EINVAL, "states ahead: more than %d keys", max);
    }
    for (int i = 0; i < lr_scene_object_count(scene) && !rc && *n > 0; i++) {
        char k[48];
        snprintf(k, sizeof k, "objects[%d].model", i);
        if (!add_key(keys, max, n, k, LR_CACHE_EXACT))
            rc = lr_err_set(e, LR_EINVAL, "states ahead: more than %d keys", max);
    }
    for (size_t i = 0; i < sizeof plan_settings / sizeof *plan_settings && !rc && *n > 0; i++)
        if (!add_key(keys, max, n, plan_settings[i], LR_CACHE_EXACT))
            rc = lr_err_set(e, LR_EINVAL, "states ahead: more than %d keys", max);
    lr_scene_destroy(probe);
    return rc;
}

typedef struct cand {
    int binding;
    double pos;
} cand;

struct lr_rig_ahead {
    int samples;
    int64_t changed_ns;
    bool listing, done;
    cand c[LR_ASYNC_MAX_STATES];
    int n_cand, next;
    lr_async_state st[LR_ASYNC_MAX_STATES];
    int n_st;
    lr_async_state rec; /* the state being recorded */
    bool rec_full;
};

int lr_rig_ahead_create(int samples, lr_rig_ahead **out, lr_err *e)
{
    *out = NULL;
    if (samples < 2 || samples > LR_ASYNC_MAX_STATES)
        return lr_err_set(e, LR_EINVAL, "states ahead: %d samples; 2..%d", samples,
                          LR_ASYNC_MAX_STATES);
    lr_rig_ahead *h = calloc(1, sizeof *h);
    if (!h)
        return lr_err_set(e, LR_ENOMEM, "out of memory");
    h->samples = samples;
    h->done = false;
    *out = h;
    return LR_OK;
}

void lr_rig_ahead_destroy(lr_rig_ahead *h) { free(h); }

void lr_rig_ahead_changed(lr_rig_ahead *h, int64_t now_ns)
{
    h->changed_ns = now_ns;
    h->listing = false;
    h->done = false;
}

bool lr_rig_ahead_due(const lr_rig_ahead *h, int64_t now_ns)
{
    return !h->done && (double)(now_ns - h->changed_ns) * 1e-9 >= LR_RIG_AHEAD_REST_S;
}

int64_t lr_rig_ahead_wake_ns(const lr_rig_ahead *h)
{
    return h->done ? INT64_MAX : h->changed_ns + (int64_t)(LR_RIG_AHEAD_REST_S * 1e9);
}

static void record(void *user, const char *key, const char *value, unsigned dirty)
{
    (void)dirty;
    lr_rig_ahead *h = user;
    lr_async_state *s = &h->rec;
    int k = 0;
    while (k < s->n && strcmp(s->key[k], key) != 0)
        k++;
    if (k == s->n) {
        if (s->n == LR_ASYNC_STATE_SETS || strlen(key) >= sizeof s->key[0]) {
            h->rec_full = true;
            return;
        }
        s->n++;
    }
    if (strlen(value) >= sizeof s->value[0]) {
        h->rec_full = true;
        return;
    }
    snprintf(s->key[k], sizeof s->key[k], "%s", key);
    snprintf(s->value[k], sizeof s->value[k], "%s", value);
}

/* The candidates from the controls as they stand: cycles' other values (next, previous,
 * the rest), then each transport level binding's samples, nearest first. */
static void list_candidates(lr_rig_ahead *h, const lr_control_map *map, const lr_scene *scene)
{
    h->n_cand = h->next = h->n_st = 0;
    lr_cache_key keys[LR_CACHE_MAX_KEYS];
    int nk = 0;
    if (lr_rig_ahead_keys(map, scene, keys, LR_CACHE_MAX_KEYS, &nk, NULL))
        return;
    if (nk == 0)
        return; /* no control changes transport: nothing to build */
    /* First the state shown now: the sample an interpolation around it needs. */
    h->c[h->n_cand++] = (cand){-1, 0};
    int nb = lr_control_map_count(map);
    for (int i = 0; i < nb; i++) {
        const char *key = lr_control_map_key(map, i);
        bool cached = false;
        for (int k = 0; k < nk && !cached; k++)
            cached = key && strcmp(keys[k].name, key) == 0;
        if (!cached || !lr_control_map_is_cycle(map, i))
            continue;
        int nv = lr_control_map_values(map, i), cur = lr_control_map_index(map, i);
        int order[2 * 32];
        int no = 0;
        for (int d = 1; d <= nv / 2 + 1 && no < nv - 1; d++) {
            int up = (cur + d) % nv, down = ((cur - d) % nv + nv) % nv;
            bool seen_up = false, seen_down = false;
            for (int k = 0; k < no; k++) {
                seen_up |= order[k] == up;
                seen_down |= order[k] == down;
            }
            if (up != cur && !seen_up)
                order[no++] = up;
            if (down != cur && down != up && !seen_down && no < nv - 1)
                order[no++] = down;
        }
        for (int k = 0; k < no && h->n_cand < LR_ASYNC_MAX_STATES; k++)
            h->c[h->n_cand++] = (cand){i, order[k]};
    }
    for (int i = 0; i < nb; i++) {
        const char *key = lr_control_map_key(map, i);
        bool cached = false;
        for (int k = 0; k < nk && !cached; k++)
            cached = key && strcmp(keys[k].name, key) == 0;
        if (!cached || lr_control_map_is_cycle(map, i))
            continue;
        double x = lr_control_map_position(map, i);
        bool used[LR_ASYNC_MAX_STATES] = {false};
        for (int k = 0; k < h->samples && h->n_cand < LR_ASYNC_MAX_STATES; k++) {
            int best = -1;
            for (int j = 0; j < h->samples; j++) {
                double pj = (double)j / (h->samples - 1), pb = (double)best / (h->samples - 1);
                if (!used[j] && (best < 0 || fabs(pj - x) < fabs(pb - x)))
                    best = j;
            }
            used[best] = true;
            h->c[h->n_cand++] = (cand){i, (double)best / (h->samples - 1)};
        }
    }
}

int lr_rig_ahead_step(lr_rig_ahead *h, const lr_control_map *map, const lr_scene *scene,
                      const lr_replan *replan, int64_t now_ns, const lr_async_state **states,
                      int *n, bool *done, lr_err *e)
{
    if (!h->listing) {
        list_candidates(h, map, scene);
        h->listing = true;
    }
    while (h->next < h->n_cand) {
        cand c = h->c[h->next++];
        if (c.binding < 0) {
            h->st[h->n_st++] = (lr_async_state){0}; /* the scene as it is */
            break;
        }
        lr_scene *copy = NULL;
        int rc = lr_scene_clone(scene, NULL, &copy, e);
        if (rc)
            return lr_err_prefix(e, "states ahead");
        h->rec = (lr_async_state){0};
        h->rec_full = false;
        lr_scene_set_journal(copy, &(lr_scene_journal){record, h});
        unsigned dirty = 0;
        lr_err we = {0};
        bool ok = lr_control_map_what_if(map, c.binding, c.pos, copy, now_ns, &dirty, &we) ==
                  LR_OK;
        if (ok && replan && (dirty & LR_DIRTY_MATERIAL))
            ok = lr_replan_what_if(replan, copy, dirty, &dirty, &we) == LR_OK;
        lr_scene_destroy(copy);
        if (ok && !h->rec_full && h->rec.n > 0 && (dirty & ~BLEND_ONLY)) {
            h->st[h->n_st++] = h->rec;
            break; /* one state per step */
        }
    }
    h->done = h->next >= h->n_cand;
    *states = h->st;
    *n = h->n_st;
    *done = h->done;
    return LR_OK;
}
