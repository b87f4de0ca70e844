/* lamprig calib — progress reports from long steps (capture, decoding, calibration).
 *
 * A step calls lr_progress_report(p, "decode pose_02", done, total) as it goes; the CLI
 * prints a line to stderr, a future UI may draw a bar. A NULL lr_progress (or a NULL fn)
 * means "nobody is listening". Reports are never used for control flow.
 */
#ifndef LR_CALIB_PROGRESS_H
#define LR_CALIB_PROGRESS_H

typedef struct lr_progress {
    /* stage: what is being done (names the pose/folder); done of total units so far. */
    void (*fn)(void *ctx, const char *stage, int done, int total);
    void *ctx;
} lr_progress;

static inline void lr_progress_report(const lr_progress *p, const char *stage, int done,
                                      int total)
{
    if (p && p->fn)
        p->fn(p->ctx, stage, done, total);
}

#endif
