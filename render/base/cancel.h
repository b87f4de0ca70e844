/* lamprig — asking long work to stop early: a cancellation token.
 *
 * The rig's renderer runs on a worker thread (render/async/async.h); a frame there can hold a
 * CPU solve of seconds (the diffusion grid, translucent radiosity's F and S, the receiver
 * bounce). When the state it solves for is already stale (a newer change arrived) or the
 * worker is retired (a scene switch, exit), finishing it only delays the next image and takes
 * CPU from the new one. The owner of a lr_cancel requests it from any thread; long steps poll
 * it at points where stopping leaves their state consistent (between solver iterations, between
 * chunks of a parallel loop, between passes) and return LR_ECANCELED without committing a
 * partial result, so that the next call redoes the work from a clean state.
 *
 * A plain value, not opaque: it is one atomic level, embedded in its owner (lr_async) and
 * handed down as `const lr_cancel *`. NULL everywhere means "never cancelled" (the CPU twin,
 * the commands, the tests that do not cancel). Polling costs one relaxed atomic load.
 */
#ifndef LR_BASE_CANCEL_H
#define LR_BASE_CANCEL_H

#include <stdatomic.h>
#include <stdbool.h>

#include "render/base/err.h"

/* How much to cut. A stale state cuts its solves (they are redone for the new state anyway);
 * the builds of caches that outlive the state (translucent radiosity's F and S, the receiver
 * bounce's F: keyed by geometry and stored on disk) run to their end unless the owner stops,
 * so that a knob turned every second does not throw the same seconds-long build away again
 * and again. */
enum lr_cancel_level {
    LR_CANCEL_STALE = 1,   /* the result is no longer wanted: cut solves and passes */
    LR_CANCEL_RESTART = 2, /* ... and the new state restarts the maps' running mean: cut
                            * inside their accumulation too (a partial frame there is only
                            * thrown away by the restart; render/passes/slice.h) */
    LR_CANCEL_STOP = 3,    /* the owner ends: cut everything, builds too */
};

typedef struct lr_cancel {
    atomic_int level; /* 0: not requested */
} lr_cancel;

static inline void lr_cancel_init(lr_cancel *c) { atomic_init(&c->level, 0); }
/* Raises the request to `level` (a stop is never lowered to stale). */
static inline void lr_cancel_request(lr_cancel *c, enum lr_cancel_level level)
{
    int cur = atomic_load(&c->level);
    while (cur < (int)level && !atomic_compare_exchange_weak(&c->level, &cur, (int)level))
        ;
}
static inline void lr_cancel_reset(lr_cancel *c) { atomic_store(&c->level, 0); }

/* True once requested at `level` or above (and until reset); false for NULL. */
static inline bool lr_cancel_at(const lr_cancel *c, enum lr_cancel_level level)
{
    return c && atomic_load_explicit(&((lr_cancel *)c)->level, memory_order_relaxed) >= (int)level;
}
/* Any request (a solve's poll). */
static inline bool lr_cancel_requested(const lr_cancel *c) { return lr_cancel_at(c, LR_CANCEL_STALE); }

/* LR_ECANCELED with "WHAT: cancelled" in e when requested at `level` or above, else LR_OK. */
static inline int lr_cancel_check_at(const lr_cancel *c, enum lr_cancel_level level,
                                     const char *what, lr_err *e)
{
    return lr_cancel_at(c, level) ? lr_err_set(e, LR_ECANCELED, "%s: cancelled", what) : LR_OK;
}
static inline int lr_cancel_check(const lr_cancel *c, const char *what, lr_err *e)
{
    return lr_cancel_check_at(c, LR_CANCEL_STALE, what, e);
}

#endif
