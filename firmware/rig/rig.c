/* lamprig firmware — the rig and its poll loop (see rig.h). */
#include "firmware/rig/rig.h"

#include <errno.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/signalfd.h>
#include <sys/stat.h>
#include <unistd.h>

#include "calib/albedo.h"
#include "calib/ar_frame.h"
#include "firmware/rig/ahead.h"
#include "firmware/rig/ar_present.h"
#include "firmware/rig/config.h"
#include "firmware/rig/control_map.h"
#include "firmware/rig/http.h"
#include "firmware/rig/job.h"
#include "firmware/rig/mqtt.h"
#include "firmware/rig/notify.h"
#include "firmware/rig/stats.h"
#include "firmware/rig/status_json.h"
#include "firmware/rig/view.h"
#include "hal/artnet.h"
#include "hal/artnet_packet.h"
#include "hal/dev.h"
#include "hal/event.h"
#include "hal/gpio.h"
#include "hal/hid.h"
#include "hal/modbus.h"
#include "hal/osc.h"
#include "hal/sacn.h"
#include "hal/sacn_packet.h"
#include "hal/sim.h"
#include "hal/usb.h"
#include "render/base/out_dir.h"
#include "render/base/paths.h"
#include "render/gl/gl.h"
#include "render/image/image.h"
#include "render/plan/limits.h"
#include "render/scene/scene.h"
#include "firmware/plan_scene.h"
#include "firmware/version.h"
#include "render/base/paths.h"

#define MAX_POLL 128
#define RETIRED_MAX 8
#define FLUSH_MS 1000
/* The worker's first image at start-up; minutes only under the sanitizers. */
#define FIRST_IMAGE_MS 600000
#define FRAME_TIMES 64 /* frame end times kept for the status's fps and interval p99 */

/* A request for a reload's answer (lr_rig_reload_async). */
typedef struct reload_waiter {
    lr_rig_reload_fn fn;
    void *ctx;
    uint64_t gen; /* answered by reload number gen (lr_rig.reload_gen) or a later one */
} reload_waiter;

/* What a config builds; swapped whole on reload. */
typedef struct rigset {
    lr_rig_config *cfg;
    lr_scene *scene;
    lr_control_map *map;
    lr_dev *devs[LR_RIG_MAX_DEVICES];
    lr_modbus *lamp[LR_RIG_MAX_DEVICES]; /* modbus devices with a lamp driver */
    lr_modbus *modbus[LR_RIG_MAX_DEVICES]; /* per devs[i]: its modbus link, or NULL */
    lr_sacn *sacn[LR_RIG_MAX_DEVICES];     /* per devs[i], or NULL; the same for these: */
    lr_artnet *artnet[LR_RIG_MAX_DEVICES];
    lr_osc *osc[LR_RIG_MAX_DEVICES];
    int n_devs, n_lamps;
    bool has_hid;
    bool no_vpl; /* the planner found no receiver that sees any object */
    lr_replan *replan;    /* re-plans on a material change; NULL when not planned */
    lr_rig_calib *calib;  /* spatial AR ("calib" in the config); NULL without */
    lr_albedo albedo;     /* the mockup's response, when the folder has albedo.json */
    bool has_albedo;
} rigset;

struct lr_rig {
    lr_rig_opts opts;
    char config_path[LR_RIG_PATH_MAX];
    char out_dir[LR_RIG_PATH_MAX];
    char stats_path[LR_RIG_PATH_MAX];
    char modbus_url[LR_RIG_PATH_MAX];
    lr_log log;
    rigset set;
    lr_event_ring *ring;
    lr_gl *gl;
    bool kms;
    lr_rig_view *view;
    /* The states the controls reach next, built ahead by the view (firmware/rig/ahead.h). */
    lr_rig_ahead *ahead;
    bool ahead_building; /* a list was handed over and the view has not finished it */
    double ahead_step_max_ms; /* the longest list step on the loop, for the log */
    /* Views replaced by a scene switch or reload whose work off the loop is still finishing
     * (lr_rig_view_retire): destroyed once done, so the loop never waits for them. */
    lr_rig_view *retired[RETIRED_MAX];
    int n_retired;
    unsigned char *rgba;
    lr_rig_stats *stats;
    int sigfd;
    sigset_t old_mask;
    bool masked;
    bool stop;
    int64_t start_ns, end_ns, next_frame_ns, frame_interval_ns, next_stats_ns;
    double lamp_written; /* -1: nothing written */
    uint64_t frames, events, reloads, reload_failures;
    unsigned frame_errors;
    bool fading; /* a fade was running at the last apply: apply once more after it ends */
    lr_frame_stats flip_stats; /* KMS: the frame on its way to the screen */
    lr_rig_frame_info flip_info;
    bool flip_stats_pending;
    bool used_hid; /* hidapi's process-wide state is released once, at the very end */
    bool ar_dirty; /* spatial AR: the scene changed since the last projector frame */
    uint64_t ar_frames;
    lr_ar_present *ar_out; /* KMS + calib: draws the compensated frames on the projector */
    bool ar_size_logged;   /* the frame/mode size mismatch was logged */
    lr_notify *notify;     /* sd_notify: READY, watchdog pings, RELOADING, STOPPING */
    bool ready_sent;
    /* The status others read (firmware/rig/status_json.h, the HTTP endpoint). */
    lr_http *http;          /* "http" in the config; NULL: no server */
    lr_rig_http_config http_cfg; /* what it was started with (a reload keeps it) */
    int64_t http_retry_ns;       /* the next attempt to listen; INT64_MAX: none due */
    bool http_failed;            /* a failure to listen was logged */
    lr_log user_log;        /* the caller's log; r->log records warnings and errors first */
    lr_rig_status_line warnings[LR_STATUS_LOG_KEEP], errors[LR_STATUS_LOG_KEEP];
    int n_warnings, n_errors;
    int64_t frame_t[FRAME_TIMES]; /* ring of frame start times (the loop's clock) */
    int n_frame_t;
    uint64_t unmatched;
    /* The plan the status shows (of the running scene), and the one plan_scene made last:
     * it becomes the shown one only when its scene does (a failed reload or scene switch
     * keeps the running scene's). */
    struct rig_plan {
        bool planned;
        char text[512];
        double error, frame_ms;
    } plan, plan_new;
    char http_scene[LR_RIG_PATH_MAX]; /* a shipped scene POST /api/scene asked for */
    unsigned char *http_rgba;         /* lr_rig_frame_rgba's readback */
    lr_mqtt *mqtt;         /* "mqtt": several rigs in step (firmware/rig/mqtt.h); NULL without */
    /* A scene switch or reload loading in a job (firmware/rig/job.h: the loop never waits for
     * a scene file, its plan and its control map); one at a time: a reload or a scene asked
     * for meanwhile waits for it. */
    struct loading *load;
    lr_rig_job *load_job;
    bool reload_pending;
    /* Reloads started (each job's number) and the answers awaited (lr_rig_reload_async), each
     * by the first reload started after its request. */
    uint64_t reload_gen;
    reload_waiter waiter[LR_RIG_RELOAD_WAITERS];
    int n_waiters;
    char scene_pending[LR_RIG_PATH_MAX];
    /* An MQTT scene command ahead of its apply_at: that scene loaded and planned (in a job)
     * and its view built in advance (mqtt_prepare), so that the switch at apply_at is a swap
     * and the rigs do not differ by their load times. */
    struct {
        bool valid;
        char path[LR_RIG_PATH_MAX];
        lr_scene *scene;
        lr_replan *replan;
        lr_rig_view *view;
        struct rig_plan plan;
    } pre;
    char pre_key[LR_MQTT_SCENE_MAX + 24]; /* the command last prepared (tried once) */
    /* Role "leader": the controls as its own devices have set them, ahead of what the rigs
     * apply (a scratch map fed with the same commands, never written to a scene), and the
     * apply_at of what it last published per binding (the scene at LR_RIG_MAX_BINDINGS). */
    lr_control_map *lead_map;
    int64_t lead_sent[LR_RIG_MAX_BINDINGS + 1];
};

/* A console input's counters for the stats file (names: static strings, or the parsers'
 * result names behind "bad_"). */
#define INPUT_COUNTERS_MAX (13 + LR_DMX_MAX_KINDS)
static int dmx_counters(const lr_dmx_counters *c, const char *(*kind_name)(int), int n_kinds,
                        lr_rig_stats_counter *out)
{
    const lr_rig_stats_counter fixed[] = {
        {"", "packets", c->packets},       {"", "taken", c->taken},
        {"", "other", c->other},           {"", "sequence", c->sequence},
        {"", "full", c->full},             {"", "preview", c->preview},
        {"", "terminated", c->terminated}, {"", "losses", c->losses},
        {"", "polls", c->polls},           {"", "replies", c->replies},
        {"", "polls_limited", c->polls_limited},
        {"", "events", c->events},         {"", "bad", c->bad},
    };
    int n = 0;
    for (size_t k = 0; k < sizeof fixed / sizeof fixed[0]; k++)
        out[n++] = fixed[k];
    for (int k = 0; k < n_kinds && k < LR_DMX_MAX_KINDS; k++)
        if (c->bad_kind[k])
            out[n++] = (lr_rig_stats_counter){"bad_", kind_name(k), c->bad_kind[k]};
    return n;
}

static const char *sacn_kind(int k) { return lr_sacn_result_name((lr_sacn_result)k); }
static const char *artnet_kind(int k) { return lr_artnet_result_name((lr_artnet_result)k); }
static const char *osc_kind(int k)
{
    static const char *const key[LR_OSC_N_BAD] = {"address", "types", "value", "scene",
                                                  "packet"}; /* lr_osc_bad */
    return (unsigned)k < LR_OSC_N_BAD ? key[k] : "?";
}

static int input_counters(const rigset *s, int i, lr_rig_stats_counter *out)
{
    lr_dmx_counters c;
    if (s->sacn[i]) {
        lr_sacn_get_counters(s->sacn[i], &c);
        return dmx_counters(&c, sacn_kind, LR_SACN_N_RESULTS, out);
    }
    if (s->artnet[i]) {
        lr_artnet_get_counters(s->artnet[i], &c);
        return dmx_counters(&c, artnet_kind, LR_ARTNET_N_RESULTS, out);
    }
    if (!s->osc[i])
        return 0;
    lr_osc_counters oc;
    lr_osc_get_counters(s->osc[i], &oc);
    int n = 0;
    out[n++] = (lr_rig_stats_counter){"", "messages", oc.messages};
    out[n++] = (lr_rig_stats_counter){"", "events", oc.events};
    out[n++] = (lr_rig_stats_counter){"", "bad", oc.bad};
    for (int k = 0; k < LR_OSC_N_BAD; k++)
        if (oc.bad_kind[k])
            out[n++] = (lr_rig_stats_counter){"bad_", osc_kind(k), oc.bad_kind[k]};
    return n;
}

/* Every line goes to the caller's log; warnings and errors are also kept (the last
 * LR_STATUS_LOG_KEEP of each) for the status document. */
static void rig_log(void *user, lr_log_level level, const char *msg)
{
    lr_rig *r = user;
    lr_log_write(&r->user_log, level, "%s", msg);
    if (level > LR_LOG_WARN)
        return;
    lr_rig_status_line *l = level == LR_LOG_ERROR ? r->errors : r->warnings;
    int *n = level == LR_LOG_ERROR ? &r->n_errors : &r->n_warnings;
    if (*n == LR_STATUS_LOG_KEEP) {
        memmove(l, l + 1, (LR_STATUS_LOG_KEEP - 1) * sizeof *l);
        (*n)--;
    }
    l[*n].t_s = (double)(lr_now_ns() - r->start_ns) * 1e-9;
    snprintf(l[*n].msg, sizeof l[*n].msg, "%s", msg);
    (*n)++;
}

static void http_start(lr_rig *r, int64_t now);

static void set_free(rigset *s)
{
    for (int i = 0; i < s->n_devs; i++)
        lr_dev_destroy(s->devs[i]);
    lr_control_map_destroy(s->map);
    lr_replan_destroy(s->replan);
    lr_scene_destroy(s->scene);
    lr_rig_config_destroy(s->cfg);
    lr_rig_calib_free(s->calib);
    free(s->calib);
    lr_albedo_free(&s->albedo);
    memset(s, 0, sizeof *s);
}

/* A scene's warnings: into the log of the job loading it while on that job's thread (a scene
 * keeps its sink for later changes, which come from the loop). */
static void scene_warn(void *user, const char *msg)
{
    lr_rig *r = user;
    lr_log_write(lr_rig_job_log_here(r->load_job, &r->log), LR_LOG_WARN, "scene: %s", msg);
}

