/* lamprig firmware — run statistics (see stats.h). */
#include "firmware/rig/stats.h"

#include "firmware/rig/lat_hist.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/atomic_file.h"
#include "render/base/json_write.h"

#define LOG_MAX 4096

#define PENDING_MAX 1024

typedef struct ev_rec {
    lr_event ev;
    uint64_t frame;
    double latency_ms;
    int stage; /* lr_rig_frame_info.stage of the frame that first showed it */
    double converge_ms; /* to the first converged frame showing it; NaN: not yet */
    bool rested;        /* the newest event that converged frame shows: the controls rested */
} ev_rec;

typedef struct fr_rec {
    lr_frame_stats f;
    int64_t t_ns;
    lr_rig_frame_info info;
} fr_rec;

/* An event waiting for a frame that shows it, and then for one that shows it converged. */
typedef struct pend_rec {
    lr_event ev;
    uint64_t batch; /* UNTAGGED until the loop applied it */
    bool shown;
    uint64_t ev_index; /* its ev_rec once shown */
} pend_rec;

#define UNTAGGED UINT64_MAX

struct lr_rig_stats {
    int64_t start_ns;
    /* A ring, oldest first from pending_head: with no converged frame (a flickering scene)
     * it stays full, and dropping the oldest by moving the other 1023 (120 KiB) cost more
     * than everything else an event does. */
    pend_rec pending[PENDING_MAX];
    int pending_head, n_pending;
    uint64_t dropped_pending;
    ev_rec *events; /* ring of LOG_MAX */
    uint64_t n_events;
    fr_rec *frames; /* ring of LOG_MAX */
    uint64_t n_frames;
    uint64_t unmatched;
    uint64_t ar_frames;
    double ar_last_px, ar_last_light, ar_max_px, ar_max_light;
    /* Every latency, for quantiles, in constant memory: a rig runs for months. */
    lr_lat_hist *lat;
    lr_lat_hist *conv; /* event -> first converged frame showing it */
    lr_lat_hist *settle; /* the same for the newest event each converged frame shows */
};

int lr_rig_stats_create(int64_t start_ns, lr_rig_stats **out, lr_err *e)
{
    lr_rig_stats *s = calloc(1, sizeof *s);
    if (s) {
        s->events = calloc(LOG_MAX, sizeof *s->events);
        s->frames = calloc(LOG_MAX, sizeof *s->frames);
        s->lat = lr_lat_hist_create();
        s->conv = lr_lat_hist_create();
        s->settle = lr_lat_hist_create();
    }
    if (!s || !s->events || !s->frames || !s->lat || !s->conv || !s->settle) {
        lr_rig_stats_destroy(s);
        return lr_err_set(e, LR_ENOMEM, "out of memory");
    }
    s->start_ns = start_ns;
    *out = s;
    return LR_OK;
}

void lr_rig_stats_destroy(lr_rig_stats *s)
{
    if (!s)
        return;
    free(s->events);
    free(s->frames);
    lr_lat_hist_destroy(s->lat);
    lr_lat_hist_destroy(s->conv);
    lr_lat_hist_destroy(s->settle);
    free(s);
}

/* The i-th pending event, oldest first. */
static pend_rec *pending_at(lr_rig_stats *s, int i)
{
    return &s->pending[(s->pending_head + i) % PENDING_MAX];
}

void lr_rig_stats_event(lr_rig_stats *s, const lr_event *ev)
{
    if (s->n_pending == PENDING_MAX) {
        /* A frame that never comes (renderer failing): keep the newest. */
        s->pending_head = (s->pending_head + 1) % PENDING_MAX;
        s->n_pending--;
        s->dropped_pending++;
    }
    *pending_at(s, s->n_pending++) = (pend_rec){.ev = *ev, .batch = UNTAGGED};
}

/* The untagged events are the newest ones: an event joins untagged at the end, a tag tags
 * all of them and frames keep the order. So the scan stops at the first tagged one from the
 * end (with 1024 waiting it was a third of a frame's bookkeeping). */
void lr_rig_stats_tag(lr_rig_stats *s, uint64_t batch)
{
    for (int i = s->n_pending - 1; i >= 0 && pending_at(s, i)->batch == UNTAGGED; i--)
        pending_at(s, i)->batch = batch;
}

