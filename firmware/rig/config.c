/* lamprig firmware — rig config parsing and validation (schema in config.h). */
#include "firmware/rig/config.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <arpa/inet.h>
#include <netinet/in.h>

#include "firmware/control/curve.h"
#include "hal/gpio.h"
#include "hal/hid.h"
#include "hal/artnet.h"
#include "hal/hid_report.h"
#include "hal/modbus.h"
#include "hal/opt.h"
#include "hal/osc.h"
#include "hal/sacn.h"
#include "hal/sim.h"
#include "hal/usb.h"
#include "render/base/json.h"
#include "render/scene/scene.h"

typedef struct ctx {
    const lr_json *j;
    lr_rig_config *c;
    char dir[LR_RIG_PATH_MAX]; /* directory of the config file, "" for the cwd */
    lr_err *e;
} ctx;

/* ---- field helpers: messages name the full field path ---- */

static void field_name(char *buf, size_t cap, const char *prefix, const char *key)
{
    if (prefix && *prefix)
        snprintf(buf, cap, "%s.%s", prefix, key);
    else
        snprintf(buf, cap, "%s", key);
}

static int missing(ctx *x, lr_jnode obj, const char *prefix, const char *key)
{
    char f[192];
    field_name(f, sizeof f, prefix, key);
    return lr_json_fail(x->j, obj, f, x->e, LR_EPARSE, "required field is missing");
}

static int get_num(ctx *x, lr_jnode obj, const char *prefix, const char *key, bool required,
                   double *out)
{
    lr_jnode v = lr_json_get(x->j, obj, key);
    if (v == LR_JNONE)
        return required ? missing(x, obj, prefix, key) : LR_OK;
    char f[192];
    field_name(f, sizeof f, prefix, key);
    return lr_json_number(x->j, v, f, out, x->e);
}

static int get_num_in(ctx *x, lr_jnode obj, const char *prefix, const char *key, bool required,
                      double lo, double hi, double *out)
{
    double v = *out;
    int rc = get_num(x, obj, prefix, key, required, &v);
    if (rc)
        return rc;
    if (v < lo || v > hi) {
        char f[192];
        field_name(f, sizeof f, prefix, key);
        return lr_json_fail(x->j, lr_json_get(x->j, obj, key), f, x->e, LR_EPARSE,
                            "must be in %g..%g, got %g", lo, hi, v);
    }
    *out = v;
    return LR_OK;
}

static int get_int_in(ctx *x, lr_jnode obj, const char *prefix, const char *key, bool required,
                      long lo, long hi, int *out)
{
    lr_jnode v = lr_json_get(x->j, obj, key);
    if (v == LR_JNONE)
        return required ? missing(x, obj, prefix, key) : LR_OK;
    char f[192];
    field_name(f, sizeof f, prefix, key);
    long n;
    int rc = lr_json_int(x->j, v, f, &n, x->e);
    if (rc)
        return rc;
    if (n < lo || n > hi)
        return lr_json_fail(x->j, v, f, x->e, LR_EPARSE, "must be in %ld..%ld, got %ld", lo, hi,
                            n);
    *out = (int)n;
    return LR_OK;
}

static int get_bool(ctx *x, lr_jnode obj, const char *prefix, const char *key, bool *out)
{
    lr_jnode v = lr_json_get(x->j, obj, key);
    if (v == LR_JNONE)
        return LR_OK;
    char f[192];
    field_name(f, sizeof f, prefix, key);
    return lr_json_bool(x->j, v, f, out, x->e);
}

static int get_str(ctx *x, lr_jnode obj, const char *prefix, const char *key, bool required,
                   char *buf, size_t cap)
{
    lr_jnode v = lr_json_get(x->j, obj, key);
    if (v == LR_JNONE)
        return required ? missing(x, obj, prefix, key) : LR_OK;
    char f[192];
    field_name(f, sizeof f, prefix, key);
    int rc = lr_json_string(x->j, v, f, buf, cap, x->e);
    if (rc)
        return rc;
    if (!*buf)
        return lr_json_fail(x->j, v, f, x->e, LR_EPARSE, "must not be empty");
    return LR_OK;
}

/* Checks keys, naming unknown ones with the object's path. */
static int keys(ctx *x, lr_jnode obj, const char *where, const char *const *allowed)
{
    if (lr_json_type(x->j, obj) != LR_JSON_OBJECT)
        return lr_json_fail(x->j, obj, where, x->e, LR_EPARSE, "expected an object, got %s",
                            lr_json_type_name(lr_json_type(x->j, obj)));
    int n = lr_json_count(x->j, obj);
    for (int m = 0; m < n; m++) {
        lr_jnode k = lr_json_key_at(x->j, obj, m);
        bool ok = false;
        for (const char *const *a = allowed; *a && !ok; a++)
            ok = lr_json_str_eq(x->j, k, *a);
        if (!ok) {
            char key[96] = "?";
            lr_json_string(x->j, k, "key", key, sizeof key, NULL);
            char f[192];
            field_name(f, sizeof f, where, key);
            return lr_json_fail(x->j, k, f, x->e, LR_EPARSE, "unknown field");
        }
    }
    return lr_json_check_keys(x->j, obj, where, allowed, x->e);
}

/* A control or device name: 1..31 characters of [A-Za-z0-9_.-] (what events carry). */
static int check_name(ctx *x, lr_jnode n, const char *field, const char *s)
{
    size_t len = strlen(s);
    bool ok = len > 0 && len < LR_RIG_NAME_MAX;
    for (size_t i = 0; ok && i < len; i++) {
        char ch = s[i];
        ok = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') ||
             ch == '_' || ch == '.' || ch == '-';
    }
    if (!ok)
        return lr_json_fail(x->j, n, field, x->e, LR_EPARSE,
                            "'%s' is not a name (1..31 of A-Z a-z 0-9 _ . -)", s);
    return LR_OK;
}

/* ---- hal options (hal/opt.h): key, range and default are the back end's own ---- */

/* An integer option: absent keeps *out (the caller's default, normally o->dflt). */
static int opt_int(ctx *x, lr_jnode obj, const char *prefix, const lr_opt *o, int *out)
{
    return get_int_in(x, obj, prefix, o->key, o->required, o->lo, o->hi, out);
}

static int opt_bool(ctx *x, lr_jnode obj, const char *prefix, const lr_opt *o, bool *out)
{
    *out = o->dflt != 0;
    return get_bool(x, obj, prefix, o->key, out);
}

/* An enum option: *out receives the index of the name (the hal enum's value). */
static int opt_enum(ctx *x, lr_jnode obj, const char *prefix, const lr_opt *o, int *out)
{
    char s[32];
    snprintf(s, sizeof s, "%s", o->names[o->dflt]);
    int rc = get_str(x, obj, prefix, o->key, o->required, s, sizeof s);
    if (rc)
        return rc;
    int i = lr_opt_enum_index(o, s);
    if (i >= 0) {
        *out = i;
        return LR_OK;
    }
    char list[160] = "", f[192];
    for (int k = 0; o->names[k]; k++)
        snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s",
                 k == 0 ? "" : o->names[k + 1] ? ", " : " or ", o->names[k]);
    field_name(f, sizeof f, prefix, o->key);
    return lr_json_fail(x->j, lr_json_get(x->j, obj, o->key), f, x->e, LR_EPARSE,
                        "'%s' is not %s", s, list);
}

/* The keys an object may have: those of the option tables (NULL-terminated list of tables)
 * and the extra ones; out holds up to cap - 1 keys and a NULL. */
static void opt_keys(const lr_opt *const *tables, const char *const *extra, const char **out,
                     int cap)
{
    int n = 0;
    for (; extra && *extra && n < cap - 1; extra++)
        out[n++] = *extra;
    for (; *tables; tables++)
        for (const lr_opt *o = *tables; o->key && n < cap - 1; o++)
            out[n++] = o->key;
    out[n] = NULL;
}

/* Resolves a path against the config's directory and checks that the file exists. */
static int resolve(ctx *x, lr_jnode n, const char *field, const char *rel, char *out, size_t cap)
{
    int w;
    if (rel[0] == '/' || !x->dir[0])
        w = snprintf(out, cap, "%s", rel);
    else
        w = snprintf(out, cap, "%s/%s", x->dir, rel);
    if (w < 0 || (size_t)w >= cap)
        return lr_json_fail(x->j, n, field, x->e, LR_EPARSE, "path too long");
    struct stat st;
    if (stat(out, &st) != 0)
        return lr_json_fail(x->j, n, field, x->e, LR_EPARSE, "'%s': %s", out, strerror(errno));
    if (!S_ISREG(st.st_mode))
        return lr_json_fail(x->j, n, field, x->e, LR_EPARSE, "'%s' is not a file", out);
    return LR_OK;
}

