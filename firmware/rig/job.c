/* lamprig firmware — work off the loop (see job.h). */
#include "firmware/rig/job.h"

#include <errno.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/eventfd.h>
#include <unistd.h>

typedef struct kept_line {
    lr_log_level level;
    char *msg;
} kept_line;

struct lr_rig_job {
    lr_rig_job_fn fn;
    void *arg;
    pthread_t thread;
    int efd;
    atomic_bool done;
    lr_log log; /* keep_line on this job */
    /* Written by the job's thread only, read by the loop only after the join. */
    kept_line *lines;
    int n_lines, cap_lines;
    unsigned dropped; /* lines not kept (out of memory) */
};

static void keep_line(void *user, lr_log_level level, const char *msg)
{
    lr_rig_job *j = user;
    if (j->n_lines == j->cap_lines) {
        int cap = j->cap_lines ? 2 * j->cap_lines : 16;
        kept_line *l = realloc(j->lines, (size_t)cap * sizeof *l);
        if (!l) {
            j->dropped++;
            return;
        }
        j->lines = l;
        j->cap_lines = cap;
    }
    char *copy = strdup(msg);
    if (!copy) {
        j->dropped++;
        return;
    }
    j->lines[j->n_lines++] = (kept_line){level, copy};
}

/* The job whose work runs on this thread (NULL on the loop's): what lr_rig_job_log_here asks. */
static _Thread_local const lr_rig_job *running;

static void *run(void *arg)
{
    lr_rig_job *j = arg;
    running = j;
    j->fn(j->arg, &j->log);
    running = NULL;
    atomic_store_explicit(&j->done, true, memory_order_release);
    uint64_t one = 1;
    /* An eventfd write of 1 cannot block or fail short of a counter at its maximum. */
    ssize_t w = write(j->efd, &one, sizeof one);
    (void)w;
    return NULL;
}

int lr_rig_job_start(lr_rig_job_fn fn, void *arg, lr_rig_job **out, lr_err *e)
{
    lr_rig_job *j = calloc(1, sizeof *j);
    if (!j)
        return lr_err_set(e, LR_ENOMEM, "job: out of memory");
    j->fn = fn;
    j->arg = arg;
    j->log = (lr_log){keep_line, j};
    atomic_init(&j->done, false);
    j->efd = eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
    if (j->efd < 0) {
        int err = errno;
        free(j);
        return lr_err_set(e, LR_EIO, "job: eventfd: %s", strerror(err));
    }
    /* *out before the thread starts: the work may look itself up through the caller's
     * pointer (lr_rig_job_log_here) from its first instruction. */
    *out = j;
    int rc = pthread_create(&j->thread, NULL, run, j);
    if (rc) {
        *out = NULL;
        close(j->efd);
        free(j);
        return lr_err_set(e, LR_EIO, "job: no thread: %s", strerror(rc));
    }
    return LR_OK;
}

bool lr_rig_job_done(const lr_rig_job *j)
{
    return atomic_load_explicit(&((lr_rig_job *)j)->done, memory_order_acquire);
}

int lr_rig_job_fd(const lr_rig_job *j) { return j->efd; }

void lr_rig_job_finish(lr_rig_job *j, const lr_log *to)
{
    if (!j)
        return;
    pthread_join(j->thread, NULL);
    for (int i = 0; i < j->n_lines; i++) {
        lr_log_write(to, j->lines[i].level, "%s", j->lines[i].msg);
        free(j->lines[i].msg);
    }
    if (j->dropped)
        lr_log_write(to, LR_LOG_WARN, "job: %u log lines lost (out of memory)", j->dropped);
    free(j->lines);
    close(j->efd);
    free(j);
}

const lr_log *lr_rig_job_log_here(const lr_rig_job *j, const lr_log *loop_log)
{
    if (j && running == j)
        return &j->log;
    return loop_log;
}