void lr_rig_stats_unmatched(lr_rig_stats *s) { s->unmatched++; }

void lr_rig_stats_ar(lr_rig_stats *s, double clipped_pixels, double clipped_light)
{
    s->ar_frames++;
    s->ar_last_px = clipped_pixels;
    s->ar_last_light = clipped_light;
    s->ar_max_px = fmax(s->ar_max_px, clipped_pixels);
    s->ar_max_light = fmax(s->ar_max_light, clipped_light);
}

void lr_rig_stats_frame(lr_rig_stats *s, const lr_frame_stats *f, int64_t done_ns)
{
    /* The renderer on the loop: every frame shows everything applied before it. */
    lr_rig_frame_info info = {.batch = UNTAGGED - 1,
                              .stage = f->converged ? LR_ASYNC_FINAL : LR_ASYNC_REFINING,
                              .converged = f->converged};
    lr_rig_stats_tag(s, 0);
    lr_rig_stats_frame_shown(s, f, &info, done_ns);
}

void lr_rig_stats_frame_shown(lr_rig_stats *s, const lr_frame_stats *f,
                              const lr_rig_frame_info *info, int64_t done_ns)
{
    fr_rec *r = &s->frames[s->n_frames % LOG_MAX];
    r->f = *f;
    r->t_ns = done_ns;
    r->info = *info;
    s->n_frames++;
    /* A frame that ran no pass re-presents the previous image: it shows no event yet (the
     * first frame of a fade, still at the old level, is one). */
    if (!f->passes)
        return;
    /* The newest event a converged frame shows: from it on the controls rested until that
     * image, so its time is the time to converge after a rest (stats.h: settle_ms). */
    int newest = -1;
    for (int i = 0; info->converged && i < s->n_pending; i++) {
        const pend_rec *p = pending_at(s, i);
        if (p->batch != UNTAGGED && p->batch <= info->batch &&
            (newest < 0 || p->ev.t_ns >= pending_at(s, newest)->ev.t_ns))
            newest = i;
    }
    int keep = 0;
    for (int i = 0; i < s->n_pending; i++) {
        pend_rec *p = pending_at(s, i);
        /* Untagged: applied after this frame's images were chosen; a later batch: the images
         * shown are older than the change. */
        bool shows = p->batch != UNTAGGED && p->batch <= info->batch;
        double ms = (double)(done_ns - p->ev.t_ns) * 1e-6;
        /* A device clock ahead of ours (never with CLOCK_MONOTONIC stamps) reads as 0. */
        if (ms < 0)
            ms = 0;
        if (shows && !p->shown) {
            ev_rec *er = &s->events[s->n_events % LOG_MAX];
            er->ev = p->ev;
            er->frame = (uint64_t)f->index;
            er->latency_ms = ms;
            er->stage = info->stage;
            er->converge_ms = NAN;
            er->rested = false;
            p->ev_index = s->n_events;
            s->n_events++;
            lr_lat_hist_add(s->lat, ms);
            p->shown = true;
        }
        if (shows && info->converged) {
            lr_lat_hist_add(s->conv, ms);
            bool last = LOG_MAX >= s->n_events - p->ev_index;
            if (last)
                s->events[p->ev_index % LOG_MAX].converge_ms = ms;
            if (i == newest) {
                lr_lat_hist_add(s->settle, ms);
                if (last)
                    s->events[p->ev_index % LOG_MAX].rested = true;
            }
            continue; /* done with */
        }
        /* Kept in order; keep <= i, so this never overwrites one not yet read. */
        if (keep != i)
            *pending_at(s, keep) = *p;
        keep++;
    }
    s->n_pending = keep;
}

/* Events not shown by any frame yet (those shown and waiting for a converged frame are not
 * pending: they have their latency). */
int lr_rig_stats_pending(const lr_rig_stats *s)
{
    int n = 0;
    for (int i = 0; i < s->n_pending; i++)
        n += !s->pending[(s->pending_head + i) % PENDING_MAX].shown;
    return n;
}
uint64_t lr_rig_stats_frames(const lr_rig_stats *s) { return s->n_frames; }
uint64_t lr_rig_stats_events(const lr_rig_stats *s) { return s->n_events; }