static int get_hex16(ctx *x, lr_jnode obj, const char *prefix, const char *key, uint16_t *out)
{
    char s[16] = "";
    int rc = get_str(x, obj, prefix, key, true, s, sizeof s);
    if (rc)
        return rc;
    char *end;
    errno = 0;
    unsigned long v = strtoul(s, &end, 16);
    if (errno || *end || v > 0xffff || s[0] == '-' || s[0] == '+') {
        char f[192];
        field_name(f, sizeof f, prefix, key);
        return lr_json_fail(x->j, lr_json_get(x->j, obj, key), f, x->e, LR_EPARSE,
                            "'%s' is not a 16-bit hex id like \"077d\"", s);
    }
    *out = (uint16_t)v;
    return LR_OK;
}

/* ---- devices ---- */

static int modbus_reg(ctx *x, lr_jnode o, const char *where, bool lamp, lr_rig_modbus_reg *r)
{
    const lr_opt *in = lr_modbus_input_opts, *out = lr_modbus_output_opts;
    const lr_opt *const tables[] = {lamp ? out : in, NULL};
    const char *allowed[16];
    opt_keys(tables, NULL, allowed, 16);
    int rc = keys(x, o, where, allowed);
    if (rc)
        return rc;
    snprintf(r->control, sizeof r->control, "%s", in[LR_MODBUS_IN_CONTROL].dflt_text);
    r->unit = lamp ? LR_RIG_LAMP_UNIT : (int)in[LR_MODBUS_IN_UNIT].dflt;
    if (!lamp) {
        if ((rc = get_str(x, o, where, "control", false, r->control, sizeof r->control)))
            return rc;
        char f[192];
        field_name(f, sizeof f, where, "control");
        if ((rc = check_name(x, o, f, r->control)))
            return rc;
        int type = LR_MODBUS_HOLDING;
        if ((rc = opt_enum(x, o, where, &in[LR_MODBUS_IN_TYPE], &type)))
            return rc;
        r->input_regs = type == LR_MODBUS_INPUT;
    } else if ((rc = opt_bool(x, o, where, &out[LR_MODBUS_OUT_MULTIPLE], &r->multiple))) {
        return rc;
    }
    const lr_opt *unit = lamp ? &out[LR_MODBUS_OUT_UNIT] : &in[LR_MODBUS_IN_UNIT];
    const lr_opt *base = lamp ? &out[LR_MODBUS_OUT_BASE] : &in[LR_MODBUS_IN_BASE];
    const lr_opt *raw_min = lamp ? &out[LR_MODBUS_OUT_RAW_MIN] : &in[LR_MODBUS_IN_RAW_MIN];
    const lr_opt *raw_max = lamp ? &out[LR_MODBUS_OUT_RAW_MAX] : &in[LR_MODBUS_IN_RAW_MAX];
    const lr_opt *reg = lamp ? &out[LR_MODBUS_OUT_REG] : &in[LR_MODBUS_IN_REG];
    r->raw_min = (int)raw_min->dflt;
    r->raw_max = (int)raw_max->dflt;
    if ((rc = opt_int(x, o, where, unit, &r->unit)) ||
        (rc = opt_int(x, o, where, base, &r->base)) ||
        /* The descriptor's range is the address reg - base's. */
        (rc = get_int_in(x, o, where, "reg", true, reg->lo + r->base, reg->hi + r->base,
                         &r->reg)) ||
        (rc = opt_int(x, o, where, raw_min, &r->raw_min)) ||
        (rc = opt_int(x, o, where, raw_max, &r->raw_max)))
        return rc;
    if (r->raw_max <= r->raw_min) {
        char f[192];
        field_name(f, sizeof f, where, "raw_max");
        return lr_json_fail(x->j, o, f, x->e, LR_EPARSE, "must be greater than raw_min (%d), got %d",
                            r->raw_min, r->raw_max);
    }
    return LR_OK;
}

/* sacn and artnet: the receiver's options and its "channels" (hal/sacn.h, hal/artnet.h). */
static int dmx_device(ctx *x, lr_jnode o, const char *where, lr_rig_device *d)
{
    bool sacn = d->type == LR_RIG_DEV_SACN;
    const lr_opt *so = lr_sacn_opts, *ao = lr_artnet_opts;
    const lr_opt *chopts = sacn ? lr_sacn_channel_opts : lr_artnet_channel_opts;
    const lr_opt *bind = sacn ? &so[LR_SACN_OPT_BIND] : &ao[LR_ARTNET_OPT_BIND];
    const lr_opt *port = sacn ? &so[LR_SACN_OPT_PORT] : &ao[LR_ARTNET_OPT_PORT];
    const lr_opt *loss = sacn ? &so[LR_SACN_OPT_LOSS] : &ao[LR_ARTNET_OPT_LOSS];
    const lr_opt *fade = sacn ? &so[LR_SACN_OPT_FADE_MS] : &ao[LR_ARTNET_OPT_FADE_MS];
    const lr_opt *maxp = sacn ? &so[LR_SACN_OPT_MAX_PACKETS] : &ao[LR_ARTNET_OPT_MAX_PACKETS];
    snprintf(d->bind, sizeof d->bind, "%s", bind->dflt_text);
    d->port = (int)port->dflt;
    d->fade_ms = (int)fade->dflt;
    d->max_packets = (int)maxp->dflt;
    int rc;
    if ((rc = get_str(x, o, where, bind->key, false, d->bind, sizeof d->bind)) ||
        (rc = opt_int(x, o, where, port, &d->port)) ||
        (rc = opt_enum(x, o, where, loss, &d->loss)) ||
        (rc = opt_int(x, o, where, fade, &d->fade_ms)) ||
        (rc = opt_int(x, o, where, maxp, &d->max_packets)))
        return rc;
    if (sacn) {
        d->max_sources = (int)so[LR_SACN_OPT_MAX_SOURCES].dflt;
        d->loss_ms = (int)so[LR_SACN_OPT_LOSS_MS].dflt;
        if ((rc = get_str(x, o, where, "interface", false, d->interface, sizeof d->interface)) ||
            (rc = opt_bool(x, o, where, &so[LR_SACN_OPT_UNICAST_ONLY], &d->unicast_only)) ||
            (rc = opt_bool(x, o, where, &so[LR_SACN_OPT_PREVIEW], &d->preview)) ||
            (rc = opt_int(x, o, where, &so[LR_SACN_OPT_MAX_SOURCES], &d->max_sources)) ||
            (rc = opt_int(x, o, where, &so[LR_SACN_OPT_LOSS_MS], &d->loss_ms)))
            return rc;
    } else {
        d->merge_timeout_ms = (int)ao[LR_ARTNET_OPT_MERGE_TIMEOUT_MS].dflt;
        snprintf(d->short_name, sizeof d->short_name, "%s",
                 ao[LR_ARTNET_OPT_SHORT_NAME].dflt_text);
        snprintf(d->announce, sizeof d->announce, "%s", ao[LR_ARTNET_OPT_ANNOUNCE].dflt_text);
        if ((rc = get_str(x, o, where, "announce", false, d->announce, sizeof d->announce)) ||
            (rc = get_str(x, o, where, "short_name", false, d->short_name,
                          sizeof d->short_name)) ||
            (rc = opt_enum(x, o, where, &ao[LR_ARTNET_OPT_MERGE], &d->merge)) ||
            (rc = opt_int(x, o, where, &ao[LR_ARTNET_OPT_MERGE_TIMEOUT_MS],
                          &d->merge_timeout_ms)))
            return rc;
    }
    char f[192];
    lr_jnode arr = lr_json_get(x->j, o, "channels");
    field_name(f, sizeof f, where, "channels");
    if (arr == LR_JNONE)
        return missing(x, o, where, "channels");
    if (lr_json_type(x->j, arr) != LR_JSON_ARRAY || lr_json_count(x->j, arr) < 1 ||
        lr_json_count(x->j, arr) > LR_RIG_MAX_CHANNELS)
        return lr_json_fail(x->j, arr, f, x->e, LR_EPARSE, "expected an array of 1..%d",
                            LR_RIG_MAX_CHANNELS);
    for (int i = 0; i < lr_json_count(x->j, arr); i++) {
        lr_jnode it = lr_json_at(x->j, arr, i);
        char w[96], wf[128];
        snprintf(w, sizeof w, "%s.channels[%d]", where, i);
        const lr_opt *const itables[] = {chopts, NULL};
        const char *iallowed[16];
        opt_keys(itables, NULL, iallowed, 16);
        lr_rig_dmx_channel *c = &d->channels[i];
        c->universe = (int)chopts[LR_DMX_CH_UNIVERSE].dflt;
        if ((rc = keys(x, it, w, iallowed)) ||
            (rc = get_str(x, it, w, "control", true, c->control, sizeof c->control)))
            return rc;
        field_name(wf, sizeof wf, w, "control");
        if ((rc = check_name(x, it, wf, c->control)) ||
            (rc = opt_int(x, it, w, &chopts[LR_DMX_CH_UNIVERSE], &c->universe)) ||
            (rc = opt_int(x, it, w, &chopts[LR_DMX_CH_CHANNEL], &c->channel)) ||
            (rc = opt_int(x, it, w, &chopts[LR_DMX_CH_FINE], &c->fine)))
            return rc;
        for (int k = 0; k < i; k++)
            if (strcmp(d->channels[k].control, c->control) == 0)
                return lr_json_fail(x->j, it, w, x->e, LR_EPARSE, "control '%s' appears twice",
                                    c->control);
        if (c->fine == c->channel) {
            field_name(wf, sizeof wf, w, "fine");
            return lr_json_fail(x->j, it, wf, x->e, LR_EPARSE,
                                "the fine byte cannot be the channel itself (%d)", c->channel);
        }
        d->n_channels = i + 1;
    }
    return LR_OK;
}

