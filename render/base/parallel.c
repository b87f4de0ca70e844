#include "render/base/parallel.h"

#include <pthread.h>
#include <stdatomic.h>
#include <unistd.h>

#define LR_CPU_MAX_THREADS 64
#define LR_CPU_CHUNK 16

typedef struct job {
    atomic_long next;
    long count;
    lr_item_fn fn;
    void *ctx;
    const lr_cancel *cancel;
    enum lr_cancel_level level;
    atomic_bool stopped;
} job;

int lr_threads_default(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    if (n < 1)
        n = 1;
    return n > LR_CPU_MAX_THREADS ? LR_CPU_MAX_THREADS : (int)n;
}

static void *worker(void *p)
{
    job *j = p;
    for (;;) {
        if (lr_cancel_at(j->cancel, j->level)) {
            atomic_store(&j->stopped, true);
            break;
        }
        long start = atomic_fetch_add(&j->next, LR_CPU_CHUNK);
        if (start >= j->count)
            break;
        long end = start + LR_CPU_CHUNK < j->count ? start + LR_CPU_CHUNK : j->count;
        for (long i = start; i < end; i++)
            j->fn(j->ctx, i);
    }
    return NULL;
}

void lr_parallel_for(long count, int threads, lr_item_fn fn, void *ctx)
{
    (void)lr_parallel_for_cancel(count, threads, fn, ctx, NULL, LR_CANCEL_STALE);
}

bool lr_parallel_for_cancel(long count, int threads, lr_item_fn fn, void *ctx,
                                const lr_cancel *cancel, enum lr_cancel_level level)
{
    if (threads <= 0)
        threads = lr_threads_default();
    if (threads > LR_CPU_MAX_THREADS)
        threads = LR_CPU_MAX_THREADS;
    job j = {.count = count, .fn = fn, .ctx = ctx, .cancel = cancel, .level = level};
    atomic_init(&j.next, 0);
    atomic_init(&j.stopped, false);
    pthread_t tid[LR_CPU_MAX_THREADS];
    int started = 0;
    for (int t = 1; t < threads && t < count; t++) {
        if (pthread_create(&tid[started], NULL, worker, &j) != 0)
            break;
        started++;
    }
    worker(&j); /* the calling thread works too */
    for (int t = 0; t < started; t++)
        pthread_join(tid[t], NULL);
    /* A thread that saw the request after the last chunk was taken ran nothing less. */
    return !atomic_load(&j.stopped) || atomic_load(&j.next) >= count;
}