double lr_rig_stats_latency_ms(const lr_rig_stats *s, double q)
{
    return lr_lat_hist_quantile(s->lat, q);
}

double lr_rig_stats_converge_ms(const lr_rig_stats *s, double q)
{
    return lr_lat_hist_quantile(s->conv, q);
}

double lr_rig_stats_settle_ms(const lr_rig_stats *s, double q)
{
    return lr_lat_hist_quantile(s->settle, q);
}

/* "NAME": {"n", "median", "p99", "max"} of a histogram. */
static void write_summary(lr_jw *w, const char *name, const lr_lat_hist *h)
{
    lr_jw_object(w, name);
    lr_jw_int(w, "n", (long)lr_lat_hist_n(h));
    lr_jw_number_or_null(w, "median", lr_lat_hist_quantile(h, 0.5));
    lr_jw_number_or_null(w, "p99", lr_lat_hist_quantile(h, 0.99));
    lr_jw_number_or_null(w, "max", lr_lat_hist_max(h));
    lr_jw_object_end(w);
}

static void write_devices(lr_jw *w, const lr_rig_stats_dev *devs, int n)
{
    lr_jw_array(w, "devices");
    for (int i = 0; i < n; i++) {
        const lr_rig_stats_dev *d = &devs[i];
        lr_jw_object(w, NULL);
        lr_jw_string(w, "name", d->name);
        lr_jw_string(w, "kind", d->kind);
        lr_jw_string(w, "state", d->state);
        if (d->modbus) {
            const lr_modbus_counters *c = d->modbus;
            lr_jw_object(w, "modbus");
            lr_jw_int(w, "requests", (long)c->requests);
            lr_jw_int(w, "responses", (long)c->responses);
            lr_jw_int(w, "timeouts", (long)c->timeouts);
            lr_jw_int(w, "stale", (long)c->stale);
            lr_jw_int(w, "bad_responses", (long)c->bad_responses);
            lr_jw_int(w, "crc_errors", (long)c->crc_errors);
            lr_jw_int(w, "exceptions", (long)c->exceptions);
            lr_jw_int(w, "last_exception", (long)c->last_exception);
            lr_jw_int(w, "io_errors", (long)c->io_errors);
            lr_jw_int(w, "connects", (long)c->connects);
            lr_jw_int(w, "writes", (long)c->writes);
            lr_jw_object_end(w);
        }
        if (d->n_input > 0) {
            lr_jw_object(w, "input");
            for (int k = 0; k < d->n_input; k++) {
                char key[96];
                snprintf(key, sizeof key, "%s%s", d->input[k].prefix, d->input[k].name);
                lr_jw_int(w, key, (long)d->input[k].value);
            }
            lr_jw_object_end(w);
        }
        lr_jw_object_end(w);
    }
    lr_jw_array_end(w);
}