/* A console channel's home for a loss fade (hal/dmx_in.h): the position the control map took
 * from the scene (or "initial") for the level binding of this device's control; NaN (hold)
 * when no level binding takes it. */
static double channel_home(const rigset *s, const lr_rig_device *d, const char *control)
{
    for (int i = 0; i < s->cfg->n_bindings; i++) {
        const lr_rig_binding *b = &s->cfg->bindings[i];
        if (b->kind == LR_BIND_LEVEL && strcmp(b->control, control) == 0 &&
            (!b->source[0] || strcmp(b->source, d->name) == 0))
            return lr_control_map_position(s->map, i);
    }
    return NAN;
}

static int create_device(lr_rig *r, rigset *s, const lr_rig_device *d, lr_err *e)
{
    lr_dev_desc dev = {
        .name = d->name,
        .sink = lr_event_ring_sink(r->ring),
        .log = r->log,
        .retry_min_ms = d->retry_min_ms,
        .retry_max_ms = d->retry_max_ms,
        .required = d->required,
    };
    int rc = LR_OK;
    lr_dev *out = NULL;
    switch (d->type) {
    case LR_RIG_DEV_SIM: {
        lr_sim_desc sd = {.dev = dev, .path = d->script[0] ? d->script : NULL, .text = d->text,
                          .loop = d->loop};
        lr_sim *sim;
        if (!(rc = lr_sim_create(&sd, &sim, e)))
            out = lr_sim_dev(sim);
        break;
    }
    case LR_RIG_DEV_MODBUS: {
        lr_modbus_input in[LR_RIG_MAX_ITEMS];
        for (int i = 0; i < d->n_inputs; i++) {
            const lr_rig_modbus_reg *g = &d->inputs[i];
            in[i] = (lr_modbus_input){.control = g->control, .unit = g->unit, .reg = g->reg,
                                      .base = g->base,
                                      .type = g->input_regs ? LR_MODBUS_INPUT : LR_MODBUS_HOLDING,
                                      .raw_min = g->raw_min, .raw_max = g->raw_max};
        }
        lr_modbus_desc md = {
            .dev = dev,
            .url = r->modbus_url[0] ? r->modbus_url : d->url,
            .inputs = in,
            .n_inputs = d->n_inputs,
            .poll_ms = d->poll_ms,
            .timeout_ms = d->timeout_ms,
            .byte_timeout_ms = d->byte_timeout_ms,
            .max_timeouts = d->max_timeouts,
        };
        if (d->has_lamp)
            md.output = (lr_modbus_output){.enabled = true, .unit = d->lamp.unit,
                                           .reg = d->lamp.reg, .base = d->lamp.base,
                                           .raw_min = d->lamp.raw_min,
                                           .raw_max = d->lamp.raw_max,
                                           .multiple = d->lamp.multiple};
        lr_modbus *m;
        if (!(rc = lr_modbus_create(&md, &m, e))) {
            out = lr_modbus_dev(m);
            s->modbus[s->n_devs] = m;
            if (d->has_lamp)
                s->lamp[s->n_lamps++] = m;
        }
        break;
    }
    case LR_RIG_DEV_GPIO: {
        lr_gpio_encoder enc[LR_RIG_MAX_ITEMS];
        lr_gpio_button btn[LR_RIG_MAX_ITEMS];
        for (int i = 0; i < d->n_encoders; i++)
            enc[i] = (lr_gpio_encoder){d->encoders[i].name, d->encoders[i].line_a,
                                       d->encoders[i].line_b, d->encoders[i].steps_per_detent,
                                       d->encoders[i].reverse};
        for (int i = 0; i < d->n_buttons; i++)
            btn[i] = (lr_gpio_button){d->buttons[i].name, d->buttons[i].line_a,
                                      d->buttons[i].active_high, d->buttons[i].debounce_ms};
        lr_gpio_desc gd = {.dev = dev, .chip = d->chip, .bias = (lr_gpio_bias)d->bias,
                           .encoders = enc, .n_encoders = d->n_encoders,
                           .buttons = btn, .n_buttons = d->n_buttons};
        lr_gpio *g;
        if (!(rc = lr_gpio_create(&gd, &g, e)))
            out = lr_gpio_dev(g);
        break;
    }
    case LR_RIG_DEV_HID: {
        lr_hid_desc hd = {.dev = dev, .vid = d->vid, .pid = d->pid,
                          .serial = d->serial[0] ? d->serial : NULL, .poll_ms = d->poll_ms};
        hd.parser.proto = (lr_hid_proto)d->proto;
        hd.parser.report_id = (uint8_t)d->report_id;
        lr_hid *h;
        s->has_hid = true;
        if (!(rc = lr_hid_create(&hd, &h, e)))
            out = lr_hid_dev(h);
        break;
    }
    case LR_RIG_DEV_USB: {
        lr_usb_watch w[LR_RIG_MAX_ITEMS];
        for (int i = 0; i < d->n_watch; i++) {
            w[i] = (lr_usb_watch){.name = d->watch[i].name, .vid = d->watch[i].vid,
                                  .pid = d->watch[i].pid, .read_reports = d->watch[i].read_reports,
                                  .interface = d->watch[i].interface};
            w[i].parser.proto = (lr_hid_proto)d->watch[i].proto;
        }
        lr_usb_desc ud = {.dev = dev, .watch = w, .n_watch = d->n_watch,
                          .rescan_ms = d->rescan_ms, .no_hotplug = d->no_hotplug};
        lr_usb *u;
        if (!(rc = lr_usb_create(&ud, &u, e)))
            out = lr_usb_dev(u);
        break;
    }
    case LR_RIG_DEV_SACN:
    case LR_RIG_DEV_ARTNET: {
        lr_dmx_channel ch[LR_RIG_MAX_CHANNELS];
        for (int i = 0; i < d->n_channels; i++)
            ch[i] = (lr_dmx_channel){.control = d->channels[i].control,
                                     .universe = d->channels[i].universe,
                                     .channel = d->channels[i].channel,
                                     .fine = d->channels[i].fine,
                                     .home = channel_home(s, d, d->channels[i].control)};
        if (d->type == LR_RIG_DEV_SACN) {
            lr_sacn_desc sd = {.dev = dev, .bind = d->bind, .interface = d->interface,
                               .unicast_only = d->unicast_only, .channels = ch,
                               .n_channels = d->n_channels, .loss = (lr_dmx_loss)d->loss,
                               .preview = d->preview, .port = d->port,
                               .max_sources = d->max_sources, .loss_ms = d->loss_ms,
                               .fade_ms = d->fade_ms, .max_packets = d->max_packets};
            lr_sacn *sa;
            if (!(rc = lr_sacn_create(&sd, &sa, e))) {
                out = lr_sacn_dev(sa);
                s->sacn[s->n_devs] = sa;
            }
        } else {
            lr_artnet_desc ad = {.dev = dev, .bind = d->bind, .announce = d->announce,
                                 .short_name = d->short_name, .channels = ch,
                                 .n_channels = d->n_channels,
                                 .merge = (lr_dmx_merge_mode)d->merge,
                                 .loss = (lr_dmx_loss)d->loss, .port = d->port,
                                 .merge_timeout_ms = d->merge_timeout_ms,
                                 .fade_ms = d->fade_ms, .max_packets = d->max_packets};
            lr_artnet *an;
            if (!(rc = lr_artnet_create(&ad, &an, e))) {
                out = lr_artnet_dev(an);
                s->artnet[s->n_devs] = an;
            }
        }
        break;
    }
    case LR_RIG_DEV_OSC: {
        const char *sc[LR_RIG_MAX_SCENE_NAMES];
        for (int i = 0; i < d->n_scenes; i++)
            sc[i] = d->scenes[i];
        lr_osc_desc od = {.dev = dev, .prefix = d->prefix, .scene_control = d->scene_control,
                          .scenes = sc,
                          .n_scenes = d->n_scenes, .port = d->port,
                          .max_packets = d->max_packets};
        lr_osc *o;
        if (!(rc = lr_osc_create(&od, &o, e))) {
            out = lr_osc_dev(o);
            s->osc[s->n_devs] = o;
        }
        break;
    }
    }
    if (rc)
        return lr_err_prefix(e, "%s:%d: device '%s'", r->config_path, d->line, d->name);
    s->devs[s->n_devs++] = out;
    return LR_OK;
}

/* The planner's text, one log line per line (it ends lines in '\n'; TEXT is cut in place). */
static void log_lines_to(const lr_log *log, char *text)
{
    for (char *line = text, *nl; line && *line; line = nl + 1) {
        if ((nl = strchr(line, '\n')))
            *nl = '\0';
        lr_log_write(log, LR_LOG_INFO, "%s", line);
        if (!nl)
            break;
    }
}

static void log_lines(lr_rig *r, char *text) { log_lines_to(&r->log, text); }

/* The planner (firmware/plan_scene.h) for a scene with a quality budget (in the scene file
 * or the config's scene_set), unless --no-plan: its settings are applied, then the config's
 * scene_set once more so that an explicit render.* setting wins. A missing or unusable table
 * is logged and the scene's settings stay. *no_vpl: the plan cuts the VPL pass. *replan: the
 * re-planner for material changes (NULL when not planned, or when it could not be made:
 * logged, the plan stands without it). Logs to `log`, the plan's summary into *out; reads
 * only r->opts (so it runs in a job too). */
static int plan_scene(const lr_rig *r, const lr_log *log, struct rig_plan *out,
                      const lr_rig_config *cfg, lr_scene *scene, bool *no_vpl,
                      lr_replan **replan, lr_err *e)
{
    *no_vpl = false;
    *replan = NULL;
    *out = (struct rig_plan){.planned = false, .error = NAN, .frame_ms = NAN};
    if (r->opts.no_plan)
        return LR_OK;
    lr_plan_scene_result *res = calloc(1, sizeof *res);
    if (!res)
        return lr_err_set(e, LR_ENOMEM, "plan: out of memory");
    lr_err pe = {0};
    int rc = LR_OK;
    if (lr_plan_scene(scene, r->opts.plan_table, false, res, &pe)) {
        lr_log_write(log, LR_LOG_WARN, "plan: %s; running with the scene's settings", pe.msg);
    } else if (res->planned) {
        char *text = lr_plan_scene_text(res, true); /* the log keeps every reason */
        log_lines_to(log, text);
        free(text);
        /* The status keeps the brief sentence and the worst predicted error and frame time. */
        if ((text = lr_plan_scene_text(res, false))) {
            snprintf(out->text, sizeof out->text, "%s", text);
            out->text[strcspn(out->text, "\n")] = '\0';
        }
        free(text);
        out->planned = true;
        out->error = out->frame_ms = 0;
        for (int i = 0; i < res->plan.nobjects; i++) {
            const lr_plan_choice *ch = &res->plan.objects[i];
            out->error = fmax(out->error, ch->predicted_error);
            out->frame_ms = fmax(out->frame_ms, ch->predicted_frame_ms);
        }
        *no_vpl = !res->vpl;
        rc = lr_rig_config_apply_sets(cfg, scene, e);
        const lr_render_settings *now = lr_scene_render(scene), *p = &res->plan.settings;
        if (!rc && (now->K != p->K || now->N != p->N || now->N_vpl != p->N_vpl ||
                    now->map_size != p->map_size || now->gbuffer_size != p->gbuffer_size ||
                    now->frames != p->frames))
            lr_log_write(log, LR_LOG_INFO,
                         "plan: the config's scene_set overrides it: render K=%d N=%d N_vpl=%d "
                         "map_size=%d gbuffer_size=%d frames=%d",
                         now->K, now->N, now->N_vpl, now->map_size, now->gbuffer_size, now->frames);
        if (!rc && lr_plan_scene_replanner(scene, res, replan, &pe))
            lr_log_write(log, LR_LOG_WARN, "plan: %s; no re-plan on material changes",
                         pe.msg);
    }
    free(res);
    return rc;
}

/* Spatial AR: the calibration folder must hold the projector and its scene pose; a broken
 * or incomplete folder fails the whole config (file and field named by the loaders). */
