/* lamprig firmware — one piece of the rig's work off the loop, on a thread of its own.
 *
 * Loading and planning a scene, or a whole config on reload, takes 0.1–1 s on the proxy:
 * many frame intervals, in which the devices, the events, the watchdog and the page flips
 * must still be serviced (the loop never waits). The rig starts such work as a job, keeps
 * turning, and collects the result when the job's descriptor becomes readable.
 *
 * The work gets a log of its own: its lines are kept in order and written to the rig's log by
 * lr_rig_job_finish, on the loop, so that the rig's log (its status lists of warnings and
 * errors) has one writer. Nothing else is shared: the work reads only what the loop leaves
 * alone while the job runs, and writes only into its own argument.
 *
 *   lr_rig_job *j;
 *   lr_rig_job_start(load, arg, &j, &e);       // load(arg, log) runs on the job's thread
 *   ... poll lr_rig_job_fd(j) with the rest (readable once load has returned) ...
 *   if (lr_rig_job_done(j)) { lr_rig_job_finish(j, &rig_log); use(arg); }
 */
#ifndef LR_RIG_JOB_H
#define LR_RIG_JOB_H

#include <stdbool.h>

#include "hal/log.h"
#include "render/base/err.h"

typedef struct lr_rig_job lr_rig_job;

/* The work: runs once on the job's thread; `log` keeps its lines for the loop. */
typedef void (*lr_rig_job_fn)(void *arg, const lr_log *log);

/* Starts fn(arg) on a new thread; *out is set before the thread starts (NULL again on
 * failure). LR_ENOMEM, or LR_EIO when no thread or eventfd can be made (then nothing runs). */
int lr_rig_job_start(lr_rig_job_fn fn, void *arg, lr_rig_job **out, lr_err *e);
/* Whether fn has returned (never blocks). */
bool lr_rig_job_done(const lr_rig_job *j);
/* Readable from the moment fn has returned: for the loop's poll set. */
int lr_rig_job_fd(const lr_rig_job *j);
/* Joins the thread (waiting for fn when not done: only at shutdown or for a caller that asked
 * to wait), writes the kept lines to `to` in order, and frees the job. NULL is a no-op. */
void lr_rig_job_finish(lr_rig_job *j, const lr_log *to);

/* The log a job's work writes through, for code that runs in the job and in the loop alike:
 * the job's keeping log while on `j`'s thread, else `loop_log`. */
const lr_log *lr_rig_job_log_here(const lr_rig_job *j, const lr_log *loop_log);

#endif
