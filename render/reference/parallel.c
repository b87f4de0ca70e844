/* Fixed batches on pthreads: the caller's result is a sum over batches in batch order, so it
 * is the same on one core or many. */
#include "render/reference/ref_priv.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <unistd.h>

int lr_ref_cpu_count(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 ? (int)n : 1;
}

typedef struct pool {
    atomic_int next;
    int batches;
    void (*fn)(int, void *);
    void *user;
} pool;

static void *worker(void *arg)
{
    pool *p = arg;
    for (;;) {
        int b = atomic_fetch_add(&p->next, 1);
        if (b >= p->batches)
            return NULL;
        p->fn(b, p->user);
    }
}

int lr_ref_parallel(int batches, int threads, void (*fn)(int batch, void *user), void *user,
                    lr_err *e)
{
    if (batches <= 0)
        return LR_OK;
    int n = threads > 0 ? threads : lr_ref_cpu_count();
    if (n > batches)
        n = batches;
    pool p = {.batches = batches, .fn = fn, .user = user};
    atomic_init(&p.next, 0);
    if (n == 1) {
        worker(&p);
        return LR_OK;
    }
    pthread_t *tid = calloc((size_t)n, sizeof *tid);
    if (!tid)
        return lr_err_set(e, LR_ENOMEM, "reference: out of memory for %d threads", n);
    /* A thread that cannot be created only costs speed: the calling thread works too and
     * finishes whatever batches are left. */
    int started = 0;
    while (started < n - 1 && pthread_create(&tid[started], NULL, worker, &p) == 0)
        started++;
    worker(&p);
    for (int i = 0; i < started; i++)
        pthread_join(tid[i], NULL);
    free(tid);
    return LR_OK;
}