static int ar_load(rigset *s, lr_err *e)
{
    const char *dir = s->cfg->calib;
    if (!(s->calib = calloc(1, sizeof *s->calib)))
        return lr_err_set(e, LR_ENOMEM, "out of memory");
    int rc = lr_rig_calib_load(dir, s->calib, e);
    if (rc)
        return lr_err_prefix(e, "%s: field 'calib'", s->cfg->path);
    if (!s->calib->has_procam || !s->calib->has_pose || !s->calib->pose.has_projector)
        return lr_err_set(e, LR_EINVAL,
                          "%s: field 'calib': %s needs projector.json and a pose.json with the "
                          "projector's pose for spatial AR",
                          s->cfg->path, dir);
    char path[LR_RIG_PATH_MAX + 32];
    snprintf(path, sizeof path, "%s/%s", dir, LR_RIG_ALBEDO);
    struct stat st;
    if (stat(path, &st) == 0) {
        if ((rc = lr_albedo_load(path, &s->albedo, e)))
            return rc;
        s->has_albedo = true;
    }
    return LR_OK;
}

static int set_devices(lr_rig *r, rigset *s, lr_err *e)
{
    int rc = LR_OK;
    for (int i = 0; !rc && i < s->cfg->n_devices; i++)
        rc = create_device(r, s, &s->cfg->devices[i], e);
    return rc;
}

/* Config, scene, plan, control map and calibration: all or nothing; logs to `log`, the plan's
 * summary into *plan. Reads only what the rig never changes after start (the config path,
 * --modbus, the options), so a reload runs it in a job. */
static int set_build_core(const lr_rig *r, const lr_log *log, struct rig_plan *plan, rigset *s,
                          lr_err *e)
{
    memset(s, 0, sizeof *s);
    int rc = lr_rig_config_load(r->config_path, &s->cfg, e);
    if (!rc && r->modbus_url[0]) {
        bool any = false;
        for (int i = 0; i < s->cfg->n_devices; i++)
            any |= s->cfg->devices[i].type == LR_RIG_DEV_MODBUS;
        if (!any)
            lr_log_write(log, LR_LOG_WARN,
                         "--modbus %s: the config has no modbus device; ignored", r->modbus_url);
    }
    lr_warn_sink warn = {scene_warn, (void *)r};
    if (!rc)
        rc = lr_scene_load(s->cfg->scene, &warn, &s->scene, e);
    if (!rc)
        rc = lr_rig_config_apply_sets(s->cfg, s->scene, e);
    if (!rc)
        rc = plan_scene(r, log, plan, s->cfg, s->scene, &s->no_vpl, &s->replan, e);
    if (!rc) /* a model forced outside its validity limit (render/plan/limits.h) */
        rc = lr_plan_check_models(s->scene, e);
    if (!rc)
        rc = lr_control_map_create(s->cfg, s->scene, true, lr_now_ns(), &s->map, e);
    if (!rc && s->cfg->calib[0])
        rc = ar_load(s, e);
    if (rc)
        set_free(s);
    return rc;
}

/* The same and (with_devices) the devices, on the loop. */
static int set_build(lr_rig *r, rigset *s, bool with_devices, lr_err *e)
{
    int rc = set_build_core(r, &r->log, &r->plan_new, s, e);
    if (!rc && with_devices && (rc = set_devices(r, s, e))) {
        r->used_hid |= s->has_hid;
        set_free(s);
    }
    return rc;
}

/* A scene file loaded, set as the config says and planned: what a scene switch needs before
 * its view. Reads r->set.cfg, which the loop leaves alone while a scene loads in a job. */
static int scene_build(const lr_rig *r, const lr_log *log, struct rig_plan *plan,
                       const char *path, lr_scene **scene, bool *no_vpl, lr_replan **rp,
                       lr_err *e)
{
    *scene = NULL;
    *rp = NULL;
    lr_warn_sink warn = {scene_warn, (void *)r};
    int rc = lr_scene_load(path, &warn, scene, e);
    if (!rc)
        rc = lr_rig_config_apply_sets(r->set.cfg, *scene, e);
    if (!rc)
        rc = plan_scene(r, log, plan, r->set.cfg, *scene, no_vpl, rp, e);
    if (!rc)
        rc = lr_plan_check_models(*scene, e);
    if (rc) {
        lr_replan_destroy(*rp);
        lr_scene_destroy(*scene);
        *scene = NULL;
        *rp = NULL;
    }
    return rc;
}

static int view_build(lr_rig *r, lr_scene *scene, bool no_vpl, lr_rig_view **out, lr_err *e)
{
    const lr_rig_config *c = r->set.cfg;
    lr_rig_view_desc vd = {.name = c->output.renderer, .gl = r->gl, .scene = scene,
                           .width = c->output.width, .height = c->output.height,
                           .no_vpl = no_vpl, .gpu_budget_mb = c->output.gpu_memory_mb};
    lr_cache_key keys[LR_CACHE_MAX_KEYS];
    int nk = 0;
    if (r->set.map && c->output.cache_mb > 0 &&
        lr_rig_ahead_keys(r->set.map, scene, keys, LR_CACHE_MAX_KEYS, &nk, e))
        return lr_err_prefix(e, "output.cache_mb");
    vd.cache_keys = keys;
    vd.n_cache_keys = nk;
    vd.cache_mb = nk > 0 ? c->output.cache_mb : 0;
    vd.slice_ms = c->output.slice_ms;
    if (r->kms)
        lr_gl_size(r->gl, &vd.width, &vd.height);
    if (r->ahead)
        lr_rig_ahead_changed(r->ahead, lr_now_ns()); /* a new view: its cache is empty */
    return lr_rig_view_create(&vd, out, e);
}

static int ensure_rgba(lr_rig *r)
{
    int w, h;
    lr_rig_view_size(r->view, &w, &h);
    free(r->rgba);
    r->rgba = malloc((size_t)w * (size_t)h * 4);
    return r->rgba ? LR_OK : LR_ENOMEM;
}

/* ---- applying control changes ---- */

static void write_lamp(lr_rig *r, double level)
{
    if (!r->set.n_lamps || level == r->lamp_written)
        return;
    for (int i = 0; i < r->set.n_lamps; i++)
        lr_modbus_write_level(r->set.lamp[i], level);
    r->lamp_written = level;
}

/* A control changed a material: the planner chooses again for the objects whose model it
 * chose (render/plan/replan.h); a dimmer (LR_DIRTY_INTENSITY) never gets here. */
static void replan(lr_rig *r, unsigned *dirty)
{
    char *text = NULL;
    lr_err e = {0};
    if (lr_replan_update(r->set.replan, r->set.scene, *dirty, dirty, &text, NULL, &e))
        lr_log_write(&r->log, LR_LOG_WARN, "plan: %s", e.msg);
    log_lines(r, text);
    free(text);
}

static void apply(lr_rig *r, int64_t now)
{
    unsigned dirty = 0;
    lr_err e = {0};
    if (lr_control_map_update(r->set.map, r->set.scene, now, &dirty, &e))
        lr_log_write(&r->log, LR_LOG_WARN, "control map: %s", e.msg);
    if (r->set.replan && (dirty & LR_DIRTY_MATERIAL))
        replan(r, &dirty);
    uint64_t batch = 0;
    if (r->ahead && (dirty & ~(unsigned)(LR_DIRTY_INTENSITY | LR_DIRTY_DISPLAY)))
        lr_rig_ahead_changed(r->ahead, now); /* the states ahead are relative to this one */
    if (dirty) {
        /* No view yet at start-up and in a scene switch: the view is built on the scene as
         * the controls have set it. */
        if (r->view)
            batch = lr_rig_view_invalidate(r->view, dirty);
        r->ar_dirty = true;
    }
    double level;
    if (lr_control_map_lamp_level(r->set.map, now, &level))
        write_lamp(r, level);
    r->fading = lr_control_map_fading(r->set.map, now);
    /* The events taken since the last apply show in the frames whose images include this
     * change (off the loop, render/async/: the batch; 0: the next frame). A fade whose first
     * step left the scene as it was has not changed anything yet: its events wait for the
     * apply that does. */
    if (dirty || !r->fading)
        lr_rig_stats_tag(r->stats, batch);
}

/* Makes one more state of the list ahead and hands the list so far to the view. */
static void ahead_step(lr_rig *r, int64_t now)
{
    const lr_async_state *states;
    int n;
    bool done;
    lr_err e = {0};
    int64_t t0 = lr_now_ns();
    int rc = lr_rig_ahead_step(r->ahead, r->set.map, r->set.scene, r->set.replan, now, &states,
                               &n, &done, &e);
    double ms = (double)(lr_now_ns() - t0) * 1e-6;
    if (ms > r->ahead_step_max_ms)
        r->ahead_step_max_ms = ms;
    if (rc || lr_rig_view_anticipate(r->view, states, n, &e)) {
        lr_log_write(&r->log, LR_LOG_WARN, "states ahead: %s", e.msg);
        lr_rig_ahead_changed(r->ahead, INT64_MAX / 2); /* not again until a change */
        return;
    }
    if (done && n > 0) {
        lr_log_write(&r->log, LR_LOG_INFO, "cache: %d states of the controls to build ahead", n);
        r->ahead_building = true;
    } else if (done) {
        lr_log_write(&r->log, LR_LOG_INFO, "cache: states built ahead: none (no control "
                                           "changes light transport)");
    }
}

/* Hands the current view to the retired list (the oldest is destroyed, waiting, when the list
 * is full: eight switches within one solve). */
static void retire_view(lr_rig *r)
{
    if (!r->view)
        return;
    if (r->n_retired == RETIRED_MAX) {
        lr_rig_view_destroy(r->retired[0]);
        memmove(r->retired, r->retired + 1, (RETIRED_MAX - 1) * sizeof r->retired[0]);
        r->n_retired--;
    }
    lr_rig_view_retire(r->view);
    r->retired[r->n_retired++] = r->view;
    r->view = NULL;
}

static void reap_views(lr_rig *r)
{
    int keep = 0;
    for (int i = 0; i < r->n_retired; i++) {
        if (lr_rig_view_retired(r->retired[i]))
            lr_rig_view_destroy(r->retired[i]);
        else
            r->retired[keep++] = r->retired[i];
    }
    r->n_retired = keep;
}

static void pre_drop(lr_rig *r)
{
    if (!r->pre.valid)
        return;
    lr_rig_view *cur = r->view;
    r->view = r->pre.view;
    retire_view(r); /* off the loop like any replaced view; its scene may go now */
    r->view = cur;
    lr_replan_destroy(r->pre.replan);
    lr_scene_destroy(r->pre.scene);
    memset(&r->pre, 0, sizeof r->pre);
}

/* A scene loaded and planned ahead (a job, load_start's LOAD_AHEAD): its view is built here
 * with the controls' values as they stand (a scratch map carrying the live one's positions:
 * the live map keeps writing the scene shown). A failure is logged; the switch at apply_at
 * then loads it as usual (and says why). */
static void ahead_commit(lr_rig *r, struct loading *l);

/* The switch to the scene loaded ahead: the controls are written into it again (what moved
 * since it was loaded), then it and its view replace the shown ones. */
static void pre_commit(lr_rig *r)
{
    lr_err e = {0};
    lr_control_map_scene_replaced(r->set.map);
    unsigned dirty = 0;
    if (lr_control_map_update(r->set.map, r->pre.scene, lr_now_ns(), &dirty, &e))
        lr_log_write(&r->log, LR_LOG_WARN, "control map: %s", e.msg);
    if (dirty)
        lr_rig_view_invalidate(r->pre.view, dirty);
    retire_view(r);
    lr_replan_destroy(r->set.replan);
    lr_scene_destroy(r->set.scene);
    r->view = r->pre.view;
    r->set.scene = r->pre.scene;
    r->set.replan = r->pre.replan;
    r->plan_new = r->plan = r->pre.plan;
    r->ar_dirty = true;
    lr_log_write(&r->log, LR_LOG_INFO, "scene: %s (loaded ahead)", r->pre.path);
    memset(&r->pre, 0, sizeof r->pre);
}

/* A scene or a config loaded and planned in a job (firmware/rig/job.h): what it made, for the
 * loop to take when the job is done (load_poll). */
typedef enum load_kind {
    LOAD_RELOAD, /* the whole config (set) */
    LOAD_SWITCH, /* the scene at path, shown when loaded */
    LOAD_AHEAD,  /* the scene at path, kept for an MQTT command's apply_at (r->pre) */
} load_kind;

typedef struct loading {
    lr_rig *r;
    load_kind kind;
    char path[LR_RIG_PATH_MAX];
    int rc;
    lr_err e;
    rigset set;                    /* reload: without its devices (they open on the loop) */
    lr_scene *scene;               /* a scene switch */
    bool no_vpl;
    lr_replan *replan;
    struct rig_plan plan;
    int64_t started_ns;
    uint64_t gen;                  /* reload: its number (lr_rig.reload_gen) */
} loading;

