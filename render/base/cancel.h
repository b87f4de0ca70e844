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
 * A plain value, not opaque: it is one atomic flag, embedded in its owner (lr_async) and
 * handed down as `const lr_cancel *`. NULL everywhere means "never cancelled" (the CPU twin,
 * the commands, the tests that do not cancel). Polling costs one relaxed atomic load.
 */
#ifndef LR_BASE_CANCEL_H
#define LR_BASE_CANCEL_H

#include <stdatomic.h>
#include <stdbool.h>

#include "render/base/err.h"

typedef struct lr_cancel {
    atomic_bool requested;
} lr_cancel;

static inline void lr_cancel_init(lr_cancel *c) { atomic_init(&c->requested, false); }
static inline void lr_cancel_request(lr_cancel *c) { atomic_store(&c->requested, true); }
static inline void lr_cancel_reset(lr_cancel *c) { atomic_store(&c->requested, false); }

/* True once requested (and until reset); false for NULL. */
static inline bool lr_cancel_requested(const lr_cancel *c)
{
    return c && atomic_load_explicit(&((lr_cancel *)c)->requested, memory_order_relaxed);
}

/* LR_ECANCELED with "WHAT: cancelled" in e when requested, else LR_OK. */
static inline int lr_cancel_check(const lr_cancel *c, const char *what, lr_err *e)
{
    return lr_cancel_requested(c) ? lr_err_set(e, LR_ECANCELED, "%s: cancelled", what) : LR_OK;
}

#endif