static int osc_device(ctx *x, lr_jnode o, const char *where, lr_rig_device *d)
{
    const lr_opt *oo = lr_osc_opts;
    d->port = (int)oo[LR_OSC_OPT_PORT].dflt;
    d->max_packets = (int)oo[LR_OSC_OPT_MAX_PACKETS].dflt;
    snprintf(d->prefix, sizeof d->prefix, "%s", oo[LR_OSC_OPT_PREFIX].dflt_text);
    int rc;
    if ((rc = opt_int(x, o, where, &oo[LR_OSC_OPT_PORT], &d->port)) ||
        (rc = opt_int(x, o, where, &oo[LR_OSC_OPT_MAX_PACKETS], &d->max_packets)) ||
        (rc = get_str(x, o, where, "prefix", false, d->prefix, sizeof d->prefix)))
        return rc;
    char f[192];
    snprintf(d->scene_control, sizeof d->scene_control, "%s",
             oo[LR_OSC_OPT_SCENE_CONTROL].dflt_text);
    if ((rc = get_str(x, o, where, "scene_control", false, d->scene_control,
                      sizeof d->scene_control)))
        return rc;
    field_name(f, sizeof f, where, "scene_control");
    if ((rc = check_name(x, o, f, d->scene_control)))
        return rc;
    size_t pl = strlen(d->prefix);
    if (pl < 2 || d->prefix[0] != '/' || d->prefix[pl - 1] == '/') {
        field_name(f, sizeof f, where, "prefix");
        return lr_json_fail(x->j, lr_json_get(x->j, o, "prefix"), f, x->e, LR_EPARSE,
                            "'%s' is not /NAME[/NAME...] without a trailing '/'", d->prefix);
    }
    lr_jnode arr = lr_json_get(x->j, o, "scenes");
    if (arr == LR_JNONE)
        return LR_OK;
    field_name(f, sizeof f, where, "scenes");
    if (lr_json_type(x->j, arr) != LR_JSON_ARRAY ||
        lr_json_count(x->j, arr) > LR_RIG_MAX_SCENE_NAMES)
        return lr_json_fail(x->j, arr, f, x->e, LR_EPARSE,
                            "expected an array of at most %d names", LR_RIG_MAX_SCENE_NAMES);
    for (int i = 0; i < lr_json_count(x->j, arr); i++) {
        char w[208];
        snprintf(w, sizeof w, "%s[%d]", f, i);
        lr_jnode it = lr_json_at(x->j, arr, i);
        if ((rc = lr_json_string(x->j, it, w, d->scenes[i], sizeof d->scenes[i], x->e)) ||
            (rc = check_name(x, it, w, d->scenes[i])))
            return rc;
        d->n_scenes = i + 1;
    }
    return LR_OK;
}