static void load_run(void *arg, const lr_log *log)
{
    loading *l = arg;
    if (l->kind == LOAD_RELOAD)
        l->rc = set_build_core(l->r, log, &l->plan, &l->set, &l->e);
    else
        l->rc = scene_build(l->r, log, &l->plan, l->path, &l->scene, &l->no_vpl, &l->replan,
                            &l->e);
}

static void loading_free(loading *l)
{
    if (!l)
        return;
    set_free(&l->set);
    lr_replan_destroy(l->replan);
    lr_scene_destroy(l->scene);
    free(l);
}

static void switch_commit(lr_rig *r, loading *l);
static void reload_commit(lr_rig *r, loading *l);
static void switch_scene(lr_rig *r, const char *path);

/* What a load made replaces the running config or scene, then it is freed. */
static void load_commit(lr_rig *r, loading *l)
{
    if (l->kind == LOAD_RELOAD)
        reload_commit(r, l);
    else if (l->kind == LOAD_AHEAD)
        ahead_commit(r, l);
    else
        switch_commit(r, l);
    loading_free(l);
}

/* Starts loading (the config, or the scene at path) in a job; where no job can be started,
 * loads it here and now. */
static void load_start(lr_rig *r, load_kind kind, const char *path)
{
    static const char *const what[] = {"reload", "scene switch", "mqtt: scene ahead"};
    loading *l = calloc(1, sizeof *l);
    if (!l) {
        lr_log_write(&r->log, LR_LOG_ERROR, "%s: out of memory", what[kind]);
        return;
    }
    l->r = r;
    l->kind = kind;
    l->started_ns = lr_now_ns();
    if (kind == LOAD_RELOAD)
        l->gen = ++r->reload_gen;
    if (path)
        snprintf(l->path, sizeof l->path, "%s", path);
    lr_err e = {0};
    r->load = l;
    if (lr_rig_job_start(load_run, l, &r->load_job, &e)) {
        lr_log_write(&r->log, LR_LOG_WARN, "%s; loading on the loop", e.msg);
        r->load_job = NULL;
        load_run(l, &r->log);
        r->load = NULL;
        load_commit(r, l);
    }
}

/* Takes what a finished job loaded (wait: also one still running, for callers that must have
 * it now: the synchronous reload, shutdown), then a request that came meanwhile. */
static void load_poll(lr_rig *r, bool wait)
{
    if (!r->load || !(wait || lr_rig_job_done(r->load_job)))
        return;
    loading *l = r->load;
    lr_rig_job_finish(r->load_job, &r->log); /* its log lines, in order */
    r->load_job = NULL;
    r->load = NULL;
    load_commit(r, l);
    if (r->reload_pending) {
        r->reload_pending = false;
        load_start(r, LOAD_RELOAD, NULL);
    } else if (r->scene_pending[0]) {
        char path[LR_RIG_PATH_MAX];
        snprintf(path, sizeof path, "%s", r->scene_pending);
        r->scene_pending[0] = '\0';
        switch_scene(r, path);
    }
}

/* A scene switch (button2, the page, MQTT): loaded and planned in a job while the loop goes on
 * with the scene shown; one at a time, and a request made meanwhile waits for it (the latest
 * wins). A scene loaded ahead (MQTT's apply_at) is a swap at once. */
static void switch_scene(lr_rig *r, const char *path)
{
    if (r->pre.valid && strcmp(r->pre.path, path) == 0) {
        pre_commit(r);
        return;
    }
    if (r->load) {
        snprintf(r->scene_pending, sizeof r->scene_pending, "%s", path);
        return;
    }
    load_start(r, LOAD_SWITCH, path);
}

static void ahead_commit(lr_rig *r, loading *l)
{
    if (l->rc) {
        lr_log_write(&r->log, LR_LOG_WARN, "mqtt: scene %s not loaded ahead: %s", l->path,
                     l->e.msg);
        return;
    }
    pre_drop(r);
    lr_err e = {0};
    int64_t now = lr_now_ns();
    lr_control_map *tmp = NULL;
    unsigned dirty = 0;
    if (lr_control_map_create(r->set.cfg, l->scene, false, now, &tmp, &e) == LR_OK) {
        lr_control_map_carry(tmp, r->set.map, now);
        lr_control_map_update(tmp, l->scene, now, &dirty, &e);
    }
    lr_control_map_destroy(tmp);
    lr_rig_view *view;
    if (view_build(r, l->scene, l->no_vpl, &view, &e)) {
        lr_log_write(&r->log, LR_LOG_WARN, "mqtt: scene %s not loaded ahead: %s", l->path,
                     e.msg);
        return;
    }
    r->pre.valid = true;
    snprintf(r->pre.path, sizeof r->pre.path, "%s", l->path);
    r->pre.scene = l->scene;
    r->pre.replan = l->replan;
    r->pre.view = view;
    r->pre.plan = l->plan;
    l->scene = NULL;
    l->replan = NULL;
    lr_log_write(&r->log, LR_LOG_INFO,
                 "mqtt: scene %s loaded ahead of its apply_at (off the loop in %.0f ms)",
                 l->path, (double)(now - l->started_ns) * 1e-6);
}

/* The loaded scene replaces the shown one (on the loop, after its job). */
static void switch_commit(lr_rig *r, loading *l)
{
    if (l->rc) {
        lr_log_write(&r->log, LR_LOG_ERROR, "scene switch: %s; keeping %s", l->e.msg,
                     lr_scene_path(r->set.scene));
        return;
    }
    lr_scene *scene = l->scene;
    /* The controls' values go into the new scene before its view copies it, so that its first
     * image is the one the controls ask for. */
    lr_control_map_scene_replaced(r->set.map);
    unsigned dirty = 0;
    lr_err e = {0};
    if (lr_control_map_update(r->set.map, scene, lr_now_ns(), &dirty, &e))
        lr_log_write(&r->log, LR_LOG_WARN, "control map: %s", e.msg);
    lr_rig_view *view;
    if (view_build(r, scene, l->no_vpl, &view, &e)) {
        lr_log_write(&r->log, LR_LOG_ERROR, "scene switch: %s", e.msg);
        lr_control_map_scene_replaced(r->set.map); /* the old scene again, written in full */
        return;
    }
    retire_view(r);
    lr_replan_destroy(r->set.replan);
    lr_scene_destroy(r->set.scene);
    r->view = view;
    r->set.scene = scene;
    r->set.replan = l->replan;
    l->scene = NULL;
    l->replan = NULL;
    r->plan_new = l->plan;
    r->plan = r->plan_new;
    r->ar_dirty = true;
    lr_log_write(&r->log, LR_LOG_INFO, "scene: %s (loaded in %.0f ms)", l->path,
                 (double)(lr_now_ns() - l->started_ns) * 1e-6);
}

static bool lead_forward(lr_rig *r, const lr_event *ev, int64_t now);

/* An event into the control map (a device's, or an MQTT command's). */
static void take_event(lr_rig *r, const lr_event *ev, int64_t now)
{
    int b = lr_control_map_event(r->set.map, ev, now);
    if (b < 0) {
        if (isfinite(ev->value)) {
            lr_rig_stats_unmatched(r->stats);
            r->unmatched++;
        }
        return;
    }
    r->events++;
    lr_rig_stats_event(r->stats, ev);
}

/* A device's event. */
static void handle_event(lr_rig *r, const lr_event *ev, int64_t now)
{
    /* A knob's USB arrival: reopen the hid device of that name now, not at its next backoff. */
    if (strcmp(ev->control, "present") == 0 && ev->value == 1)
        for (int i = 0; i < r->set.n_devs; i++)
            if (strcmp(lr_dev_kind(r->set.devs[i]), "hid") == 0 &&
                strcmp(lr_dev_name(r->set.devs[i]), ev->source) == 0)
                lr_dev_retry_now(r->set.devs[i], now);
    if (!lead_forward(r, ev, now))
        take_event(r, ev, now);
}

/* ---- MQTT (firmware/rig/mqtt.h) ---- */

/* The rig's status for its MQTT document: the one GET /api/status shows. */
static void mqtt_status(void *user, lr_rig_status *st)
{
    lr_rig_get_status(user, st);
}

/* The leader's map, from the live one's positions (a reload, the link opened). */
static void lead_reset(lr_rig *r)
{
    lr_control_map_destroy(r->lead_map);
    r->lead_map = NULL;
    memset(r->lead_sent, 0, sizeof r->lead_sent);
    if (!r->mqtt || r->set.cfg->mqtt.role != LR_RIG_MQTT_LEADER)
        return;
    lr_err e = {0};
    int64_t now = lr_now_ns();
    if (lr_control_map_create(r->set.cfg, r->set.scene, false, now, &r->lead_map, &e)) {
        lr_log_write(&r->log, LR_LOG_ERROR, "mqtt: leader: %s; its controls stay local", e.msg);
        return;
    }
    lr_control_map_carry(r->lead_map, r->set.map, now);
    /* The cycles (presets, the scene) where the live map has them: an absolute position in the
     * middle of each one's value. */
    for (int i = 0; i < r->set.cfg->n_bindings; i++) {
        const lr_rig_binding *b = &r->set.cfg->bindings[i];
        int idx = lr_control_map_index(r->set.map, i);
        if (b->kind != LR_BIND_CYCLE || idx < 0)
            continue;
        lr_event ev;
        lr_event_set(&ev, b->source[0] ? b->source : "mqtt", b->control, LR_EV_ABSOLUTE,
                     (idx + 0.5) / b->n_values, now);
        lr_control_map_event(r->lead_map, &ev, now);
    }
    lr_control_map_scene_request(r->lead_map); /* it loads nothing */
}

static int mqtt_open(lr_rig *r, lr_err *e)
{
    if (!r->set.cfg->mqtt.enabled)
        return LR_OK;
    lr_mqtt_desc d = {.cfg = r->set.cfg, .log = r->log, .status = mqtt_status, .user = r};
    int rc = lr_mqtt_create(&d, lr_now_ns(), &r->mqtt, e);
    if (!rc)
        lead_reset(r);
    return rc;
}

/* Role "leader": a device's event moves the leader's map, and what it moved goes to every rig
 * (this one too) at now + lead_ms, as the positions it gave; this rig applies it when it comes
 * back, in step with the others. Not connected: false, and the event applies here at once
 * (the leader's map follows, so the two agree). */
static bool lead_forward(lr_rig *r, const lr_event *ev, int64_t now)
{
    if (!r->lead_map)
        return false;
    int moved = lr_control_map_event(r->lead_map, ev, now);
    lr_control_map_scene_request(r->lead_map);
    if (moved < 0 || !lr_mqtt_connected(r->mqtt))
        return false;
    const lr_rig_config *cfg = r->set.cfg;
    int64_t at = lr_mqtt_realtime_ns() + (int64_t)cfg->mqtt.lead_ms * 1000000LL;
    bool all = true;
    for (int i = 0; i < cfg->n_bindings; i++) {
        const lr_rig_binding *b = &cfg->bindings[i];
        if ((b->source[0] && strcmp(b->source, ev->source) != 0) ||
            strcmp(b->control, ev->control) != 0)
            continue;
        lr_mqtt_cmd c = {.kind = LR_MQTT_CONTROL, .has_apply_at = true, .apply_at_ns = at};
        int key = i;
        if (b->kind == LR_BIND_LEVEL) {
            c.value = lr_control_map_position(r->lead_map, i);
        } else if (strcmp(b->param, "scene") != 0) {
            c.value = (lr_control_map_index(r->lead_map, i) + 0.5) / b->n_values;
        } else {
            /* The file name: the other rigs' configs name the same scene by their own paths. */
            const char *v = b->values[lr_control_map_index(r->lead_map, i)];
            c.kind = LR_MQTT_SCENE;
            snprintf(c.scene, sizeof c.scene, "%s", strrchr(v, '/') ? strrchr(v, '/') + 1 : v);
            key = LR_RIG_MAX_BINDINGS;
        }
        snprintf(c.name, sizeof c.name, "%s", b->name);
        if (lr_mqtt_publish_cmd(r->mqtt, &c))
            r->lead_sent[key] = at;
        else
            all = false;
    }
    return all;
}

/* "candle", "candle.json" or a path: the config's scene cycle first (its binding then moves to
 * that value, so a button goes on from there), else a shipped scene. *binding: the cycle
 * binding and *index its value, or -1 with the shipped path in path. */
