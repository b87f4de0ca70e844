/* lamprig — per-pass milliseconds for the stats and the bench.
 *
 * GPU time from EXT_disjoint_timer_query where the driver has it; otherwise (or when asked)
 * CPU wall time around each section with glFinish on both ends, which measures the pass
 * alone but serialises CPU and GPU, so frames run slower while it is on. Sections are timed
 * one after another (GL time-elapsed queries cannot nest):
 *
 *     lr_timer_begin(t, "gbuffer", &e); ...draw...; lr_timer_end(t, &e);
 *     lr_timer_begin(t, "radiosity", &e); ...;       lr_timer_end(t, &e);
 *     lr_timer_collect(t, &e);   // waits for the results
 *     for (i < lr_timer_count(t)) lr_timer_name(t, i), lr_timer_ms(t, i)
 *     lr_timer_reset(t);         // next frame
 */
#ifndef LR_TIMER_H
#define LR_TIMER_H

#include <stdbool.h>

#include "render/base/err.h"
#include "render/gl/gl.h"

typedef struct lr_timer lr_timer;

typedef struct lr_timer_desc {
    int max_sections; /* per frame; 0 means 16 */
    bool cpu;         /* force glFinish + CPU clock even where GPU queries exist */
} lr_timer_desc;

int lr_timer_create(lr_gl *gl, const lr_timer_desc *desc, lr_timer **out, lr_err *e);
void lr_timer_destroy(lr_timer *t);

/* True when sections are measured by GPU timer queries. */
bool lr_timer_is_gpu(const lr_timer *t);

/* Starts a section (name copied, up to 31 characters). LR_EINVAL when a section is open or
 * max_sections are used. */
int lr_timer_begin(lr_timer *t, const char *name, lr_err *e);
int lr_timer_end(lr_timer *t, lr_err *e);
/* Waits for every ended section's result. LR_EIO when the GPU reported a disjoint event
 * (clock change, power state): that frame's times are meaningless and are set to NaN. */
int lr_timer_collect(lr_timer *t, lr_err *e);
/* Forgets this frame's sections. */
void lr_timer_reset(lr_timer *t);

int lr_timer_count(const lr_timer *t);
const char *lr_timer_name(const lr_timer *t, int i);
/* Milliseconds of section i after lr_timer_collect. */
double lr_timer_ms(const lr_timer *t, int i);

#endif