int lr_rig_stats_write(const lr_rig_stats *s, const char *path, const char *config,
                       int64_t now_ns, unsigned garbage, const lr_rig_stats_dev *devs,
                       int n_devs, lr_err *e)
{
    lr_atomic_file *af;
    /* The rig's state: the service's group reads it, others not. */
    int rc = lr_atomic_file_open_mode(path, LR_FILE_MODE_PRIVATE, &af, e);
    if (rc)
        return rc;
    lr_jw *w = lr_jw_create(lr_atomic_file_stream(af));
    if (!w) {
        lr_atomic_file_abort(af);
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
    }
    lr_jw_object(w, NULL);
    if (config)
        lr_jw_string(w, "config", config);
    else
        lr_jw_null(w, "config");
    lr_jw_number(w, "duration_s", (double)(now_ns - s->start_ns) * 1e-9);
    lr_jw_int(w, "frames", (long)s->n_frames);
    lr_jw_int(w, "events", (long)s->n_events);
    lr_jw_int(w, "events_pending", lr_rig_stats_pending(s));
    lr_jw_int(w, "events_converging", s->n_pending - lr_rig_stats_pending(s));
    lr_jw_int(w, "events_unmatched", (long)s->unmatched);
    lr_jw_int(w, "garbage", (long)garbage);
    write_devices(w, devs, n_devs);
    if (s->ar_frames) {
        lr_jw_object(w, "ar");
        lr_jw_int(w, "frames", (long)s->ar_frames);
        lr_jw_number_or_null(w, "clipped_pixels", s->ar_last_px);
        lr_jw_number_or_null(w, "clipped_light", s->ar_last_light);
        lr_jw_number_or_null(w, "max_clipped_pixels", s->ar_max_px);
        lr_jw_number_or_null(w, "max_clipped_light", s->ar_max_light);
        lr_jw_object_end(w);
    }
    const lr_lat_hist *h = s->lat;
    lr_jw_object(w, "latency_ms");
    lr_jw_int(w, "n", (long)lr_lat_hist_n(h));
    lr_jw_number_or_null(w, "min", lr_lat_hist_min(h));
    lr_jw_number_or_null(w, "median", lr_lat_hist_quantile(h, 0.5));
    lr_jw_number_or_null(w, "p99", lr_lat_hist_quantile(h, 0.99));
    lr_jw_number_or_null(w, "max", lr_lat_hist_max(h));
    lr_jw_number_or_null(w, "mean", lr_lat_hist_mean(h));
    lr_jw_object_end(w);
    write_summary(w, "converge_ms", s->conv);
    write_summary(w, "settle_ms", s->settle);
    lr_jw_array(w, "event_log");
    uint64_t first = s->n_events > LOG_MAX ? s->n_events - LOG_MAX : 0;
    for (uint64_t i = first; i < s->n_events; i++) {
        const ev_rec *r = &s->events[i % LOG_MAX];
        lr_jw_object(w, NULL);
        lr_jw_string(w, "source", r->ev.source);
        lr_jw_string(w, "control", r->ev.control);
        lr_jw_string(w, "kind", lr_event_kind_name(r->ev.kind));
        lr_jw_number_or_null(w, "value", r->ev.value);
        lr_jw_number(w, "t_s", (double)(r->ev.t_ns - s->start_ns) * 1e-9);
        lr_jw_int(w, "frame", (long)r->frame);
        lr_jw_number_or_null(w, "latency_ms", r->latency_ms);
        lr_jw_string(w, "stage", lr_async_stage_name((lr_async_stage)r->stage));
        lr_jw_number_or_null(w, "converge_ms", r->converge_ms);
        lr_jw_bool(w, "rested", r->rested);
        lr_jw_object_end(w);
    }
    lr_jw_array_end(w);
    lr_jw_array(w, "frame_log");
    first = s->n_frames > LOG_MAX ? s->n_frames - LOG_MAX : 0;
    for (uint64_t i = first; i < s->n_frames; i++) {
        const fr_rec *r = &s->frames[i % LOG_MAX];
        lr_jw_object(w, NULL);
        lr_jw_int(w, "index", r->f.index);
        lr_jw_number(w, "t_s", (double)(r->t_ns - s->start_ns) * 1e-9);
        lr_jw_array(w, "passes");
        for (int p = 0; p < LR_PASS_COUNT; p++)
            if (r->f.passes & (1u << p))
                lr_jw_string(w, NULL, lr_pass_name(p));
        lr_jw_array_end(w);
        lr_jw_array(w, "ms");
        for (int p = 0; p < LR_PASS_COUNT; p++)
            lr_jw_number_or_null(w, NULL, r->f.ms[p]);
        lr_jw_array_end(w);
        lr_jw_number_or_null(w, "total_ms", r->f.total_ms);
        lr_jw_int(w, "samples", r->f.samples);
        lr_jw_bool(w, "converged", r->f.converged);
        lr_jw_string(w, "stage", lr_async_stage_name(r->info.stage));
        if (r->info.batch < UNTAGGED - 1)
            lr_jw_int(w, "batch", (long)r->info.batch);
        lr_jw_object_end(w);
    }
    lr_jw_array_end(w);
    lr_jw_object_end(w);
    if ((rc = lr_jw_finish(w, e))) {
        lr_atomic_file_abort(af);
        return rc;
    }
    return lr_atomic_file_commit(af, e);
}