static bool mqtt_scene(const lr_rig *r, const char *name, int *binding, int *index, char *path,
                       size_t cap)
{
    const lr_rig_config *c = r->set.cfg;
    size_t n = strlen(name);
    for (int b = 0; b < c->n_bindings; b++) {
        if (strcmp(c->bindings[b].param, "scene") != 0)
            continue;
        for (int i = 0; i < c->bindings[b].n_values; i++) {
            const char *v = c->bindings[b].values[i];
            const char *base = strrchr(v, '/') ? strrchr(v, '/') + 1 : v;
            if (strcmp(v, name) == 0 || strcmp(base, name) == 0 ||
                (strncmp(base, name, n) == 0 && strcmp(base + n, ".json") == 0)) {
                *binding = b;
                *index = i;
                return true;
            }
        }
    }
    *binding = *index = -1;
    if (strchr(name, '/') || !n)
        return false;
    bool ext = n > 5 && strcmp(name + n - 5, ".json") == 0;
    char leaf[LR_MQTT_SCENE_MAX + 8];
    snprintf(leaf, sizeof leaf, "%s%s", name, ext ? "" : ".json");
    struct stat st;
    return lr_path_join(path, cap, lr_configs_dir(), "scenes", leaf) == 0 &&
           stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

/* A scene command ahead of its time: its scene loaded in advance (once per command). */
static void mqtt_prepare(lr_rig *r)
{
    lr_mqtt_cmd c;
    if (!lr_mqtt_pending_scene(r->mqtt, &c) || !c.has_apply_at ||
        c.apply_at_ns <= lr_mqtt_realtime_ns())
        return;
    char key[sizeof r->pre_key];
    snprintf(key, sizeof key, "%lld %s", (long long)c.apply_at_ns, c.scene);
    if (strcmp(key, r->pre_key) == 0)
        return;
    if (r->load)
        return; /* a load runs (one at a time): asked again at the next turn */
    snprintf(r->pre_key, sizeof r->pre_key, "%s", key);
    int b, idx;
    char path[LR_RIG_PATH_MAX];
    if (!mqtt_scene(r, c.scene, &b, &idx, path, sizeof path))
        return; /* refused when it is due */
    if (b >= 0)
        snprintf(path, sizeof path, "%s", r->set.cfg->bindings[b].values[idx]);
    if (!(r->pre.valid && strcmp(r->pre.path, path) == 0))
        load_start(r, LOAD_AHEAD, path);
}

/* The commands due now, each as the event of its binding (an absolute position, like a fader
 * of that control); a scene outside the config's cycle is switched to directly. True when an
 * event was taken. */
static bool mqtt_apply(lr_rig *r, int64_t now)
{
    if (!r->mqtt)
        return false;
    bool any = false;
    lr_mqtt_cmd c;
    while (lr_mqtt_take(r->mqtt, lr_mqtt_realtime_ns(), &c)) {
        const lr_rig_config *cfg = r->set.cfg;
        int b = -1, idx = -1;
        double x = c.value;
        if (c.kind == LR_MQTT_SCENE) {
            char path[LR_RIG_PATH_MAX];
            if (!mqtt_scene(r, c.scene, &b, &idx, path, sizeof path)) {
                lr_mqtt_refuse(r->mqtt, &c, "no such scene in the config's scene cycle or "
                                            "configs/scenes");
                continue;
            }
            if (b < 0) {
                switch_scene(r, path);
                any = true;
                continue;
            }
            /* The middle of value idx's interval: floor(x * n) picks it. */
            x = (idx + 0.5) / cfg->bindings[b].n_values;
        } else {
            for (int i = 0; i < cfg->n_bindings && b < 0; i++)
                if (strcmp(cfg->bindings[i].name, c.name) == 0)
                    b = i;
            if (b < 0) {
                lr_mqtt_refuse(r->mqtt, &c, "no binding of that name");
                continue;
            }
        }
        const lr_rig_binding *bd = &cfg->bindings[b];
        lr_event ev;
        lr_event_set(&ev, bd->source[0] ? bd->source : "mqtt", bd->control, LR_EV_ABSOLUTE, x,
                     now);
        take_event(r, &ev, now);
        /* A leader's map takes what others sent (its own sends are in it already, and an
         * older one of its own must not undo a newer). */
        int key = c.kind == LR_MQTT_SCENE ? LR_RIG_MAX_BINDINGS : b;
        if (r->lead_map && !(c.has_apply_at && r->lead_sent[key] == c.apply_at_ns)) {
            lr_control_map_event(r->lead_map, &ev, now);
            lr_control_map_scene_request(r->lead_map);
        }
        any = true;
    }
    return any;
}

/* ---- frames ---- */

/* Files are numbered by the rig's own frame count, never the view's accumulation index: that
 * restarts at 0 after every change and every scene switch, and its frames would overwrite the
 * earlier ones. */
static void write_png(lr_rig *r, uint64_t index)
{
    int w, h;
    lr_rig_view_size(r->view, &w, &h);
    lr_image img = {0};
    lr_err e = {0};
    if (lr_image_alloc(&img, w, h, &e) == LR_OK) {
        for (size_t i = 0; i < (size_t)w * (size_t)h; i++)
            for (int k = 0; k < 3; k++)
                img.rgb[3 * i + k] = lr_srgb_decode(r->rgba[4 * i + k] / 255.0f);
        char path[LR_RIG_PATH_MAX + 32];
        snprintf(path, sizeof path, "%s/frame_%06llu.png", r->out_dir, (unsigned long long)index);
        if (lr_image_write_png(path, &img, NULL, &e) && r->frame_errors++ == 0)
            lr_log_write(&r->log, LR_LOG_ERROR, "frames: %s", e.msg);
    }
    lr_image_free(&img);
}

/* Spatial AR: the compensated projector frame for the current scene (CPU reference from the
 * projector's pose; calib/ar_frame.h), once per change of the scene. The frame the view
 * rendered (the scene's camera) is kept as is for the stats and --out-dir. */
static void ar_frame(lr_rig *r)
{
    lr_ar_frame_desc d = {.scene = r->set.scene, .calib = r->set.calib,
                          .response = r->set.has_albedo ? &r->set.albedo.response : NULL,
                          .samples = r->set.cfg->ar_samples};
    lr_image levels = {0};
    lr_ar_stats st;
    lr_err e = {0};
    r->ar_dirty = false;
    if (lr_ar_frame(&d, &levels, NULL, &st, &e)) {
        lr_log_write(&r->log, LR_LOG_ERROR, "spatial AR: %s", e.msg);
        return;
    }
    char msg[128];
    lr_ar_stats_format(&st, msg, sizeof msg);
    lr_rig_stats_ar(r->stats, st.clipped_fraction, st.clipped_light_fraction);
    if (r->out_dir[0]) {
        lr_img png;
        if (lr_img_alloc(&png, levels.width, levels.height, 3, 1, &e) == LR_OK) {
            lr_ar_levels_to_rgb8(&levels, png.px);
            char path[LR_RIG_PATH_MAX + 32];
            snprintf(path, sizeof path, "%s/ar_%06llu.png", r->out_dir,
                     (unsigned long long)r->ar_frames);
            if (lr_img_write(path, &png, &e))
                lr_log_write(&r->log, LR_LOG_ERROR, "spatial AR: %s", e.msg);
            lr_img_free(&png);
        }
    }
    if (r->ar_out) {
        /* On the projector: only when a new frame was computed (the loop stays idle). */
        int mw, mh;
        lr_gl_size(r->gl, &mw, &mh);
        if ((mw != levels.width || mh != levels.height) && !r->ar_size_logged) {
            lr_log_write(&r->log, LR_LOG_WARN,
                         "spatial AR: frame %dx%d (the calibrated projector) differs from the "
                         "KMS mode %dx%d; stretched to fill the mode (set output.mode_size to "
                         "the calibrated size for pixel-exact levels)",
                         levels.width, levels.height, mw, mh);
            r->ar_size_logged = true;
        }
        if (lr_ar_present_show(r->ar_out, &levels, &e))
            lr_log_write(&r->log, LR_LOG_ERROR, "spatial AR: %s", e.msg);
    }
    lr_log_write(&r->log, LR_LOG_INFO, "spatial AR frame %llu: %dx%d, %s%s",
                 (unsigned long long)r->ar_frames, levels.width, levels.height, msg,
                 r->ar_out ? ", on the projector" : "");
    r->ar_frames++;
    lr_image_free(&levels);
}

static void frame(lr_rig *r, int64_t now)
{
    lr_frame_stats st;
    lr_rig_frame_info info;
    lr_err e = {0};
    int rc = lr_rig_view_frame(r->view, &st, &info, &e);
    if (!rc && info.stage == LR_ASYNC_NONE) {
        /* Nothing to show yet (the worker's first image is on its way): no frame. */
        r->next_frame_ns = now + r->frame_interval_ns;
        return;
    }
    /* With spatial AR the projector shows the compensated frame (ar_frame), not the view. */
    if (!rc && r->kms && !r->set.calib)
        rc = lr_rig_view_present(r->view, &e);
    if (!rc && r->out_dir[0]) {
        rc = lr_rig_view_read_rgba8(r->view, r->rgba, &e);
        if (!rc)
            write_png(r, r->frames);
    }
    if (rc) {
        /* Logged once per run of failures; the loop keeps going on the controls. */
        if (r->frame_errors++ == 0)
            lr_log_write(&r->log, LR_LOG_ERROR, "frame: %s", e.msg);
        r->next_frame_ns = now + 1000000000LL;
        return;
    }
    if (r->set.calib && r->ar_dirty)
        ar_frame(r);
    r->frame_errors = 0;
    /* The start, as the loop paces it: headless frames start at least frame_interval_ns
     * apart, so the status's fps is at most output.fps (its end times vary with the work). */
    r->frame_t[r->frames % FRAME_TIMES] = now;
    r->frames++;
    if (r->mqtt)
        lr_mqtt_frame(r->mqtt, r->frames - 1, lr_mqtt_realtime_ns());
    if (r->kms && lr_gl_flip_pending(r->gl)) {
        /* On the projector a frame shows at its page flip: the latency ends there. */
        if (r->flip_stats_pending)
            lr_rig_stats_frame_shown(r->stats, &r->flip_stats, &r->flip_info, lr_now_ns());
        r->flip_stats = st;
        r->flip_info = info;
        r->flip_stats_pending = true;
    } else {
        lr_rig_stats_frame_shown(r->stats, &st, &info, lr_now_ns());
    }
    r->next_frame_ns = now + r->frame_interval_ns;
}

/* Whether something is due, without moving the clock. */
static bool frame_due(const lr_rig *r)
{
    return lr_rig_view_needs_frame(r->view) || r->fading;
}

/* A running fade does not by itself want a frame: its first step often leaves the level
 * where it was (nothing dirty), and rendering that would only push the frame that shows the
 * change one frame interval later. The loop wakes for the fade instead (fade_wake). */
static bool frame_wanted(lr_rig *r, int64_t now)
{
    /* The renderer's clock is the rig's wall clock: a flickering flame wants a frame (a
     * composition only) at every frame interval. */
    lr_rig_view_set_time(r->view, (double)(now - r->start_ns) * 1e-9);
    return lr_rig_view_needs_frame(r->view);
}

/* When to apply a running fade again: at the next frame slot, but at least FADE_TICK_NS
 * from now so an unchanged level (a fade clamped at a limit) cannot spin the loop. */
#define FADE_TICK_NS 4000000LL
static int64_t fade_wake(const lr_rig *r, int64_t now)
{
    int64_t t = now + FADE_TICK_NS;
    return r->next_frame_ns > t ? r->next_frame_ns : t;
}

static void write_stats(lr_rig *r, int64_t now)
{
    if (!r->stats_path[0])
        return;
    lr_err e = {0};
    lr_rig_stats_dev devs[LR_RIG_MAX_DEVICES];
    lr_modbus_counters mc[LR_RIG_MAX_DEVICES];
    lr_rig_stats_counter in[LR_RIG_MAX_DEVICES][INPUT_COUNTERS_MAX];
    for (int i = 0; i < r->set.n_devs; i++) {
        lr_dev *d = r->set.devs[i];
        devs[i] = (lr_rig_stats_dev){lr_dev_name(d), lr_dev_kind(d),
                                     lr_dev_state_name(lr_dev_get_state(d)), NULL, NULL, 0};
        if (r->set.modbus[i]) {
            lr_modbus_get_counters(r->set.modbus[i], &mc[i]);
            devs[i].modbus = &mc[i];
        }
        devs[i].n_input = input_counters(&r->set, i, in[i]);
        devs[i].input = in[i];
    }
    if (lr_rig_stats_write(r->stats, r->stats_path, r->config_path, now,
                           lr_control_map_garbage(r->set.map), devs, r->set.n_devs, &e))
        lr_log_write(&r->log, LR_LOG_ERROR, "stats: %s", e.msg);
}

/* ---- create / reload / destroy ---- */

static int open_output(lr_rig *r, lr_err *e)
{
    const lr_rig_config *c = r->set.cfg;
    if (c->output.mode == LR_RIG_KMS && !r->opts.headless) {
        lr_gl_desc gd = {.backend = LR_GL_KMS,
                         .drm_device = c->output.drm_device[0] ? c->output.drm_device : NULL,
                         .connector = c->output.connector[0] ? c->output.connector : NULL,
                         .width = c->output.mode_w, .height = c->output.mode_h,
                         .refresh_hz = c->output.refresh_hz};
        lr_err ge = {0};
        if (lr_gl_create(&gd, &r->gl, &ge) == LR_OK) {
            r->kms = true;
            int w, h;
            lr_gl_size(r->gl, &w, &h);
            lr_log_write(&r->log, LR_LOG_INFO, "output: kms %dx%d", w, h);
        } else {
            lr_log_write(&r->log, LR_LOG_WARN, "output: kms: %s; running headless", ge.msg);
        }
    }
    if (!r->gl && lr_rig_view_needs_gl(c->output.renderer)) {
        lr_gl_desc gd = {.backend = LR_GL_SURFACELESS};
        int rc = lr_gl_create(&gd, &r->gl, e);
        if (rc)
            return lr_err_prefix(e, "output: headless GL");
    }
    if (!r->kms)
        lr_log_write(&r->log, LR_LOG_INFO, "output: headless%s%s",
                     r->out_dir[0] ? ", frames to " : "", r->out_dir);
    return LR_OK;
}

/* KMS + spatial AR: the presenter of the compensated frames (kept across reloads). */
static int ar_output(lr_rig *r, lr_err *e)
{
    int rc = lr_ar_present_create(r->gl, &r->ar_out, e);
    if (rc)
        return lr_err_prefix(e, "field 'calib'");
    lr_log_write(&r->log, LR_LOG_INFO, "spatial AR: the projector shows the compensated frames; "
                 "the render view is not shown while AR is active");
    return LR_OK;
}

/* Frames are paced by the flips only when the view itself is on the projector; with spatial
 * AR (the projector shows only new compensated frames) and headless, by output.fps. */
static int64_t frame_interval(const lr_rig *r)
{
    return r->kms && !r->set.calib ? 0 : (int64_t)(1e9 / r->set.cfg->output.fps);
}

int lr_rig_create(const lr_rig_opts *opts, lr_rig **out, lr_err *e)
{
    if (!opts || !opts->config)
        return lr_err_set(e, LR_EINVAL, "no config file given");
    lr_rig *r = calloc(1, sizeof *r);
    if (!r)
        return lr_err_set(e, LR_ENOMEM, "out of memory");
    r->opts = *opts;
    r->user_log = opts->log;
    r->log = (lr_log){rig_log, r};
    r->sigfd = -1;
    r->lamp_written = -1;
    snprintf(r->config_path, sizeof r->config_path, "%s", opts->config);
    if (opts->out_dir)
        snprintf(r->out_dir, sizeof r->out_dir, "%s", opts->out_dir);
    if (opts->modbus_url)
        snprintf(r->modbus_url, sizeof r->modbus_url, "%s", opts->modbus_url);
    int rc = LR_OK;
    if (r->modbus_url[0]) {
        lr_modbus_url u;
        rc = lr_modbus_url_parse(r->modbus_url, &u, e);
        if (rc)
            lr_err_prefix(e, "--modbus");
    }
    r->start_ns = lr_now_ns();
    if (!rc)
        rc = lr_notify_create(r->start_ns, &r->notify, e);
    if (!rc)
        rc = lr_event_ring_create(1024, &r->ring, e);
    if (!rc)
        rc = lr_rig_stats_create(r->start_ns, &r->stats, e);
    if (!rc && !opts->no_signals) {
        sigset_t m;
        sigemptyset(&m);
        sigaddset(&m, SIGINT);
        sigaddset(&m, SIGTERM);
        sigaddset(&m, SIGHUP);
        if (sigprocmask(SIG_BLOCK, &m, &r->old_mask) == 0) {
            r->masked = true;
            r->sigfd = signalfd(-1, &m, SFD_NONBLOCK | SFD_CLOEXEC);
        }
        if (r->sigfd < 0)
            rc = lr_err_set(e, LR_EIO, "signalfd: %s", strerror(errno));
    }
    if (!rc && r->out_dir[0] && (rc = lr_out_dir_prepare(r->out_dir, e)))
        lr_err_prefix(e, "--out-dir");
    if (!rc)
        rc = set_build(r, &r->set, false, e);
    /* The samples are the starting config's (a reload keeps them). */
    if (!rc && r->set.cfg->output.cache_mb > 0)
        rc = lr_rig_ahead_create(r->set.cfg->output.cache_samples, &r->ahead, e);
    if (!rc) {
        r->plan = r->plan_new;
        if (opts->stats_path)
            snprintf(r->stats_path, sizeof r->stats_path, "%s", opts->stats_path);
        else
            snprintf(r->stats_path, sizeof r->stats_path, "%s", r->set.cfg->stats_path);
        rc = open_output(r, e);
    }
    if (!rc && r->kms && r->set.calib)
        rc = ar_output(r, e);
    /* The controls' initial values first (a dimmer's start level, a knob's preset), so the
     * view copies the scene the controls ask for; the devices' own states come below. */
    if (!rc)
        apply(r, r->start_ns);
    if (!rc)
        rc = view_build(r, r->set.scene, r->set.no_vpl, &r->view, e);
    r->ar_dirty = true;
    if (!rc && ensure_rgba(r))
        rc = lr_err_set(e, LR_ENOMEM, "out of memory");
    /* The first image: with the transport off the loop ("passes") the worker's first
     * publication, a coarse preview of the scene (render/async/), which it then refines while
     * the loop runs; on the loop ("passes_inline") the whole first frame (the G-buffers,
     * maps, bounce, a grid's first solve: seconds on the 2-core proxy). It is made before
     * the devices open, so that the rig takes controls once it shows an image. */
    if (!rc && (rc = lr_rig_view_wait_first(r->view, FIRST_IMAGE_MS, e)))
        lr_err_prefix(e, "the first image");
    if (!rc) {
        lr_rig_view_set_time(r->view, 0.0);
        frame(r, lr_now_ns());
    }
    /* The devices come last, and --duration counts from then: a sim script's time 0 and the
     * duration's start are the same instant, however long the GL set-up and the first frame
     * above took, so a run plays the same part of the script. */
    if (!rc)
        rc = set_devices(r, &r->set, e);
    if (!rc)
        rc = mqtt_open(r, e);
    if (rc) {
        lr_rig_destroy(r);
        return rc;
    }
    const lr_rig_config *c = r->set.cfg;
    r->frame_interval_ns = frame_interval(r);
    int64_t devices_ns = lr_now_ns();
    r->end_ns = opts->duration_s > 0 ? devices_ns + (int64_t)(opts->duration_s * 1e9)
                                     : INT64_MAX;
    /* The HTTP endpoint last: it answers once the rig shows an image and takes controls. */
    r->http_cfg = c->http;
    r->http_retry_ns = INT64_MAX;
    if (c->http.enabled)
        http_start(r, devices_ns);
    r->next_stats_ns = c->stats_period_s > 0 ? r->start_ns + (int64_t)(c->stats_period_s * 1e9)
                                             : INT64_MAX;
    lr_log_write(&r->log, LR_LOG_INFO, "config %s: scene %s, %d devices, %d controls, view %s",
                 r->config_path, c->scene, c->n_devices, c->n_bindings,
                 lr_rig_view_name(r->view));
    apply(r, r->start_ns);
    *out = r;
    return LR_OK;
}

/* Starts the HTTP endpoint. A failure (the port taken by another program) is logged once
 * and retried every HTTP_RETRY_NS, as a missing device is: the controls and the lamp do not
 * depend on the page, and a show box must not go dark because a port is busy. */
#define HTTP_RETRY_NS 2000000000LL
static void http_start(lr_rig *r, int64_t now)
{
    const lr_rig_http_config *c = &r->http_cfg;
    lr_http_desc hd = {.host = c->host, .port = c->port, .loopback = c->loopback,
                       .token = c->token, .rig = r, .log = r->log};
    lr_err e = {0};
    if (lr_http_create(&hd, &r->http, &e)) {
        if (!r->http_failed)
            lr_log_write(&r->log, LR_LOG_ERROR, "%s; retrying every %lld s", e.msg,
                         HTTP_RETRY_NS / 1000000000LL);
        r->http_failed = true;
        r->http_retry_ns = now + HTTP_RETRY_NS;
        return;
    }
    r->http_retry_ns = INT64_MAX;
    lr_log_write(&r->log, LR_LOG_INFO, "http: listening on %s%s%s:%d%s",
                 strchr(c->host, ':') ? "[" : "", c->host, strchr(c->host, ':') ? "]" : "",
                 lr_http_port(r->http), c->token[0] ? ", token required for changes" : "");
}

/* One line for `systemctl status` (STATUS=). */
static const char *status_line(const lr_rig *r, char *buf, size_t cap)
{
    const char *scene = r->set.cfg ? r->set.cfg->scene : "";
    const char *slash = strrchr(scene, '/');
    int w = snprintf(buf, cap, "%s, %s; %llu frames, %llu events, %llu reloads (%llu failed)",
                     slash ? slash + 1 : scene, r->kms ? "kms" : "headless",
                     (unsigned long long)r->frames, (unsigned long long)r->events,
                     (unsigned long long)r->reloads, (unsigned long long)r->reload_failures);
    if (w > 0 && r->lamp_written >= 0 && (size_t)w < cap)
        snprintf(buf + w, cap - (size_t)w, ", lamp %.3f", r->lamp_written);
    return buf;
}

static int reload_finish(lr_rig *r, rigset *s, lr_err *e);
static void reload_start(lr_rig *r);

/* Answers the requests that reload `gen` (or a later one) serves: those made before it
 * started. */
static void reload_answer(lr_rig *r, uint64_t gen, int rc, const lr_err *e)
{
    int k = 0;
    for (int i = 0; i < r->n_waiters; i++) {
        if (r->waiter[i].gen <= gen) {
            /* Copied out first: the answer may ask again (a new entry) or forget. */
            lr_rig_reload_fn fn = r->waiter[i].fn;
            void *ctx = r->waiter[i].ctx;
            r->waiter[i].fn = NULL;
            fn(ctx, rc, e);
        }
    }
    for (int i = 0; i < r->n_waiters; i++)
        if (r->waiter[i].fn)
            r->waiter[k++] = r->waiter[i];
    r->n_waiters = k;
}

static int reload_failed(lr_rig *r, const lr_err *e)
{
    r->reload_failures++;
    lr_log_write(&r->log, LR_LOG_ERROR, "reload: %s; keeping the running config", e->msg);
    return e->code ? e->code : LR_EINVAL;
}

static void notify_ready(lr_rig *r)
{
    if (r->ready_sent) {
        char st[256];
        lr_notify_ready(r->notify, status_line(r, st, sizeof st));
    }
}

/* The synchronous reload (in-process callers, POST /api/reload): what loads meanwhile is
 * taken first, then the config is loaded here and now. */
int lr_rig_reload(lr_rig *r, lr_err *e)
{
    r->reload_pending = false; /* this is it */
    while (r->load)
        load_poll(r, true);
    /* The service manager sees the reload start and end (a failed one too: the old config
     * runs on, ready as before). */
    if (r->ready_sent)
        lr_notify_reloading(r->notify, lr_now_ns());
    rigset s;
    int rc = set_build(r, &s, true, e);
    rc = rc ? reload_failed(r, e) : reload_finish(r, &s, e);
    notify_ready(r);
    /* It started after every request awaiting one. */
    reload_answer(r, UINT64_MAX, rc, e);
    return rc;
}

int lr_rig_reload_async(lr_rig *r, lr_rig_reload_fn done, void *ctx, lr_err *e)
{
    if (r->n_waiters >= LR_RIG_RELOAD_WAITERS)
        return lr_err_set(e, LR_EUNSUPPORTED, "reload: %d reloads already waiting",
                          LR_RIG_RELOAD_WAITERS);
    /* The next reload to start: now, or the pending one after the job that runs. */
    r->waiter[r->n_waiters++] = (reload_waiter){done, ctx, r->reload_gen + 1};
    lr_log_write(&r->log, LR_LOG_INFO, "reload: asked for over HTTP: reloading %s",
                 r->config_path);
    reload_start(r);
    return LR_OK;
}

void lr_rig_reload_forget(lr_rig *r, void *ctx)
{
    int k = 0;
    for (int i = 0; i < r->n_waiters; i++)
        if (r->waiter[i].ctx != ctx)
            r->waiter[k++] = r->waiter[i];
    r->n_waiters = k;
}

/* SIGHUP: the config loads and plans in a job; the loop goes on with the running one and
 * takes the new one when it is ready (reload_commit). */
static void reload_start(lr_rig *r)
{
    if (r->load) {
        r->reload_pending = true;
        return;
    }
    if (r->ready_sent)
        lr_notify_reloading(r->notify, lr_now_ns());
    load_start(r, LOAD_RELOAD, NULL);
}

/* The config a job loaded: its devices open here, then it replaces the running one. */
static void reload_commit(lr_rig *r, loading *l)
{
    lr_err e = {0};
    int rc = l->rc;
    if (rc) {
        e = l->e;
        reload_failed(r, &e);
    } else {
        rigset s = l->set;
        memset(&l->set, 0, sizeof l->set);
        r->plan_new = l->plan;
        if ((rc = set_devices(r, &s, &e))) {
            r->used_hid |= s.has_hid;
            set_free(&s);
            reload_failed(r, &e);
        } else {
            rc = reload_finish(r, &s, &e);
        }
    }
    if (!rc)
        lr_log_write(&r->log, LR_LOG_INFO, "reload: loaded and planned off the loop in %.0f ms",
                     (double)(lr_now_ns() - l->started_ns) * 1e-6);
    notify_ready(r);
    reload_answer(r, l->gen, rc, &e);
}

/* s: a config built with its devices (taken: freed on failure). */
static int reload_finish(lr_rig *r, rigset *sp, lr_err *e)
{
    rigset s = *sp;
    memset(sp, 0, sizeof *sp);
    int rc = LR_OK;
    /* The controls stay where they are (the dimmer, the knobs): the lamp does not jump back to
     * the config's initial level and fade to the panel again. */
    lr_control_map_carry(s.map, r->set.map, lr_now_ns());
    lr_rig_view *view = NULL;
    if (!rc && r->kms && s.calib && !r->ar_out && (rc = ar_output(r, e))) {
        r->used_hid |= s.has_hid;
        set_free(&s);
    }
    if (!rc) {
        /* The view belongs to the scene: build it against the new one, then swap. */
        rigset old = r->set;
        r->set = s;
        /* A new renderer may need GL where the old one did not (the output mode itself is
         * kept until restart). */
        if (!r->gl && lr_rig_view_needs_gl(s.cfg->output.renderer)) {
            lr_gl_desc gd = {.backend = LR_GL_SURFACELESS};
            if ((rc = lr_gl_create(&gd, &r->gl, e)))
                lr_err_prefix(e, "output: headless GL");
        }
        if (!rc)
            rc = view_build(r, s.scene, s.no_vpl, &view, e);
        r->set = old;
        if (rc) {
            r->used_hid |= s.has_hid;
            set_free(&s);
        }
    }
    if (rc)
        return reload_failed(r, e);
    /* Events already queued by the old devices still apply to the old map: drop them. */
    lr_event ev;
    while (lr_event_ring_pop(r->ring, &ev))
        ;
    retire_view(r);
    r->used_hid |= r->set.has_hid;
    pre_drop(r); /* loaded for the old config's controls */
    r->pre_key[0] = '\0';
    /* The MQTT link stays when its block is the same (only the binding names are new). */
    bool mqtt_new = !lr_mqtt_same(&r->set.cfg->mqtt, &s.cfg->mqtt);
    if (mqtt_new) {
        lr_mqtt_destroy(r->mqtt);
        r->mqtt = NULL;
    } else if (r->mqtt) {
        lr_mqtt_set_config(r->mqtt, s.cfg);
    }
    set_free(&r->set);
    r->set = s;
    lr_err me = {0};
    if (mqtt_new && mqtt_open(r, &me))
        lr_log_write(&r->log, LR_LOG_ERROR, "reload: %s; running without MQTT", me.msg);
    if (!mqtt_new)
        lead_reset(r); /* the new config's bindings */
    r->view = view;
    r->plan = r->plan_new;
    ensure_rgba(r);
    r->ar_dirty = true;
    r->lamp_written = -1;
    r->reloads++;
    const lr_rig_config *c = r->set.cfg;
    if (!r->opts.stats_path)
        snprintf(r->stats_path, sizeof r->stats_path, "%s", c->stats_path);
    r->frame_interval_ns = frame_interval(r);
    lr_log_write(&r->log, LR_LOG_INFO, "reloaded %s: scene %s, %d devices, %d controls",
                 r->config_path, c->scene, c->n_devices, c->n_bindings);
    if (c->http.enabled != r->http_cfg.enabled || c->http.port != r->http_cfg.port ||
        strcmp(c->http.host, r->http_cfg.host) || strcmp(c->http.token, r->http_cfg.token))
        lr_log_write(&r->log, LR_LOG_WARN,
                     "reload: the \"http\" block changed; it takes effect at the next start");
    apply(r, lr_now_ns());
    return LR_OK;
}

void lr_rig_stop(lr_rig *r) { r->stop = true; }

static void read_signals(lr_rig *r)
{
    struct signalfd_siginfo si;
    while (read(r->sigfd, &si, sizeof si) == (ssize_t)sizeof si) {
        if (si.ssi_signo == SIGHUP) {
            lr_log_write(&r->log, LR_LOG_INFO, "SIGHUP: reloading %s", r->config_path);
            reload_start(r);
        } else {
            lr_log_write(&r->log, LR_LOG_INFO, "%s: shutting down",
                         si.ssi_signo == SIGINT ? "SIGINT" : "SIGTERM");
            r->stop = true;
        }
    }
}

int lr_rig_run_until(lr_rig *r, int64_t until_ns, lr_err *e)
{
    (void)e;
    char st[256];
    if (!r->ready_sent) {
        lr_notify_ready(r->notify, status_line(r, st, sizeof st));
        r->ready_sent = true;
    }
    while (!r->stop) {
        int64_t now = lr_now_ns();
        /* The watchdog ping comes from here, the top of the loop, and nowhere else: a loop
         * stuck in a device, a frame or a reload stops the pings and systemd restarts us. */
        if (now >= lr_notify_deadline(r->notify))
            lr_notify_tick(r->notify, now, status_line(r, st, sizeof st));
        if (now >= r->end_ns) {
            lr_log_write(&r->log, LR_LOG_INFO, "duration reached: shutting down");
            r->stop = true;
            break;
        }
        if (now >= until_ns)
            break;
        /* The poll set and the earliest deadline. */
        struct pollfd fds[MAX_POLL];
        int owner[MAX_POLL]; /* -1 signalfd, -2 gl, -3 the view, -4 http, -5 mqtt, else device index */
        int nf = 0;
        int64_t t = r->end_ns < until_ns ? r->end_ns : until_ns;
        if (r->sigfd >= 0) {
            fds[nf] = (struct pollfd){r->sigfd, POLLIN, 0};
            owner[nf++] = -1;
        }
        if (r->load_job) { /* readable once the scene or config it loads is ready */
            fds[nf] = (struct pollfd){lr_rig_job_fd(r->load_job), POLLIN, 0};
            owner[nf++] = -6;
        }
        /* The worker's publications wake the loop only while no frame is wanted: once one is,
         * the frame deadline below wakes it, and the descriptor (drained by the frame) would
         * otherwise stay readable and spin the loop until that deadline. */
        bool want = frame_wanted(r, now);
        if (lr_rig_view_event_fd(r->view) >= 0 && !want) {
            fds[nf] = (struct pollfd){lr_rig_view_event_fd(r->view), POLLIN, 0};
            owner[nf++] = -3;
        }
        if (r->mqtt) {
            if (nf < MAX_POLL && lr_mqtt_pollfd(r->mqtt, &fds[nf]))
                owner[nf++] = -5;
            int64_t d = lr_mqtt_deadline(r->mqtt, now, lr_mqtt_realtime_ns());
            if (d < t)
                t = d;
        }
        if (r->kms && lr_gl_flip_pending(r->gl) && lr_gl_event_fd(r->gl) >= 0) {
            fds[nf] = (struct pollfd){lr_gl_event_fd(r->gl), POLLIN, 0};
            owner[nf++] = -2;
        }
        if (r->http_retry_ns < t)
            t = r->http_retry_ns;
        if (r->http && nf < MAX_POLL) {
            fds[nf] = (struct pollfd){lr_http_pollfd(r->http), POLLIN, 0};
            owner[nf++] = -4;
            int64_t d = lr_http_deadline(r->http, now);
            if (d < t)
                t = d;
        }
        for (int i = 0; i < r->set.n_devs; i++) {
            int k = lr_dev_pollfds(r->set.devs[i], fds + nf, MAX_POLL - nf);
            if (k > MAX_POLL - nf)
                k = MAX_POLL - nf;
            for (int j = 0; j < k; j++)
                owner[nf + j] = i;
            nf += k;
            int64_t d = lr_dev_next_deadline(r->set.devs[i]);
            if (d < t)
                t = d;
        }
        if (want && !(r->kms && lr_gl_flip_pending(r->gl)) && r->next_frame_ns < t)
            t = r->next_frame_ns;
        if (r->fading && fade_wake(r, now) < t)
            t = fade_wake(r, now);
        if (r->stats_path[0] && r->next_stats_ns < t)
            t = r->next_stats_ns;
        if (lr_notify_deadline(r->notify) < t)
            t = lr_notify_deadline(r->notify);
        if (r->ahead && r->view && !lr_rig_view_busy(r->view)) {
            int64_t d = lr_rig_ahead_wake_ns(r->ahead);
            if (d < t)
                t = d < now ? now : d;
        }
        int timeout;
        if (t == INT64_MAX)
            timeout = -1;
        else if (t <= now)
            timeout = 0;
        else {
            int64_t ms = (t - now + 999999) / 1000000;
            timeout = ms > 1000000 ? 1000000 : (int)ms;
        }
        int n = poll(fds, (nfds_t)nf, timeout);
        if (n < 0 && errno != EINTR) {
            lr_log_write(&r->log, LR_LOG_ERROR, "poll: %s", strerror(errno));
            return lr_err_set(e, LR_EIO, "poll: %s", strerror(errno));
        }
        now = lr_now_ns();
        short mqtt_ev = 0;
        for (int i = 0; i < nf && n > 0; i++) {
            if (!fds[i].revents)
                continue;
            if (owner[i] == -1) {
                read_signals(r);
                if (r->stop)
                    return LR_OK;
            } else if (owner[i] == -5) {
                mqtt_ev = fds[i].revents;
            } else if (owner[i] == -2) {
                lr_err ge = {0};
                if (lr_gl_dispatch(r->gl, &ge))
                    lr_log_write(&r->log, LR_LOG_ERROR, "output: %s", ge.msg);
                if (r->flip_stats_pending && !lr_gl_flip_pending(r->gl)) {
                    lr_rig_stats_frame_shown(r->stats, &r->flip_stats, &r->flip_info, now);
                    r->flip_stats_pending = false;
                }
            }
        }
        /* A scene or config loaded off the loop is taken here, before the devices: a reload
         * replaces them. */
        load_poll(r, false);
        /* Every device is dispatched on every wake: dispatch reads only what is ready and runs
         * only due timers, so this costs nothing when idle, and it stays right when a reload
         * above replaced the devices (owner[] then refers to the old set). */
        for (int i = 0; i < r->set.n_devs; i++)
            lr_dev_dispatch(r->set.devs[i], now);
        /* The HTTP endpoint the same way (MHD_run reads only what is ready); its POSTs push
         * events into the ring, drained just below with the devices' own. */
        if (r->http)
            lr_http_dispatch(r->http, now);
        else if (now >= r->http_retry_ns)
            http_start(r, now);
        if (r->mqtt) {
            lr_mqtt_dispatch(r->mqtt, mqtt_ev, now);
            mqtt_prepare(r);
        }
        lr_event ev;
        bool any = false;
        while (lr_event_ring_pop(r->ring, &ev)) {
            handle_event(r, &ev, now);
            any = true;
        }
        any |= mqtt_apply(r, now);
        if (r->n_retired)
            reap_views(r);
        lr_err ve = {0};
        if (lr_rig_view_error(r->view, &ve))
            lr_log_write(&r->log, LR_LOG_ERROR, "render: %s", ve.msg);
        const char *sw = lr_control_map_scene_request(r->set.map);
        if (sw)
            switch_scene(r, sw);
        if (r->http_scene[0]) {
            switch_scene(r, r->http_scene);
            r->http_scene[0] = '\0';
            sw = "http";
        }
        if (any || sw || r->fading) {
            apply(r, now);
            lr_http_controls_changed(r->http);
        }
        if (frame_wanted(r, now) && now >= r->next_frame_ns &&
            !(r->kms && lr_gl_flip_pending(r->gl)))
            frame(r, now);
        /* One state ahead per turn once the controls rest and the view has converged. */
        if (r->ahead && r->view && lr_rig_ahead_due(r->ahead, now) && !lr_rig_view_busy(r->view))
            ahead_step(r, now);
        if (r->ahead_building && r->view && !lr_rig_view_busy(r->view) &&
            !lr_rig_ahead_due(r->ahead, now)) {
            lr_state_cache_stats cs;
            int pending = 0;
            lr_rig_view_cache_stats(r->view, &cs, &pending);
            if (pending == 0) {
                r->ahead_building = false;
                lr_log_write(&r->log, LR_LOG_INFO,
                             "cache: states built ahead: %d held, %.1f of %.0f MB (the longest "
                             "step of the list on the loop: %.1f ms)", cs.entries,
                             (double)cs.bytes / 1048576.0, (double)cs.budget / 1048576.0,
                             r->ahead_step_max_ms);
            }
        }
        if (r->stats_path[0] && now >= r->next_stats_ns) {
            write_stats(r, now);
            r->next_stats_ns = now + (int64_t)(r->set.cfg->stats_period_s * 1e9);
        }
    }
    return LR_OK;
}

int lr_rig_run(lr_rig *r, lr_err *e) { return lr_rig_run_until(r, INT64_MAX, e); }

void lr_rig_destroy(lr_rig *r)
{
    if (!r)
        return;
    if (r->ready_sent)
        lr_notify_stopping(r->notify);
    /* A load in flight is waited for and dropped (what it made is freed, never shown). */
    if (r->load) {
        lr_rig_job_finish(r->load_job, &r->log);
        loading_free(r->load);
        r->load = NULL;
        r->load_job = NULL;
    }
    /* Nothing answers for the rig once it is going. */
    lr_http_destroy(r->http);
    r->http = NULL;
    /* The lamp driver goes to its safe level first, and we wait for the acknowledgement. */
    if (r->set.cfg) {
        for (int i = 0; i < r->set.n_lamps; i++) {
            lr_modbus_write_level(r->set.lamp[i], r->set.cfg->safe_level);
            lr_err e = {0};
            if (lr_modbus_flush(r->set.lamp[i], FLUSH_MS, &e))
                lr_log_write(&r->log, LR_LOG_ERROR, "shutdown: lamp driver: %s", e.msg);
            else
                lr_log_write(&r->log, LR_LOG_INFO, "shutdown: lamp driver at safe level %g (raw %d)",
                             r->set.cfg->safe_level, lr_modbus_output_raw(r->set.lamp[i]));
        }
    }
    lr_mqtt_destroy(r->mqtt); /* "offline" on the status topic */
    lr_control_map_destroy(r->lead_map);
    if (r->stats && r->set.cfg)
        write_stats(r, lr_now_ns());
    lr_rig_view_destroy(r->view);
    lr_rig_view_destroy(r->pre.view);
    lr_rig_ahead_destroy(r->ahead);
    lr_replan_destroy(r->pre.replan);
    lr_scene_destroy(r->pre.scene);
    for (int i = 0; i < r->n_retired; i++)
        lr_rig_view_destroy(r->retired[i]);
    lr_ar_present_destroy(r->ar_out);
    if (r->gl)
        lr_gl_destroy(r->gl);
    r->used_hid |= r->set.has_hid;
    set_free(&r->set);
    if (r->used_hid)
        lr_hid_library_exit();
    free(r->rgba);
    free(r->http_rgba);
    lr_rig_stats_destroy(r->stats);
    lr_event_ring_destroy(r->ring);
    lr_notify_destroy(r->notify);
    if (r->sigfd >= 0)
        close(r->sigfd);
    if (r->masked)
        sigprocmask(SIG_SETMASK, &r->old_mask, NULL);
    free(r);
}

void lr_rig_get_info(const lr_rig *r, lr_rig_info *out)
{
    out->frames = r->frames;
    out->events = r->events;
    out->reloads = r->reloads;
    out->reload_failures = r->reload_failures;
    out->lamp_level = r->lamp_written;
    out->output = r->kms ? "kms" : "headless";
    out->view = r->view ? lr_rig_view_name(r->view) : "";
    out->idle = r->view && !frame_due(r) && !lr_rig_view_busy(r->view);
}

struct lr_scene *lr_rig_scene(lr_rig *r) { return r->set.scene; }

/* ---- the status and requests from outside (firmware/rig/http.h) ---- */

static int cmp_i64(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

/* A value of a cycle binding as the status shows it: a scene file by its file name. */
static const char *value_name(const lr_rig_binding *b, int i)
{
    const char *v = b->values[i];
    const char *sl = strcmp(b->param, "scene") == 0 ? strrchr(v, '/') : NULL;
    return sl ? sl + 1 : v;
}

void lr_rig_get_status(lr_rig *r, lr_rig_status *st)
{
    int64_t now = lr_now_ns();
    const lr_rig_config *c = r->set.cfg;
    memset(st, 0, sizeof *st);
    st->version = lr_version();
    st->config = r->config_path;
    const char *scene = r->set.scene ? lr_scene_path(r->set.scene) : c->scene;
    const char *sl = strrchr(scene, '/');
    st->scene = sl ? sl + 1 : scene;
    st->output = r->kms ? "kms" : "headless";
    st->view = r->view ? lr_rig_view_name(r->view) : "";
    st->uptime_s = (double)(now - r->start_ns) * 1e-9;
    st->idle = r->view && !frame_due(r) && !lr_rig_view_busy(r->view);
    st->frames = r->frames;
    st->events = r->events;
    st->events_unmatched = r->unmatched;
    st->garbage = lr_control_map_garbage(r->set.map);
    st->reloads = r->reloads;
    st->reload_failures = r->reload_failures;
    st->lamp_level = r->lamp_written;
    /* fps: the frames that started in the last 2 s, over the time between the first and the
     * last of them (0 when fewer than two: an idle rig renders nothing). The interval p99 is
     * the nearest-rank 99th percentile of the last FRAME_TIMES - 1 start-to-start intervals. */
    int n = r->frames < FRAME_TIMES ? (int)r->frames : FRAME_TIMES;
    int64_t t[FRAME_TIMES], iv[FRAME_TIMES];
    for (int i = 0; i < n; i++) /* oldest first */
        t[i] = r->frame_t[(r->frames - (uint64_t)n + (uint64_t)i) % FRAME_TIMES];
    int recent = 0;
    for (int i = 0; i < n; i++)
        recent += t[i] >= now - 2000000000LL;
    st->fps = recent >= 2 ? (recent - 1) / ((double)(t[n - 1] - t[n - recent]) * 1e-9) : 0;
    for (int i = 1; i < n; i++)
        iv[i - 1] = t[i] - t[i - 1];
    if (n >= 2) {
        qsort(iv, (size_t)(n - 1), sizeof iv[0], cmp_i64);
        int k = (int)ceil(0.99 * (n - 1)) - 1;
        st->frame_interval_p99_ms = (double)iv[k < 0 ? 0 : k] * 1e-6;
    } else {
        st->frame_interval_p99_ms = NAN;
    }
    st->latency_n = lr_rig_stats_events(r->stats);
    st->latency_median_ms = lr_rig_stats_latency_ms(r->stats, 0.5);
    st->latency_p99_ms = lr_rig_stats_latency_ms(r->stats, 0.99);
    st->n_devices = r->set.n_devs;
    for (int i = 0; i < r->set.n_devs; i++) {
        lr_dev *d = r->set.devs[i];
        st->devices[i] = (lr_rig_status_dev){lr_dev_name(d), lr_dev_kind(d),
                                             lr_dev_state_name(lr_dev_get_state(d))};
    }
    st->planned = r->plan.planned;
    st->plan_text = r->plan.text;
    st->plan_error = r->plan.error;
    st->plan_frame_ms = r->plan.frame_ms;
    st->warnings = r->warnings;
    st->n_warnings = r->n_warnings;
    st->errors = r->errors;
    st->n_errors = r->n_errors;
    st->n_controls = c->n_bindings;
    for (int i = 0; i < c->n_bindings; i++) {
        const lr_rig_binding *b = &c->bindings[i];
        lr_rig_status_control *o = &st->controls[i];
        o->name = b->name;
        o->source = b->source;
        o->control = b->control;
        o->param = b->param;
        o->cycle = b->kind == LR_BIND_CYCLE;
        o->position = lr_control_map_position(r->set.map, i);
        o->level = lr_control_map_level(r->set.map, i, now);
        o->index = lr_control_map_index(r->set.map, i);
        o->n_values = o->cycle ? b->n_values : 0;
        for (int k = 0; k < o->n_values; k++)
            o->values[k] = value_name(b, k);
    }
}

static void push_absolute(lr_rig *r, const lr_rig_binding *b, double x)
{
    lr_event ev;
    lr_event_set(&ev, b->source[0] ? b->source : "http", b->control, LR_EV_ABSOLUTE, x,
                 lr_now_ns());
    lr_event_ring_push(r->ring, &ev);
}

int lr_rig_post_control(lr_rig *r, const char *name, double x, lr_err *e)
{
    if (!(x >= 0 && x <= 1))
        return lr_err_set(e, LR_EINVAL, "value must be in 0..1, got %g", x);
    const lr_rig_config *c = r->set.cfg;
    for (int i = 0; i < c->n_bindings; i++)
        if (strcmp(c->bindings[i].name, name) == 0) {
            push_absolute(r, &c->bindings[i], x);
            return LR_OK;
        }
    return lr_err_set(e, LR_ENODEV, "no control named '%s'", name);
}

int lr_rig_post_scene(lr_rig *r, const char *name, lr_err *e)
{
    const lr_rig_config *c = r->set.cfg;
    size_t nl = strlen(name);
    for (int i = 0; i < c->n_bindings; i++) {
        const lr_rig_binding *b = &c->bindings[i];
        if (b->kind != LR_BIND_CYCLE || strcmp(b->param, "scene") != 0)
            continue;
        for (int k = 0; k < b->n_values; k++) {
            const char *v = value_name(b, k);
            if (strcmp(v, name) == 0 ||
                (strncmp(v, name, nl) == 0 && strcmp(v + nl, ".json") == 0)) {
                /* The middle of the value's slot: floor(x * n) = k whatever rounding. */
                push_absolute(r, b, (k + 0.5) / b->n_values);
                return LR_OK;
            }
        }
    }
    /* A shipped scene, by a plain name only: no path reaches outside configs/scenes/. */
    char base[LR_RIG_PATH_MAX];
    snprintf(base, sizeof base, "%s", name);
    if (nl > 5 && strcmp(base + nl - 5, ".json") == 0)
        base[nl - 5] = '\0';
    bool plain = base[0] && strlen(base) < 64;
    for (const char *p = base; *p && plain; p++)
        plain = (*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') ||
                *p == '_' || *p == '-';
    char path[LR_RIG_PATH_MAX];
    struct stat sb;
    if (plain && snprintf(path, sizeof path, "%s/scenes/%s.json", lr_configs_dir(), base) <
                     (int)sizeof path &&
        stat(path, &sb) == 0 && S_ISREG(sb.st_mode)) {
        snprintf(r->http_scene, sizeof r->http_scene, "%s", path);
        return LR_OK;
    }
    return lr_err_set(e, LR_ENODEV,
                      "no scene '%s' in the config's scene binding or in %s/scenes", name,
                      lr_configs_dir());
}

const unsigned char *lr_rig_frame_rgba(lr_rig *r, int *w, int *h, uint64_t *frame, lr_err *e)
{
    if (!r->frames || !r->view) {
        lr_err_set(e, LR_ENODEV, "the rig has not rendered a frame");
        return NULL;
    }
    lr_rig_view_size(r->view, w, h);
    free(r->http_rgba);
    if (!(r->http_rgba = malloc((size_t)*w * (size_t)*h * 4))) {
        lr_err_set(e, LR_ENOMEM, "out of memory");
        return NULL;
    }
    if (lr_rig_view_read_rgba8(r->view, r->http_rgba, e))
        return NULL;
    *frame = r->frames - 1;
    return r->http_rgba;
}

int lr_rig_http_port(const lr_rig *r) { return lr_http_port(r->http); }