static int device(ctx *x, lr_jnode o, int index, lr_rig_device *d)
{
    char where[64];
    snprintf(where, sizeof where, "devices[%d]", index);
    d->line = lr_json_line(x->j, o);
    if (lr_json_type(x->j, o) != LR_JSON_OBJECT)
        return lr_json_fail(x->j, o, where, x->e, LR_EPARSE, "expected an object");
    char type[16];
    int rc = get_str(x, o, where, "type", true, type, sizeof type);
    if (rc)
        return rc;
    static const char *const types[] = {"sim", "modbus", "gpio", "hid", "usb",
                                        "sacn", "artnet", "osc"};
    int t = -1;
    for (int i = 0; i < 8; i++)
        if (strcmp(type, types[i]) == 0)
            t = i;
    char f[192];
    field_name(f, sizeof f, where, "type");
    if (t < 0)
        return lr_json_fail(x->j, lr_json_get(x->j, o, "type"), f, x->e, LR_EPARSE,
                            "unknown device type '%s' (sim, modbus, gpio, hid, usb, sacn, "
                            "artnet, osc)", type);
    d->type = (lr_rig_dev_type)t;
    /* The options of every device and of its back end (hal/opt.h), in lr_rig_dev_type order. */
    static const lr_opt *const backend[] = {lr_sim_opts, lr_modbus_opts, lr_gpio_opts,
                                            lr_hid_opts, lr_usb_opts, lr_sacn_opts,
                                            lr_artnet_opts, lr_osc_opts};
    static const char *const type_key[] = {"type", NULL};
    const lr_opt *const tables[] = {lr_dev_opts, backend[t], NULL};
    const char *allowed[32];
    opt_keys(tables, type_key, allowed, 32);
    if ((rc = keys(x, o, where, allowed)))
        return rc;
    snprintf(d->name, sizeof d->name, "%s", type);
    if ((rc = get_str(x, o, where, "name", false, d->name, sizeof d->name)))
        return rc;
    field_name(f, sizeof f, where, "name");
    if ((rc = check_name(x, o, f, d->name)))
        return rc;
    const lr_opt *dv = lr_dev_opts;
    d->retry_min_ms = (int)dv[LR_DEV_OPT_RETRY_MIN_MS].dflt;
    d->retry_max_ms = (int)dv[LR_DEV_OPT_RETRY_MAX_MS].dflt;
    if ((rc = opt_bool(x, o, where, &dv[LR_DEV_OPT_REQUIRED], &d->required)) ||
        (rc = opt_int(x, o, where, &dv[LR_DEV_OPT_RETRY_MIN_MS], &d->retry_min_ms)) ||
        (rc = opt_int(x, o, where, &dv[LR_DEV_OPT_RETRY_MAX_MS], &d->retry_max_ms)))
        return rc;
    switch (d->type) {
    case LR_RIG_DEV_SIM: {
        lr_jnode s = lr_json_get(x->j, o, "script"), tx = lr_json_get(x->j, o, "text");
        if ((s == LR_JNONE) == (tx == LR_JNONE))
            return lr_json_fail(x->j, o, where, x->e, LR_EPARSE,
                                "give exactly one of 'script' (a file) or 'text'");
        if (s != LR_JNONE) {
            char rel[LR_RIG_PATH_MAX];
            if ((rc = get_str(x, o, where, "script", true, rel, sizeof rel)))
                return rc;
            field_name(f, sizeof f, where, "script");
            if ((rc = resolve(x, s, f, rel, d->script, sizeof d->script)))
                return rc;
        } else {
            enum { TEXT_MAX = 1 << 16 };
            field_name(f, sizeof f, where, "text");
            d->text = malloc(TEXT_MAX);
            if (!d->text)
                return lr_err_set(x->e, LR_ENOMEM, "out of memory");
            if ((rc = lr_json_string(x->j, tx, f, d->text, TEXT_MAX, x->e)))
                return rc;
        }
        return opt_bool(x, o, where, &lr_sim_opts[LR_SIM_OPT_LOOP], &d->loop);
    }
    case LR_RIG_DEV_MODBUS: {
        const lr_opt *mo = lr_modbus_opts;
        d->poll_ms = (int)mo[LR_MODBUS_OPT_POLL_MS].dflt;
        d->timeout_ms = (int)mo[LR_MODBUS_OPT_TIMEOUT_MS].dflt;
        d->byte_timeout_ms = (int)mo[LR_MODBUS_OPT_BYTE_TIMEOUT_MS].dflt;
        d->max_timeouts = (int)mo[LR_MODBUS_OPT_MAX_TIMEOUTS].dflt;
        if ((rc = get_str(x, o, where, "url", true, d->url, sizeof d->url)) ||
            (rc = opt_int(x, o, where, &mo[LR_MODBUS_OPT_POLL_MS], &d->poll_ms)) ||
            (rc = opt_int(x, o, where, &mo[LR_MODBUS_OPT_TIMEOUT_MS], &d->timeout_ms)) ||
            (rc = opt_int(x, o, where, &mo[LR_MODBUS_OPT_BYTE_TIMEOUT_MS], &d->byte_timeout_ms)) ||
            (rc = opt_int(x, o, where, &mo[LR_MODBUS_OPT_MAX_TIMEOUTS], &d->max_timeouts)))
            return rc;
        lr_modbus_url u;
        lr_err ue = {0};
        if (lr_modbus_url_parse(d->url, &u, &ue)) {
            field_name(f, sizeof f, where, "url");
            return lr_json_fail(x->j, lr_json_get(x->j, o, "url"), f, x->e, LR_EPARSE, "%s",
                                ue.msg);
        }
        lr_jnode in = lr_json_get(x->j, o, "inputs");
        if (in != LR_JNONE) {
            field_name(f, sizeof f, where, "inputs");
            if (lr_json_type(x->j, in) != LR_JSON_ARRAY)
                return lr_json_fail(x->j, in, f, x->e, LR_EPARSE, "expected an array");
            if (lr_json_count(x->j, in) > LR_RIG_MAX_ITEMS)
                return lr_json_fail(x->j, in, f, x->e, LR_EPARSE, "at most %d inputs",
                                    LR_RIG_MAX_ITEMS);
            for (int i = 0; i < lr_json_count(x->j, in); i++) {
                char w[96];
                snprintf(w, sizeof w, "%s.inputs[%d]", where, i);
                if ((rc = modbus_reg(x, lr_json_at(x->j, in, i), w, false, &d->inputs[i])))
                    return rc;
                for (int k = 0; k < i; k++)
                    if (strcmp(d->inputs[k].control, d->inputs[i].control) == 0)
                        return lr_json_fail(x->j, lr_json_at(x->j, in, i), w, x->e, LR_EPARSE,
                                            "control '%s' appears twice", d->inputs[i].control);
                d->n_inputs = i + 1;
            }
        }
        lr_jnode lamp = lr_json_get(x->j, o, "lamp");
        if (lamp != LR_JNONE) {
            char w[96];
            snprintf(w, sizeof w, "%s.lamp", where);
            if ((rc = modbus_reg(x, lamp, w, true, &d->lamp)))
                return rc;
            d->has_lamp = true;
        }
        if (!d->n_inputs && !d->has_lamp)
            return lr_json_fail(x->j, o, where, x->e, LR_EPARSE,
                                "a modbus device needs 'inputs', 'lamp' or both");
        return LR_OK;
    }
    case LR_RIG_DEV_GPIO: {
        snprintf(d->chip, sizeof d->chip, "%s", lr_gpio_opts[LR_GPIO_OPT_CHIP].dflt_text);
        if ((rc = get_str(x, o, where, "chip", false, d->chip, sizeof d->chip)) ||
            (rc = opt_enum(x, o, where, &lr_gpio_opts[LR_GPIO_OPT_BIAS], &d->bias)))
            return rc;
        for (int pass = 0; pass < 2; pass++) {
            const char *key = pass ? "buttons" : "encoders";
            lr_jnode arr = lr_json_get(x->j, o, key);
            if (arr == LR_JNONE)
                continue;
            field_name(f, sizeof f, where, key);
            if (lr_json_type(x->j, arr) != LR_JSON_ARRAY)
                return lr_json_fail(x->j, arr, f, x->e, LR_EPARSE, "expected an array");
            if (lr_json_count(x->j, arr) > LR_RIG_MAX_ITEMS)
                return lr_json_fail(x->j, arr, f, x->e, LR_EPARSE, "at most %d entries",
                                    LR_RIG_MAX_ITEMS);
            for (int i = 0; i < lr_json_count(x->j, arr); i++) {
                lr_jnode it = lr_json_at(x->j, arr, i);
                char w[96], wf[128];
                snprintf(w, sizeof w, "%s.%s[%d]", where, key, i);
                const lr_opt *eo = lr_gpio_encoder_opts, *bo = lr_gpio_button_opts;
                const lr_opt *const itables[] = {pass ? bo : eo, NULL};
                const char *iallowed[16];
                opt_keys(itables, NULL, iallowed, 16);
                if ((rc = keys(x, it, w, iallowed)))
                    return rc;
                lr_rig_gpio_line *l = pass ? &d->buttons[i] : &d->encoders[i];
                l->steps_per_detent = (int)eo[LR_GPIO_ENC_STEPS_PER_DETENT].dflt;
                l->debounce_ms = (int)bo[LR_GPIO_BTN_DEBOUNCE_MS].dflt;
                if ((rc = get_str(x, it, w, "name", true, l->name, sizeof l->name)))
                    return rc;
                field_name(wf, sizeof wf, w, "name");
                if ((rc = check_name(x, it, wf, l->name)))
                    return rc;
                if (pass) {
                    if ((rc = get_str(x, it, w, "line", true, l->line_a, sizeof l->line_a)) ||
                        (rc = opt_bool(x, it, w, &bo[LR_GPIO_BTN_ACTIVE_HIGH], &l->active_high)) ||
                        (rc = opt_int(x, it, w, &bo[LR_GPIO_BTN_DEBOUNCE_MS], &l->debounce_ms)))
                        return rc;
                    d->n_buttons = i + 1;
                } else {
                    if ((rc = get_str(x, it, w, "line_a", true, l->line_a, sizeof l->line_a)) ||
                        (rc = get_str(x, it, w, "line_b", true, l->line_b, sizeof l->line_b)) ||
                        (rc = opt_bool(x, it, w, &eo[LR_GPIO_ENC_REVERSE], &l->reverse)) ||
                        (rc = opt_int(x, it, w, &eo[LR_GPIO_ENC_STEPS_PER_DETENT],
                                      &l->steps_per_detent)))
                        return rc;
                    if (l->steps_per_detent == 3) {
                        field_name(wf, sizeof wf, w, "steps_per_detent");
                        return lr_json_fail(x->j, it, wf, x->e, LR_EPARSE,
                                            "must be 1, 2 or 4, got 3");
                    }
                    d->n_encoders = i + 1;
                }
            }
        }
        if (!d->n_encoders && !d->n_buttons)
            return lr_json_fail(x->j, o, where, x->e, LR_EPARSE,
                                "a gpio device needs 'encoders', 'buttons' or both");
        return LR_OK;
    }
    case LR_RIG_DEV_HID: {
        const lr_opt *ho = lr_hid_opts;
        d->poll_ms = (int)ho[LR_HID_OPT_POLL_MS].dflt;
        d->report_id = (int)ho[LR_HID_OPT_REPORT_ID].dflt;
        if ((rc = get_hex16(x, o, where, "vid", &d->vid)) ||
            (rc = get_hex16(x, o, where, "pid", &d->pid)) ||
            (rc = opt_int(x, o, where, &ho[LR_HID_OPT_POLL_MS], &d->poll_ms)) ||
            (rc = opt_int(x, o, where, &ho[LR_HID_OPT_REPORT_ID], &d->report_id)) ||
            (rc = opt_enum(x, o, where, &ho[LR_HID_OPT_PROTO], &d->proto)))
            return rc;
        return get_str(x, o, where, "serial", false, d->serial, sizeof d->serial);
    }
    case LR_RIG_DEV_USB: {
        const lr_opt *uo = lr_usb_opts, *wo = lr_usb_watch_opts;
        d->rescan_ms = (int)uo[LR_USB_OPT_RESCAN_MS].dflt;
        if ((rc = opt_int(x, o, where, &uo[LR_USB_OPT_RESCAN_MS], &d->rescan_ms)) ||
            (rc = opt_bool(x, o, where, &uo[LR_USB_OPT_NO_HOTPLUG], &d->no_hotplug)))
            return rc;
        lr_jnode arr = lr_json_get(x->j, o, "watch");
        field_name(f, sizeof f, where, "watch");
        if (arr == LR_JNONE)
            return missing(x, o, where, "watch");
        if (lr_json_type(x->j, arr) != LR_JSON_ARRAY || lr_json_count(x->j, arr) < 1 ||
            lr_json_count(x->j, arr) > LR_RIG_MAX_ITEMS)
            return lr_json_fail(x->j, arr, f, x->e, LR_EPARSE, "expected an array of 1..%d",
                                LR_RIG_MAX_ITEMS);
        for (int i = 0; i < lr_json_count(x->j, arr); i++) {
            lr_jnode it = lr_json_at(x->j, arr, i);
            char w[96], wf[128];
            snprintf(w, sizeof w, "%s.watch[%d]", where, i);
            const lr_opt *const itables[] = {wo, NULL};
            const char *iallowed[16];
            opt_keys(itables, NULL, iallowed, 16);
            lr_rig_usb_watch *u = &d->watch[i];
            u->interface = (int)wo[LR_USB_W_INTERFACE].dflt;
            if ((rc = keys(x, it, w, iallowed)) ||
                (rc = get_str(x, it, w, "name", true, u->name, sizeof u->name)))
                return rc;
            field_name(wf, sizeof wf, w, "name");
            if ((rc = check_name(x, it, wf, u->name)) ||
                (rc = get_hex16(x, it, w, "vid", &u->vid)) ||
                (rc = get_hex16(x, it, w, "pid", &u->pid)) ||
                (rc = opt_bool(x, it, w, &wo[LR_USB_W_READ_REPORTS], &u->read_reports)) ||
                (rc = opt_int(x, it, w, &wo[LR_USB_W_INTERFACE], &u->interface)) ||
                (rc = opt_enum(x, it, w, &wo[LR_USB_W_PROTO], &u->proto)))
                return rc;
            d->n_watch = i + 1;
        }
        return LR_OK;
    }
    case LR_RIG_DEV_SACN:
    case LR_RIG_DEV_ARTNET: return dmx_device(x, o, where, d);
    case LR_RIG_DEV_OSC: return osc_device(x, o, where, d);
    }
    return LR_OK;
}

