/* lamprig — the control-space cache of render/async/ (issue 32, item 3): converged per-light
 * unit-intensity images of states the caller may ask for next, kept within a memory budget,
 * found again by the state's values, and interpolated between for a continuous control.
 *
 * A state is named by its *tag*: the text values (lr_scene_get) of a fixed list of scene keys
 * (the parameters the controls write, the models and settings a re-plan writes), everything
 * else being the scene as it stands. Both threads compute tags the same way from scenes that
 * went through the same changes, so a tag found equal is the same state.
 *
 * Lookup (lr_state_cache_find) for the tag of the state the caller shows now:
 *   exact         an entry with the same tag: its images are that state's converged images;
 *   interpolated  entries equal in every key but one marked LR_CACHE_LINEAR
 *                 (a material's scale), numbers per band (one number: the same in every band):
 *                 for each band separately, the two entries whose value in that band brackets
 *                 the state's, weighted by the position t between them in the value, their
 *                 images combined
 *                 geometrically, lo^(1-t) hi^t per pixel (render/passes/mix.h): light through
 *                 an absorbing, scattering medium is a sum over paths of exponentials in the
 *                 coefficients' scale s, A_p exp(-c_p s), so ln(image) is convex and close to
 *                 linear in s where the image itself curves strongly (a factor of 2 in the
 *                 scale of a candle's wax changes its emergent light by 4 to 10). Per band
 *                 because light
 *                 transport at one wavelength depends on the material's coefficients at that
 *                 wavelength alone (seed 003's passes run each RGB band on its own
 *                 coefficients): one row of samples along a scale answers both a uniform
 *                 scale knob and a tint that scales the bands differently.
 * A band no pair brackets (outside the samples) makes the lookup miss: the caller falls back
 * to rendering. Interpolation error against the exact state is bounded by the samples'
 * spacing: a chord of ln(image) errs by at most h^2/8 max|(ln f)''| per pixel (h the spacing
 * in the interpolation variable); tests/render/test_async_cache.c checks it.
 *
 * Storage: an entry owns an RGBA32F 2D array (layer l: light l's image) in the share group of
 * both contexts. Entries are made on the worker's thread (lr_state_cache_store) and read on
 * the caller's; the caller pins what it shows, and eviction (least recently used first, when a
 * new entry would exceed the budget) never takes a pinned entry. Not thread-safe: render/async/
 * calls every function under its mutex, except lr_state_cache_destroy.
 */
#ifndef LR_ASYNC_CACHE_H
#define LR_ASYNC_CACHE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "render/base/err.h"
#include "render/gl/gl.h"
#include "render/gl/tex.h"
#include "render/scene/scene.h"

#define LR_CACHE_MAX_KEYS 24
#define LR_CACHE_VALUE_MAX 96
#define LR_CACHE_KEY_MAX 96
/* Entries blended for one interpolated state: two per band. */
#define LR_CACHE_MIX_MAX 6

typedef enum lr_cache_interp {
    LR_CACHE_EXACT = 0, /* matched as text only */
    LR_CACHE_LINEAR,    /* numbers per band, interpolated by position in the value */
} lr_cache_interp;

typedef struct lr_cache_key {
    char name[LR_CACHE_KEY_MAX];
    lr_cache_interp interp;
} lr_cache_key;

typedef struct lr_state_tag {
    int n;
    char value[LR_CACHE_MAX_KEYS][LR_CACHE_VALUE_MAX];
} lr_state_tag;

/* The tag of scene s over keys[0..n-1]. Errors: a key the scene does not have (named). */
int lr_state_tag_of(const lr_scene *s, const lr_cache_key *keys, int n, lr_state_tag *out,
                    lr_err *e);
bool lr_state_tag_equal(const lr_state_tag *a, const lr_state_tag *b);

/* What a lookup found: images entry[k] weighted per band by w[k] (summing to 1 per band). */
typedef struct lr_cache_mix {
    int n;
    int entry[LR_CACHE_MIX_MAX];
    double w[LR_CACHE_MIX_MAX][3];
    bool exact; /* one entry, weight 1: the state itself */
} lr_cache_mix;

typedef struct lr_state_cache lr_state_cache;

/* keys are copied; budget_bytes 0: nothing is stored. */
int lr_state_cache_create(const lr_cache_key *keys, int n_keys, size_t budget_bytes,
                          lr_state_cache **out, lr_err *e);
/* Frees the entries' textures: call on a thread with a context of their share group current,
 * once neither thread reads them. */
void lr_state_cache_destroy(lr_state_cache *c);

const lr_cache_key *lr_state_cache_keys(const lr_state_cache *c, int *n);
/* Whether key is one of the cache's keys (a change to any other flushes the cache). */
bool lr_state_cache_has_key(const lr_state_cache *c, const char *key);

/* Finds tag: true with *mix filled when an exact entry or an interpolation covers it (the
 * entries used are marked used now, for the eviction order). */
bool lr_state_cache_find(lr_state_cache *c, const lr_state_tag *tag, lr_cache_mix *mix);
/* Whether tag has an entry of its own. */
bool lr_state_cache_holds(const lr_state_cache *c, const lr_state_tag *tag);

/* Whether an entry of `bytes` more would fit after evicting unpinned entries. */
bool lr_state_cache_fits(const lr_state_cache *c, size_t bytes);
/* Takes ownership of tex (n layers; scale[l] the renderer's per-light scale, the blend's
 * divisor) as the entry for tag, evicting least recently used unpinned entries as needed.
 * false (tex destroyed) when it cannot fit. The texture must be complete on the GPU (the
 * worker finished it) before the caller may read it. */
bool lr_state_cache_store(lr_state_cache *c, const lr_state_tag *tag, lr_tex *tex, int n,
                          const float *scale, size_t bytes);
/* Evicted textures wait here until the thread that owns the GL work deletes them
 * (lr_state_cache_reap): the caller may still blend from a texture the worker evicts. */
void lr_state_cache_reap(lr_state_cache *c);

/* Drops every entry not pinned (a change outside the keys makes them stale); pinned ones are
 * dropped when unpinned. */
void lr_state_cache_flush(lr_state_cache *c);

/* Frees every entry, pinned or not, and the reaped textures (the worker's exit: its context
 * made them and neither thread reads them any more). */
void lr_state_cache_drop_all(lr_state_cache *c);

void lr_state_cache_pin(lr_state_cache *c, const lr_cache_mix *mix);
void lr_state_cache_unpin(lr_state_cache *c, const lr_cache_mix *mix);

/* Entry k's images and per-light scale (k from a mix). */
const lr_tex *lr_state_cache_images(const lr_state_cache *c, int k, int *n, const float **scale);

typedef struct lr_state_cache_stats {
    int entries;
    size_t bytes, budget;
    uint64_t stored, evicted, flushed, hits_exact, hits_interp, misses;
} lr_state_cache_stats;
void lr_state_cache_get_stats(const lr_state_cache *c, lr_state_cache_stats *st);

#endif
