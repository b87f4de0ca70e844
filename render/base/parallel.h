/* lamprig — the parallel loop of the CPU twin, the light paths and the models: independent
 * items on worker threads (pthreads). Each item writes only its own outputs and draws its
 * random numbers from its own key, so results do not depend on the number of threads or on
 * scheduling. */
#ifndef LR_BASE_PARALLEL_H
#define LR_BASE_PARALLEL_H

#include <stdbool.h>

#include "render/base/cancel.h"

typedef void (*lr_item_fn)(void *ctx, long item);

/* Number of online CPUs (at least 1). */
int lr_threads_default(void);

/* Runs fn(ctx, i) for i in [0, count) on `threads` threads (0: lr_threads_default()),
 * items handed out in chunks by an atomic counter; the calling thread works too. A thread that
 * cannot start only makes the loop slower: every item is run either way. */
void lr_parallel_for(long count, int threads, lr_item_fn fn, void *ctx);

/* The same, polling `cancel` (may be NULL) before each chunk: once it is requested at `level`
 * or above no new chunk starts (those under way finish), and the call returns false -- some
 * items did not run, so the outputs are incomplete and the caller must discard them. True:
 * every item ran. */
bool lr_parallel_for_cancel(long count, int threads, lr_item_fn fn, void *ctx,
                                const lr_cancel *cancel, enum lr_cancel_level level);

#endif