/* ---- bindings ---- */

static int color3(ctx *x, lr_jnode n, const char *field, double out[3])
{
    int rc = lr_json_numbers(x->j, n, field, out, 3, x->e);
    if (rc)
        return rc;
    for (int k = 0; k < 3; k++)
        if (out[k] < 0)
            return lr_json_fail(x->j, n, field, x->e, LR_EPARSE,
                                "colour components must be >= 0, got %g", out[k]);
    return LR_OK;
}

static int binding(ctx *x, lr_jnode o, const char *where, lr_rig_binding *b)
{
    static const char *const b_keys[] = {"name", "control", "param", "range", "colors", "curve",
                                         "step", "accel", "fade_s", "initial", "lamp", "values",
                                         "wrap", NULL};
    int rc = keys(x, o, where, b_keys);
    if (rc)
        return rc;
    snprintf(b->file, sizeof b->file, "%s", lr_json_name(x->j));
    b->line = b->line_param = b->line_range = lr_json_line(x->j, o);
    if (lr_json_get(x->j, o, "param") != LR_JNONE)
        b->line_param = lr_json_line(x->j, lr_json_get(x->j, o, "param"));
    char f[192];
    char control[2 * LR_RIG_NAME_MAX + 2];
    if ((rc = get_str(x, o, where, "control", true, control, sizeof control)) ||
        (rc = get_str(x, o, where, "param", true, b->param, sizeof b->param)))
        return rc;
    field_name(f, sizeof f, where, "control");
    lr_jnode cn = lr_json_get(x->j, o, "control");
    char *slash = strchr(control, '/');
    if (slash) {
        *slash = '\0';
        if ((rc = check_name(x, cn, f, control)))
            return rc;
        snprintf(b->source, sizeof b->source, "%.31s", control);
        if ((rc = check_name(x, cn, f, slash + 1)))
            return rc;
        snprintf(b->control, sizeof b->control, "%.31s", slash + 1);
    } else {
        if ((rc = check_name(x, cn, f, control)))
            return rc;
        snprintf(b->control, sizeof b->control, "%.31s", control);
    }
    snprintf(b->name, sizeof b->name, "%s", b->control);
    if ((rc = get_str(x, o, where, "name", false, b->name, sizeof b->name)))
        return rc;

    lr_jnode values = lr_json_get(x->j, o, "values");
    lr_jnode colors = lr_json_get(x->j, o, "colors");
    lr_jnode range = lr_json_get(x->j, o, "range");
    bool scene = strcmp(b->param, "scene") == 0;
    b->wrap = true;
    if (values != LR_JNONE) {
        b->kind = LR_BIND_CYCLE;
        static const char *const level_only[] = {"range", "colors", "curve", "step", "accel",
                                                 "fade_s", "lamp", NULL};
        for (const char *const *k = level_only; *k; k++)
            if (lr_json_get(x->j, o, *k) != LR_JNONE) {
                field_name(f, sizeof f, where, *k);
                return lr_json_fail(x->j, lr_json_get(x->j, o, *k), f, x->e, LR_EPARSE,
                                    "not allowed with 'values' (a cycle binding)");
            }
        field_name(f, sizeof f, where, "values");
        int n = lr_json_count(x->j, values);
        if (lr_json_type(x->j, values) != LR_JSON_ARRAY || n < 1 || n > LR_RIG_MAX_VALUES)
            return lr_json_fail(x->j, values, f, x->e, LR_EPARSE,
                                "expected an array of 1..%d values", LR_RIG_MAX_VALUES);
        for (int i = 0; i < n; i++) {
            lr_jnode v = lr_json_at(x->j, values, i);
            b->line_values[i] = lr_json_line(x->j, v);
            char vf[224];
            snprintf(vf, sizeof vf, "%s[%d]", f, i);
            if (lr_json_type(x->j, v) == LR_JSON_ARRAY && !scene) {
                double c[3];
                if ((rc = color3(x, v, vf, c)))
                    return rc;
                snprintf(b->values[i], sizeof b->values[i], "%.17g,%.17g,%.17g", c[0], c[1],
                         c[2]);
            } else {
                char s[LR_RIG_PATH_MAX];
                if ((rc = lr_json_string(x->j, v, vf, s, sizeof s, x->e)))
                    return rc;
                if (!*s)
                    return lr_json_fail(x->j, v, vf, x->e, LR_EPARSE, "must not be empty");
                if (scene) {
                    if ((rc = resolve(x, v, vf, s, b->values[i], sizeof b->values[i])))
                        return rc;
                } else {
                    snprintf(b->values[i], sizeof b->values[i], "%s", s);
                }
            }
        }
        b->n_values = n;
        if ((rc = get_bool(x, o, where, "wrap", &b->wrap)))
            return rc;
        lr_jnode in = lr_json_get(x->j, o, "initial");
        if (in != LR_JNONE) {
            int idx = 0;
            if ((rc = get_int_in(x, o, where, "initial", false, 0, n - 1, &idx)))
                return rc;
            b->has_initial = true;
            b->initial = idx;
        }
        return LR_OK;
    }
    b->kind = LR_BIND_LEVEL;
    if (scene)
        return lr_json_fail(x->j, o, where, x->e, LR_EPARSE,
                            "param 'scene' needs 'values' (a list of scene files)");
    if (lr_json_get(x->j, o, "wrap") != LR_JNONE) {
        field_name(f, sizeof f, where, "wrap");
        return lr_json_fail(x->j, lr_json_get(x->j, o, "wrap"), f, x->e, LR_EPARSE,
                            "only for cycle bindings (with 'values')");
    }
    b->range[0] = 0;
    b->range[1] = 1;
    if (colors != LR_JNONE && range != LR_JNONE) {
        field_name(f, sizeof f, where, "colors");
        return lr_json_fail(x->j, colors, f, x->e, LR_EPARSE, "give 'range' or 'colors', not both");
    }
    if (range != LR_JNONE || colors != LR_JNONE)
        b->line_range = lr_json_line(x->j, range != LR_JNONE ? range : colors);
    if (range != LR_JNONE) {
        field_name(f, sizeof f, where, "range");
        if ((rc = lr_json_numbers(x->j, range, f, b->range, 2, x->e)))
            return rc;
        if (!(b->range[0] != b->range[1]))
            return lr_json_fail(x->j, range, f, x->e, LR_EPARSE, "range is empty: [%g, %g]",
                                b->range[0], b->range[1]);
    }
    if (colors != LR_JNONE) {
        field_name(f, sizeof f, where, "colors");
        if (lr_json_type(x->j, colors) != LR_JSON_ARRAY || lr_json_count(x->j, colors) != 2)
            return lr_json_fail(x->j, colors, f, x->e, LR_EPARSE,
                                "expected two colours [[r,g,b], [r,g,b]]");
        for (int i = 0; i < 2; i++) {
            char vf[224];
            snprintf(vf, sizeof vf, "%s[%d]", f, i);
            if ((rc = color3(x, lr_json_at(x->j, colors, i), vf, b->colors[i])))
                return rc;
        }
        b->is_color = true;
    }
    char curve[16] = "linear";
    if ((rc = get_str(x, o, where, "curve", false, curve, sizeof curve)))
        return rc;
    enum lr_curve cv;
    if (lr_curve_parse(curve, &cv) != 0) {
        field_name(f, sizeof f, where, "curve");
        return lr_json_fail(x->j, lr_json_get(x->j, o, "curve"), f, x->e, LR_EPARSE,
                            "unknown curve '%s' (linear, square, s-curve, log, warm-dim)", curve);
    }
    b->curve = (int)cv;
    b->step = 0.02;
    b->accel_rate0 = 5;
    b->accel_max = 10;
    if ((rc = get_num_in(x, o, where, "step", false, 1e-6, 1, &b->step)) ||
        (rc = get_num_in(x, o, where, "fade_s", false, 0, 3600, &b->fade_s)) ||
        (rc = get_bool(x, o, where, "lamp", &b->lamp)))
        return rc;
    if (lr_json_get(x->j, o, "initial") != LR_JNONE) {
        if ((rc = get_num_in(x, o, where, "initial", false, 0, 1, &b->initial)))
            return rc;
        b->has_initial = true;
    }
    lr_jnode acc = lr_json_get(x->j, o, "accel");
    if (acc != LR_JNONE) {
        char w[96];
        snprintf(w, sizeof w, "%s.accel", where);
        static const char *const a_keys[] = {"gain", "rate0", "max", NULL};
        if ((rc = keys(x, acc, w, a_keys)) ||
            (rc = get_num_in(x, acc, w, "gain", false, 0, 100, &b->accel_gain)) ||
            (rc = get_num_in(x, acc, w, "rate0", false, 0.1, 1000, &b->accel_rate0)) ||
            (rc = get_num_in(x, acc, w, "max", false, 1, 1000, &b->accel_max)))
            return rc;
    }
    if (b->lamp && b->is_color) {
        field_name(f, sizeof f, where, "lamp");
        return lr_json_fail(x->j, lr_json_get(x->j, o, "lamp"), f, x->e, LR_EPARSE,
                            "a colour binding cannot drive the lamp driver");
    }
    return LR_OK;
}

