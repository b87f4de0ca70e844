/* lamprig firmware — the status document (see status_json.h). */
#include "firmware/rig/status_json.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static void control(lr_jw *w, const lr_rig_status_control *c)
{
    lr_jw_object(w, NULL);
    lr_jw_string(w, "name", c->name);
    lr_jw_string(w, "source", c->source);
    lr_jw_string(w, "control", c->control);
    lr_jw_string(w, "param", c->param);
    lr_jw_string(w, "kind", c->cycle ? "cycle" : "level");
    if (c->cycle) {
        lr_jw_int(w, "index", c->index);
        lr_jw_array(w, "values");
        for (int i = 0; i < c->n_values; i++)
            lr_jw_string(w, NULL, c->values[i]);
        lr_jw_array_end(w);
    } else {
        lr_jw_number_or_null(w, "position", c->position);
        lr_jw_number_or_null(w, "level", c->level);
    }
    lr_jw_object_end(w);
}

void lr_status_json_controls(lr_jw *w, const char *key, const lr_rig_status *st)
{
    lr_jw_array(w, key);
    for (int i = 0; i < st->n_controls; i++)
        control(w, &st->controls[i]);
    lr_jw_array_end(w);
}

static void lines(lr_jw *w, const char *key, const lr_rig_status_line *l, int n)
{
    lr_jw_array(w, key);
    for (int i = 0; i < n; i++) {
        lr_jw_object(w, NULL);
        lr_jw_number(w, "t_s", l[i].t_s);
        lr_jw_string(w, "msg", l[i].msg);
        lr_jw_object_end(w);
    }
    lr_jw_array_end(w);
}

void lr_status_json_write(lr_jw *w, const char *key, const lr_rig_status *st)
{
    lr_jw_object(w, key);
    lr_status_json_members(w, st);
    lr_jw_object_end(w);
}

void lr_status_json_members(lr_jw *w, const lr_rig_status *st)
{
    lr_jw_string(w, "version", st->version);
    lr_jw_string(w, "config", st->config);
    lr_jw_string(w, "scene", st->scene);
    lr_jw_string(w, "output", st->output);
    lr_jw_string(w, "view", st->view);
    lr_jw_number(w, "uptime_s", st->uptime_s);
    lr_jw_bool(w, "idle", st->idle);
    lr_jw_int(w, "frames", (long)st->frames);
    lr_jw_int(w, "events", (long)st->events);
    lr_jw_int(w, "events_unmatched", (long)st->events_unmatched);
    lr_jw_int(w, "garbage", (long)st->garbage);
    lr_jw_int(w, "reloads", (long)st->reloads);
    lr_jw_int(w, "reload_failures", (long)st->reload_failures);
    if (st->lamp_level >= 0)
        lr_jw_number(w, "lamp_level", st->lamp_level);
    else
        lr_jw_null(w, "lamp_level");
    lr_jw_number_or_null(w, "fps", st->fps);
    lr_jw_number_or_null(w, "frame_interval_p99_ms", st->frame_interval_p99_ms);
    lr_jw_object(w, "latency_ms");
    lr_jw_int(w, "n", (long)st->latency_n);
    lr_jw_number_or_null(w, "median", st->latency_median_ms);
    lr_jw_number_or_null(w, "p99", st->latency_p99_ms);
    lr_jw_object_end(w);
    lr_jw_array(w, "devices");
    for (int i = 0; i < st->n_devices; i++) {
        lr_jw_object(w, NULL);
        lr_jw_string(w, "name", st->devices[i].name);
        lr_jw_string(w, "kind", st->devices[i].kind);
        lr_jw_string(w, "state", st->devices[i].state);
        lr_jw_object_end(w);
    }
    lr_jw_array_end(w);
    lr_jw_object(w, "plan");
    lr_jw_bool(w, "planned", st->planned);
    lr_jw_string(w, "text", st->plan_text ? st->plan_text : "");
    lr_jw_number_or_null(w, "predicted_error", st->plan_error);
    lr_jw_number_or_null(w, "predicted_frame_ms", st->plan_frame_ms);
    lr_jw_object_end(w);
    lines(w, "warnings", st->warnings, st->n_warnings);
    lines(w, "errors", st->errors, st->n_errors);
    lr_status_json_controls(w, "controls", st);
}

char *lr_status_json_string(const lr_rig_status *st, bool controls_only, size_t *len)
{
    char *buf = NULL;
    size_t n = 0;
    FILE *f = open_memstream(&buf, &n);
    if (!f)
        return NULL;
    lr_jw *w = lr_jw_create(f);
    int rc = LR_ENOMEM;
    if (w) {
        if (controls_only)
            lr_status_json_controls(w, NULL, st);
        else
            lr_status_json_write(w, NULL, st);
        lr_err e = {0};
        rc = lr_jw_finish(w, &e);
    }
    if (fclose(f) || rc) {
        free(buf);
        return NULL;
    }
    if (len)
        *len = n;
    return buf;
}
