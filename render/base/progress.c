#include "render/base/progress.h"

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

struct lr_progress_meter {
    char prefix[96];
    lr_progress_style style; /* resolved: LINES, TTY or QUIET */
    FILE *out;
    double interval_s;
    double (*clock)(void *ctx);
    void *clock_ctx;
    lr_progress sink;
    char stage[256];
    int last_done;
    double stage_t0, last_line; /* last_line < 0: nothing printed yet */
    bool stage_shown, line_open;
    int lines;
};

static double mono_s(void *ctx)
{
    (void)ctx;
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void print_line(lr_progress_meter *m, const char *stage, int done, int total, double now)
{
    double el = now - m->stage_t0;
    char how[96] = "";
    if (total > 0 && done > 0 && done < total)
        snprintf(how, sizeof how, ", ~%.0f s left", el * (double)(total - done) / done);
    char text[512];
    if (total > 0)
        snprintf(text, sizeof text, "%s%s%s %d/%d (%.0f %%), %.0f s elapsed%s", m->prefix,
                 m->prefix[0] ? ": " : "", stage, done, total, 100.0 * done / total, el, how);
    else
        snprintf(text, sizeof text, "%s%s%s %d, %.0f s elapsed", m->prefix,
                 m->prefix[0] ? ": " : "", stage, done, el);
    if (m->style == LR_PROGRESS_TTY) {
        /* one line rewritten in place, cleared to its end; a finished stage keeps its line */
        fprintf(m->out, "\r%s\033[K", text);
        m->line_open = !(total > 0 && done >= total);
        if (!m->line_open)
            fputc('\n', m->out);
    } else {
        fprintf(m->out, "%s\n", text);
    }
    fflush(m->out);
    m->last_line = now;
    m->stage_shown = true;
    m->lines++;
}

static void report(void *ctx, const char *stage, int done, int total)
{
    lr_progress_meter *m = ctx;
    if (m->style == LR_PROGRESS_QUIET)
        return;
    double now = m->clock(m->clock_ctx);
    bool fresh = strncmp(m->stage, stage, sizeof m->stage - 1) != 0 || done < m->last_done;
    if (fresh) {
        if (m->line_open) { /* a new stage starts below the unfinished one */
            fputc('\n', m->out);
            m->line_open = false;
        }
        snprintf(m->stage, sizeof m->stage, "%s", stage);
        m->stage_t0 = now;
        m->stage_shown = false;
    }
    bool closes = total > 0 && done >= total && m->stage_shown && done != m->last_done;
    m->last_done = done;
    if (m->last_line < 0 || now - m->last_line >= m->interval_s || closes)
        print_line(m, stage, done, total, now);
}

int lr_progress_meter_create(const lr_progress_meter_desc *d, lr_progress_meter **out,
                             lr_err *e)
{
    *out = NULL;
    lr_progress_meter *m = calloc(1, sizeof *m);
    if (!m)
        return lr_err_set(e, LR_ENOMEM, "progress: out of memory");
    const lr_progress_meter_desc none = {0};
    if (!d)
        d = &none;
    snprintf(m->prefix, sizeof m->prefix, "%s", d->prefix ? d->prefix : "");
    m->out = d->out ? d->out : stderr;
    m->style = d->style;
    if (m->style == LR_PROGRESS_AUTO)
        m->style = isatty(fileno(m->out)) ? LR_PROGRESS_TTY : LR_PROGRESS_LINES;
    m->interval_s = d->interval_s > 0 ? d->interval_s : m->style == LR_PROGRESS_TTY ? 0.25 : 1.0;
    m->clock = d->clock ? d->clock : mono_s;
    m->clock_ctx = d->clock_ctx;
    m->last_line = -1;
    m->last_done = -1;
    m->sink = (lr_progress){report, m};
    *out = m;
    return LR_OK;
}

void lr_progress_meter_destroy(lr_progress_meter *m)
{
    if (!m)
        return;
    if (m->line_open) {
        fputc('\n', m->out);
        fflush(m->out);
    }
    free(m);
}

const lr_progress *lr_progress_meter_sink(lr_progress_meter *m)
{
    return m ? &m->sink : NULL;
}

int lr_progress_meter_lines(const lr_progress_meter *m)
{
    return m ? m->lines : 0;
}