static int bindings(ctx *x, lr_jnode arr, const lr_json *owner)
{
    (void)owner;
    if (lr_json_type(x->j, arr) != LR_JSON_ARRAY)
        return lr_json_fail(x->j, arr, "controls", x->e, LR_EPARSE, "expected an array");
    int n = lr_json_count(x->j, arr);
    if (n > LR_RIG_MAX_BINDINGS)
        return lr_json_fail(x->j, arr, "controls", x->e, LR_EPARSE, "at most %d bindings",
                            LR_RIG_MAX_BINDINGS);
    int lamps = 0;
    for (int i = 0; i < n; i++) {
        char where[64];
        snprintf(where, sizeof where, "controls[%d]", i);
        lr_rig_binding *b = &x->c->bindings[i];
        lr_jnode o = lr_json_at(x->j, arr, i);
        int rc = binding(x, o, where, b);
        if (rc)
            return rc;
        x->c->n_bindings = i + 1;
        if (b->lamp && ++lamps > 1)
            return lr_json_fail(x->j, o, where, x->e, LR_EPARSE,
                                "only one binding may drive the lamp driver ('lamp': true)");
        for (int k = 0; k < i; k++) {
            const lr_rig_binding *p = &x->c->bindings[k];
            bool string_param = b->kind == LR_BIND_CYCLE || p->kind == LR_BIND_CYCLE;
            if (string_param && strcmp(p->param, b->param) == 0)
                return lr_json_fail(x->j, o, where, x->e, LR_EPARSE,
                                    "param '%s' is already driven by controls[%d]; a cycle "
                                    "binding must be the only one on its parameter",
                                    b->param, k);
        }
    }
    return LR_OK;
}

/* ---- http ---- */

/* "http": {"listen": "HOST:PORT", "token": "..."}. HOST is a numeric address (an IPv4
 * literal, or an IPv6 literal in brackets): a name would need a resolver at start-up and
 * could change what it means later. */
static int parse_http(ctx *x, lr_jnode root)
{
    lr_jnode h = lr_json_get(x->j, root, "http");
    if (h == LR_JNONE)
        return LR_OK;
    static const char *const ok[] = {"listen", "token", NULL};
    lr_rig_config *c = x->c;
    char listen[96] = "";
    int rc;
    if ((rc = keys(x, h, "http", ok)) ||
        (rc = get_str(x, h, "http", "listen", true, listen, sizeof listen)) ||
        (rc = get_str(x, h, "http", "token", false, c->http.token, sizeof c->http.token)))
        return rc;
    lr_jnode ln = lr_json_get(x->j, h, "listen");
    const char *colon = strrchr(listen, ':');
    const char *host = listen;
    size_t hlen = colon ? (size_t)(colon - listen) : 0;
    if (hlen >= 2 && listen[0] == '[' && listen[hlen - 1] == ']') {
        host++;
        hlen -= 2;
    }
    char *end = NULL;
    long port = colon ? strtol(colon + 1, &end, 10) : 0;
    if (!colon || !hlen || hlen >= sizeof c->http.host || !end || *end || end == colon + 1 ||
        port < 1 || port > 65535)
        return lr_json_fail(x->j, ln, "http.listen", x->e, LR_EPARSE,
                            "expected \"ADDRESS:PORT\" (\"127.0.0.1:8080\", \"[::1]:8080\"), "
                            "got \"%s\"", listen);
    memcpy(c->http.host, host, hlen);
    c->http.host[hlen] = '\0';
    struct in_addr a4;
    struct in6_addr a6;
    if (inet_pton(AF_INET, c->http.host, &a4) == 1)
        c->http.loopback = (ntohl(a4.s_addr) >> 24) == 127;
    else if (inet_pton(AF_INET6, c->http.host, &a6) == 1 && listen[0] == '[')
        c->http.loopback = IN6_IS_ADDR_LOOPBACK(&a6);
    else
        return lr_json_fail(x->j, ln, "http.listen", x->e, LR_EPARSE,
                            "'%s' is not a numeric IPv4 address or [IPv6] address",
                            c->http.host);
    c->http.port = (int)port;
    size_t tl = strlen(c->http.token);
    lr_jnode tn = lr_json_get(x->j, h, "token");
    if (tl && tl < LR_RIG_HTTP_TOKEN_MIN)
        return lr_json_fail(x->j, tn, "http.token", x->e, LR_EPARSE,
                            "at least %d characters, got %zu", LR_RIG_HTTP_TOKEN_MIN, tl);
    for (size_t i = 0; i < tl; i++)
        if (c->http.token[i] <= ' ' || c->http.token[i] > '~')
            return lr_json_fail(x->j, tn, "http.token", x->e, LR_EPARSE,
                                "printable ASCII without spaces (it goes in an HTTP header)");
    if (!c->http.loopback && !tl)
        return lr_json_fail(x->j, h, "http.token", x->e, LR_EPARSE,
                            "required when http.listen (%s) is not a loopback address: "
                            "anyone on the network could change the rig", listen);
    c->http.enabled = true;
    return LR_OK;
}

/* "mqtt" (config.h; firmware/rig/mqtt.h). The rig name becomes a topic level, so it may not
 * hold MQTT's separators or wildcards. */
static int parse_mqtt(ctx *x, lr_jnode root)
{
    lr_rig_mqtt *m = &x->c->mqtt;
    lr_jnode o = lr_json_get(x->j, root, "mqtt");
    *m = (lr_rig_mqtt){.status_period_s = 5, .keepalive_s = 10, .retry_min_ms = 250,
                       .retry_max_ms = 10000, .lead_ms = 250};
    if (o == LR_JNONE)
        return LR_OK;
    static const char *const ok[] = {"broker", "rig", "role", "status_period_s", "keepalive_s",
                                     "retry_min_ms", "retry_max_ms", "lead_ms", NULL};
    char broker[160] = "", role[16] = "follower";
    int rc;
    if ((rc = keys(x, o, "mqtt", ok)) ||
        (rc = get_str(x, o, "mqtt", "broker", true, broker, sizeof broker)) ||
        (rc = get_str(x, o, "mqtt", "rig", true, m->rig, sizeof m->rig)) ||
        (rc = get_str(x, o, "mqtt", "role", false, role, sizeof role)) ||
        (rc = get_num_in(x, o, "mqtt", "status_period_s", false, 0.1, 86400,
                         &m->status_period_s)) ||
        (rc = get_int_in(x, o, "mqtt", "keepalive_s", false, 5, 3600, &m->keepalive_s)) ||
        (rc = get_int_in(x, o, "mqtt", "retry_min_ms", false, 1, 3600000, &m->retry_min_ms)) ||
        (rc = get_int_in(x, o, "mqtt", "retry_max_ms", false, 1, 3600000, &m->retry_max_ms)) ||
        (rc = get_int_in(x, o, "mqtt", "lead_ms", false, 0, 60000, &m->lead_ms)))
        return rc;
    if (strpbrk(m->rig, "/+#"))
        return lr_json_fail(x->j, lr_json_get(x->j, o, "rig"), "mqtt.rig", x->e, LR_EPARSE,
                            "'%s': no '/', '+' or '#' (it is one topic level)", m->rig);
    if (strcmp(role, "follower") == 0)
        m->role = LR_RIG_MQTT_FOLLOWER;
    else if (strcmp(role, "status") == 0)
        m->role = LR_RIG_MQTT_STATUS;
    else if (strcmp(role, "leader") == 0)
        m->role = LR_RIG_MQTT_LEADER;
    else
        return lr_json_fail(x->j, lr_json_get(x->j, o, "role"), "mqtt.role", x->e, LR_EPARSE,
                            "'%s': expected follower, leader or status", role);
    /* HOST:PORT, the port required (an MQTT broker's 1883 is not assumed silently). */
    char *colon = strrchr(broker, ':');
    char *end = NULL;
    long port = colon ? strtol(colon + 1, &end, 10) : 0;
    if (!colon || colon == broker || !colon[1] || *end || port < 1 || port > 65535 ||
        (size_t)(colon - broker) >= sizeof m->host)
        return lr_json_fail(x->j, lr_json_get(x->j, o, "broker"), "mqtt.broker", x->e, LR_EPARSE,
                            "'%s': expected HOST:PORT (port 1..65535)", broker);
    memcpy(m->host, broker, (size_t)(colon - broker));
    m->host[colon - broker] = '\0';
    m->port = (int)port;
    m->line = lr_json_line(x->j, o);
    m->enabled = true;
    return LR_OK;
}

