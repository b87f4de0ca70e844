/* lamprig — progress of long work: the callback a step reports through (lr_progress) and the
 * one printer every command and tool shows it with (lr_progress_meter).
 *
 * A step calls lr_progress_report(p, "decode pose_02", done, total) as it goes. A NULL
 * lr_progress (or a NULL fn) means "nobody is listening"; reports are never used for control
 * flow. The meter turns reports into lines on stderr that say the stage, how far (done of
 * total), the time spent in the stage and an estimate of the time left (elapsed x
 * (total - done) / done: a straight-line guess, good for steps of equal cost):
 *
 *     lamprig fit: model renders 40/400 (10 %), 12 s elapsed, ~108 s left
 *
 * Rate-limited, so a log stays readable and a fast loop does not spend its time printing: on
 * a terminal one line rewritten in place (\r) at most every 0.25 s; otherwise plain lines, at
 * most one per second, plus the line that closes a stage already shown (so a shown stage
 * ends at total of total). LR_PROGRESS_QUIET prints nothing (the commands' --quiet).
 */
#ifndef LR_BASE_PROGRESS_H
#define LR_BASE_PROGRESS_H

#include <stdio.h>

#include "render/base/err.h"

typedef struct lr_progress {
    /* stage: what is being done (names the pose/folder); done of total units so far
     * (total <= 0: not known in advance). */
    void (*fn)(void *ctx, const char *stage, int done, int total);
    void *ctx;
} lr_progress;

static inline void lr_progress_report(const lr_progress *p, const char *stage, int done,
                                      int total)
{
    if (p && p->fn)
        p->fn(p->ctx, stage, done, total);
}

typedef enum lr_progress_style {
    LR_PROGRESS_AUTO = 0, /* TTY when out is a terminal, else LINES */
    LR_PROGRESS_LINES,
    LR_PROGRESS_TTY,
    LR_PROGRESS_QUIET,
} lr_progress_style;

typedef struct lr_progress_meter_desc {
    const char *prefix;       /* before each line ("lamprig fit"); NULL: none */
    lr_progress_style style;
    FILE *out;                /* NULL: stderr */
    double interval_s;        /* least time between lines; 0: 1 s (LINES), 0.25 s (TTY) */
    double (*clock)(void *ctx); /* seconds, monotonic; NULL: CLOCK_MONOTONIC (tests pass theirs) */
    void *clock_ctx;
} lr_progress_meter_desc;

typedef struct lr_progress_meter lr_progress_meter;

int lr_progress_meter_create(const lr_progress_meter_desc *d, lr_progress_meter **out,
                             lr_err *e);
/* Ends a line left open on a terminal. NULL is fine. */
void lr_progress_meter_destroy(lr_progress_meter *m);
/* What the steps take; valid until destroy. NULL m gives NULL (nobody listening). */
const lr_progress *lr_progress_meter_sink(lr_progress_meter *m);
/* Lines printed so far (for tests). */
int lr_progress_meter_lines(const lr_progress_meter *m);

#endif