/* ---- top level ---- */

/* "budget": the quality block the rig plans every scene for (config.h). */
static int parse_budget(ctx *x, lr_jnode root)
{
    lr_jnode b = lr_json_get(x->j, root, "budget");
    if (b == LR_JNONE)
        return LR_OK;
    static const char *const ok[] = {"max_error", "frame_ms", "converge_ms", "change_ms", NULL};
    int rc = keys(x, b, "budget", ok);
    if (rc)
        return rc;
    lr_rig_budget *bu = &x->c->budget;
    if ((rc = get_num_in(x, b, "budget", "max_error", false, 0, 1e6, &bu->max_error)) ||
        (rc = get_num_in(x, b, "budget", "frame_ms", false, 0, 1e9, &bu->frame_ms)) ||
        (rc = get_num_in(x, b, "budget", "converge_ms", false, 0, 1e9, &bu->converge_ms)) ||
        (rc = get_num_in(x, b, "budget", "change_ms", false, 0, 1e9, &bu->change_ms)))
        return rc;
    if (!(bu->max_error > 0) && !(bu->frame_ms > 0) && !(bu->converge_ms > 0))
        return lr_json_fail(x->j, b, "budget", x->e, LR_EPARSE,
                            "no budget: give max_error, frame_ms or converge_ms (> 0)");
    bu->given = true;
    bu->line = lr_json_line(x->j, b);
    return LR_OK;
}

static int parse_root(ctx *x)
{
    const lr_json *j = x->j;
    lr_jnode root = lr_json_root(j);
    lr_rig_config *c = x->c;
    static const char *const top[] = {"scene",      "scene_set", "budget", "devices",
                                      "controls",   "output",    "safe_level", "stats",
                                      "calib",      "ar_samples", "http",    "mqtt", NULL};
    int rc = keys(x, root, "", top);
    if (rc)
        return rc;
    char rel[LR_RIG_PATH_MAX];
    if ((rc = get_str(x, root, "", "scene", true, rel, sizeof rel)) ||
        (rc = resolve(x, lr_json_get(j, root, "scene"), "scene", rel, c->scene, sizeof c->scene)))
        return rc;

    if ((rc = parse_budget(x, root)))
        return rc;
    lr_jnode sets = lr_json_get(j, root, "scene_set");
    if (sets != LR_JNONE) {
        if (lr_json_type(j, sets) != LR_JSON_OBJECT)
            return lr_json_fail(j, sets, "scene_set", x->e, LR_EPARSE, "expected an object");
        if (lr_json_count(j, sets) > LR_RIG_MAX_SETS)
            return lr_json_fail(j, sets, "scene_set", x->e, LR_EPARSE, "at most %d parameters",
                                LR_RIG_MAX_SETS);
        for (int i = 0; i < lr_json_count(j, sets); i++) {
            lr_jnode k = lr_json_key_at(j, sets, i), v = lr_json_at(j, sets, i);
            char *key = c->sets[i].key, *val = c->sets[i].value;
            if ((rc = lr_json_string(j, k, "scene_set", key, sizeof c->sets[i].key, x->e)))
                return rc;
            char f[160];
            snprintf(f, sizeof f, "scene_set.%s", key);
            c->sets[i].line = lr_json_line(j, v);
            enum lr_json_type t = lr_json_type(j, v);
            if (t == LR_JSON_NUMBER) {
                double d;
                if ((rc = lr_json_number(j, v, f, &d, x->e)))
                    return rc;
                snprintf(val, sizeof c->sets[i].value, "%.17g", d);
            } else if (t == LR_JSON_STRING) {
                if ((rc = lr_json_string(j, v, f, val, sizeof c->sets[i].value, x->e)))
                    return rc;
            } else if (t == LR_JSON_BOOL) {
                bool b;
                lr_json_bool(j, v, f, &b, NULL);
                snprintf(val, sizeof c->sets[i].value, "%s", b ? "true" : "false");
            } else if (t == LR_JSON_ARRAY && lr_json_count(j, v) == 3) {
                double d[3];
                if ((rc = lr_json_numbers(j, v, f, d, 3, x->e)))
                    return rc;
                snprintf(val, sizeof c->sets[i].value, "%.17g,%.17g,%.17g", d[0], d[1], d[2]);
            } else {
                return lr_json_fail(j, v, f, x->e, LR_EPARSE,
                                    "expected a number, a string, a boolean or [x, y, z]");
            }
            c->n_sets = i + 1;
        }
    }

    lr_jnode devs = lr_json_get(j, root, "devices");
    if (devs != LR_JNONE) {
        if (lr_json_type(j, devs) != LR_JSON_ARRAY)
            return lr_json_fail(j, devs, "devices", x->e, LR_EPARSE, "expected an array");
        if (lr_json_count(j, devs) > LR_RIG_MAX_DEVICES)
            return lr_json_fail(j, devs, "devices", x->e, LR_EPARSE, "at most %d devices",
                                LR_RIG_MAX_DEVICES);
        for (int i = 0; i < lr_json_count(j, devs); i++) {
            lr_jnode o = lr_json_at(j, devs, i);
            if ((rc = device(x, o, i, &c->devices[i])))
                return rc;
            c->n_devices = i + 1;
            for (int k = 0; k < i; k++)
                if (strcmp(c->devices[k].name, c->devices[i].name) == 0) {
                    char f[64];
                    snprintf(f, sizeof f, "devices[%d].name", i);
                    return lr_json_fail(j, o, f, x->e, LR_EPARSE,
                                        "device name '%s' is already used by devices[%d]",
                                        c->devices[i].name, k);
                }
        }
    }

    lr_jnode ctl = lr_json_get(j, root, "controls");
    if (ctl != LR_JNONE && lr_json_type(j, ctl) == LR_JSON_STRING) {
        char rel2[LR_RIG_PATH_MAX], path[LR_RIG_PATH_MAX];
        if ((rc = get_str(x, root, "", "controls", true, rel2, sizeof rel2)) ||
            (rc = resolve(x, ctl, "controls", rel2, path, sizeof path)))
            return rc;
        lr_json *cj;
        if ((rc = lr_json_load(path, &cj, x->e)))
            return rc;
        ctx y = *x;
        y.j = cj;
        /* Paths inside a control-map file resolve against that file. */
        char *sl = strrchr(path, '/');
        if (sl) {
            *sl = '\0';
            snprintf(y.dir, sizeof y.dir, "%s", path);
        } else {
            y.dir[0] = '\0';
        }
        static const char *const ck[] = {"controls", NULL};
        lr_jnode croot = lr_json_root(cj);
        rc = keys(&y, croot, "", ck);
        if (!rc) {
            lr_jnode arr = lr_json_get(cj, croot, "controls");
            rc = arr == LR_JNONE ? missing(&y, croot, "", "controls") : bindings(&y, arr, cj);
        }
        lr_json_destroy(cj);
        if (rc)
            return rc;
    } else if (ctl != LR_JNONE) {
        if ((rc = bindings(x, ctl, j)))
            return rc;
    }

    c->output.width = 640;
    c->output.height = 480;
    c->output.fps = 30;
    /* A quarter of a 4 GB board, whose GPU shares the RAM: the shipped rigs need 10-60 MB. */
    c->output.gpu_memory_mb = 1024;
    /* Converged images of the controls' next states (render/async/cache.h): a 640x480 state of
     * one light is 4.7 MB, so 256 MB holds every preset and sample of the shipped maps with
     * room, a sixteenth of a 4 GB board. */
    c->output.cache_mb = 256;
    c->output.cache_samples = 9;
    /* A quarter of the 30 fps frame interval: a change's first image (the cut, the preview,
     * the next frame) within two intervals. */
    c->output.slice_ms = 8;
    lr_jnode out = lr_json_get(j, root, "output");
    if (out != LR_JNONE) {
        static const char *const ok[] = {"mode", "connector", "drm_device", "mode_size",
                                         "refresh_hz", "width", "height", "fps", "renderer",
                                         "gpu_memory_mb", "cache_mb", "cache_samples", "slice_ms",
                                         NULL};
        /* "mode" is headless|kms; the display mode size is "mode_size": [W, H]. */
        if ((rc = keys(x, out, "output", ok)))
            return rc;
        char mode[16] = "headless";
        if ((rc = get_str(x, out, "output", "mode", false, mode, sizeof mode)))
            return rc;
        if (strcmp(mode, "headless") == 0)
            c->output.mode = LR_RIG_HEADLESS;
        else if (strcmp(mode, "kms") == 0)
            c->output.mode = LR_RIG_KMS;
        else
            return lr_json_fail(j, lr_json_get(j, out, "mode"), "output.mode", x->e, LR_EPARSE,
                                "'%s' is not headless or kms", mode);
        lr_jnode ms = lr_json_get(j, out, "mode_size");
        if (ms != LR_JNONE) {
            double wh[2];
            if ((rc = lr_json_numbers(j, ms, "output.mode_size", wh, 2, x->e)))
                return rc;
            if (wh[0] < 1 || wh[1] < 1 || wh[0] > 16384 || wh[1] > 16384 ||
                wh[0] != floor(wh[0]) || wh[1] != floor(wh[1]))
                return lr_json_fail(j, ms, "output.mode_size", x->e, LR_EPARSE,
                                    "expected [W, H] in pixels (1..16384)");
            c->output.mode_w = (int)wh[0];
            c->output.mode_h = (int)wh[1];
        }
        if ((rc = get_str(x, out, "output", "connector", false, c->output.connector,
                          sizeof c->output.connector)) ||
            (rc = get_str(x, out, "output", "drm_device", false, c->output.drm_device,
                          sizeof c->output.drm_device)) ||
            (rc = get_int_in(x, out, "output", "refresh_hz", false, 0, 1000,
                             &c->output.refresh_hz)) ||
            (rc = get_int_in(x, out, "output", "width", false, 16, 8192, &c->output.width)) ||
            (rc = get_int_in(x, out, "output", "height", false, 16, 8192, &c->output.height)) ||
            (rc = get_num_in(x, out, "output", "fps", false, 0.1, 1000, &c->output.fps)) ||
            (rc = get_num_in(x, out, "output", "gpu_memory_mb", false, 0, 1048576,
                             &c->output.gpu_memory_mb)) ||
            (rc = get_num_in(x, out, "output", "cache_mb", false, 0, 1048576,
                             &c->output.cache_mb)) ||
            (rc = get_int_in(x, out, "output", "cache_samples", false, 2, 48,
                             &c->output.cache_samples)) ||
            (rc = get_num_in(x, out, "output", "slice_ms", false, 0, 1000,
                             &c->output.slice_ms)) ||
            (rc = get_str(x, out, "output", "renderer", false, c->output.renderer,
                          sizeof c->output.renderer)))
            return rc;
    }
    if ((rc = get_num_in(x, root, "", "safe_level", false, 0, 1, &c->safe_level)))
        return rc;
    lr_jnode cal = lr_json_get(j, root, "calib");
    if (cal != LR_JNONE) {
        char p[LR_RIG_PATH_MAX] = "";
        if ((rc = get_str(x, root, "", "calib", true, p, sizeof p)))
            return rc;
        int w = p[0] == '/' || !x->dir[0]
                    ? snprintf(c->calib, sizeof c->calib, "%s", p)
                    : snprintf(c->calib, sizeof c->calib, "%s/%s", x->dir, p);
        if (w < 0 || (size_t)w >= sizeof c->calib)
            return lr_json_fail(j, cal, "calib", x->e, LR_EPARSE, "path too long");
        struct stat cst;
        if (stat(c->calib, &cst) != 0 || !S_ISDIR(cst.st_mode))
            return lr_json_fail(j, cal, "calib", x->e, LR_EPARSE,
                                "'%s' is not a calibration folder", c->calib);
    }
    c->ar_samples = 16;
    if ((rc = get_int_in(x, root, "", "ar_samples", false, 1, 1 << 20, &c->ar_samples)))
        return rc;
    c->stats_period_s = 10;
    lr_jnode st = lr_json_get(j, root, "stats");
    if (st != LR_JNONE) {
        static const char *const ok[] = {"path", "period_s", NULL};
        if ((rc = keys(x, st, "stats", ok)) ||
            (rc = get_num_in(x, st, "stats", "period_s", false, 0, 86400, &c->stats_period_s)))
            return rc;
        char p[LR_RIG_PATH_MAX] = "";
        if ((rc = get_str(x, st, "stats", "path", false, p, sizeof p)))
            return rc;
        if (*p) {
            if (p[0] == '/' || !x->dir[0])
                snprintf(c->stats_path, sizeof c->stats_path, "%s", p);
            else if (snprintf(c->stats_path, sizeof c->stats_path, "%s/%s", x->dir, p) >=
                     (int)sizeof c->stats_path)
                return lr_json_fail(j, st, "stats.path", x->e, LR_EPARSE, "path too long");
        }
    }
    if ((rc = parse_http(x, root)) || (rc = parse_mqtt(x, root)))
        return rc;
    /* Bindings name devices by source: a source that no device has (and no sim script could
     * speak for, i.e. there is no sim device) is a typo. */
    bool have_sim = false;
    for (int i = 0; i < c->n_devices; i++)
        have_sim |= c->devices[i].type == LR_RIG_DEV_SIM;
    for (int i = 0; i < c->n_bindings && !have_sim; i++) {
        const lr_rig_binding *b = &c->bindings[i];
        if (!b->source[0])
            continue;
        bool found = false;
        for (int k = 0; k < c->n_devices && !found; k++) {
            found = strcmp(c->devices[k].name, b->source) == 0;
            for (int w = 0; w < c->devices[k].n_watch && !found; w++)
                found = strcmp(c->devices[k].watch[w].name, b->source) == 0;
        }
        if (!found) {
            char f[64];
            snprintf(f, sizeof f, "controls[%d].control", i);
            return lr_err_set(x->e, LR_EPARSE, "%s:%d: field '%s': no device named '%s'",
                              b->file, b->line, f, b->source);
        }
    }
    return LR_OK;
}

static int parse_json(lr_json *j, const char *name, lr_rig_config **out, lr_err *e)
{
    lr_rig_config *c = calloc(1, sizeof *c);
    if (!c)
        return lr_err_set(e, LR_ENOMEM, "out of memory");
    ctx x = {.j = j, .c = c, .e = e};
    snprintf(c->path, sizeof c->path, "%s", name);
    const char *sl = strrchr(name, '/');
    if (sl)
        snprintf(x.dir, sizeof x.dir, "%.*s", (int)(sl - name), name);
    int rc = parse_root(&x);
    if (rc) {
        lr_rig_config_destroy(c);
        return rc;
    }
    *out = c;
    return LR_OK;
}

int lr_rig_config_load(const char *path, lr_rig_config **out, lr_err *e)
{
    lr_json *j;
    int rc = lr_json_load(path, &j, e);
    if (rc)
        return rc;
    rc = parse_json(j, path, out, e);
    lr_json_destroy(j);
    return rc;
}

int lr_rig_config_parse(const char *text, const char *name, lr_rig_config **out, lr_err *e)
{
    lr_json *j;
    int rc = lr_json_parse(text, strlen(text), name, &j, e);
    if (rc)
        return rc;
    rc = parse_json(j, name, out, e);
    lr_json_destroy(j);
    return rc;
}

void lr_rig_config_destroy(lr_rig_config *c)
{
    if (!c)
        return;
    for (int i = 0; i < LR_RIG_MAX_DEVICES; i++)
        free(c->devices[i].text);
    free(c);
}

int lr_rig_config_apply_sets(const lr_rig_config *c, lr_scene *scene, lr_err *e)
{
    /* The budget replaces the scene's max_error, frame_ms and converge_ms together (one kind
     * of budget, as `lamprig plan --max-error` does), change_ms only when given. */
    if (c->budget.given) {
        const struct {
            const char *key;
            double v;
            bool always;
        } q[] = {{"quality.max_error", c->budget.max_error, true},
                 {"quality.frame_ms", c->budget.frame_ms, true},
                 {"quality.converge_ms", c->budget.converge_ms, true},
                 {"quality.change_ms", c->budget.change_ms, false}};
        for (size_t i = 0; i < sizeof q / sizeof q[0]; i++) {
            if (!q[i].always && !(q[i].v > 0))
                continue;
            char v[64];
            lr_err le = {0};
            snprintf(v, sizeof v, "%.17g", q[i].v);
            if (lr_scene_set(scene, q[i].key, v, NULL, &le))
                return lr_err_set(e, LR_EPARSE, "%s:%d: field 'budget': %s", c->path,
                                  c->budget.line, le.msg);
        }
    }
    for (int i = 0; i < c->n_sets; i++) {
        lr_err le = {0};
        if (lr_scene_set(scene, c->sets[i].key, c->sets[i].value, NULL, &le))
            return lr_err_set(e, LR_EPARSE, "%s:%d: field 'scene_set.%s': %s", c->path,
                              c->sets[i].line, c->sets[i].key, le.msg);
    }
    return LR_OK;
}

int lr_rig_config_lamp_device(const lr_rig_config *c)
{
    for (int i = 0; i < c->n_devices; i++)
        if (c->devices[i].type == LR_RIG_DEV_MODBUS && c->devices[i].has_lamp)
            return i;
    return -1;
}

const char *lr_rig_dev_type_name(lr_rig_dev_type t)
{
    static const char *const names[] = {"sim", "modbus", "gpio", "hid", "usb",
                                        "sacn", "artnet", "osc"};
    return (unsigned)t < 8 ? names[t] : "?";
}
