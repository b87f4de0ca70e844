/* OSC input: see hal/osc.h. */
#include "hal/osc.h"

#include <ctype.h>
#include <lo/lo.h>
#include <math.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hal/dev_impl.h"

const lr_opt lr_osc_opts[] = {
    [LR_OSC_OPT_PORT] = {"port", LR_OPT_INT, 1, 65535, 9000, .help = "UDP port"},
    [LR_OSC_OPT_PREFIX] = {"prefix", LR_OPT_STRING, .dflt_text = "/lamprig",
                           .help = "address prefix"},
    [LR_OSC_OPT_SCENES] = {"scenes", LR_OPT_LIST,
                           .help = "scene names for PREFIX/scene s, in the scene binding's order"},
    [LR_OSC_OPT_SCENE_CONTROL] = {"scene_control", LR_OPT_STRING, .dflt_text = "scene",
                                  .help = "control of PREFIX/scene events"},
    [LR_OSC_OPT_MAX_PACKETS] = {"max_packets", LR_OPT_INT, 1, 4096, 64,
                                .help = "messages read per loop turn"},
    LR_OPT_END,
};

struct lr_osc {
    lr_dev base;
    char prefix[64];
    char scene_control[LR_EVENT_NAME_MAX];
    char scenes[LR_OSC_MAX_SCENES][LR_EVENT_NAME_MAX];
    int n_scenes;
    int port, max_packets;
    lo_server srv;
    bool handled; /* a method of ours ran for the message just read */
    bool more;
    int64_t now;  /* of the dispatch in progress: the events' time */
    bool logged[LR_OSC_N_BAD];
    lr_osc_counters c;
};

const char *lr_osc_bad_name(lr_osc_bad k)
{
    static const char *const n[LR_OSC_N_BAD] = {"unknown address", "wrong argument types",
                                                "bad value", "unknown scene", "unparsable"};
    return (unsigned)k < LR_OSC_N_BAD ? n[k] : "?";
}

static void bad(lr_osc *o, lr_osc_bad k, const char *path)
{
    o->c.bad++;
    o->c.bad_kind[k]++;
    if (o->logged[k])
        return;
    o->logged[k] = true;
    lr_dev_log(&o->base, LR_LOG_WARN, "%s%s%s: dropped; later ones of this kind are only counted",
               lr_osc_bad_name(k), path ? ": " : "", path ? path : "");
}

static bool number(const char *types, lo_arg **argv, int argc, double *v)
{
    if (argc != 1)
        return false;
    switch (types[0]) {
    case LO_FLOAT: *v = argv[0]->f; return true;
    case LO_DOUBLE: *v = argv[0]->d; return true;
    case LO_INT32: *v = argv[0]->i; return true;
    case LO_INT64: *v = (double)argv[0]->h; return true;
    default: return false;
    }
}

static void emit(lr_osc *o, const char *control, double v)
{
    lr_dev_emit(&o->base, NULL, control, LR_EV_ABSOLUTE, v, o->now);
    o->c.events++;
}

static bool valid_name(const char *s)
{
    size_t n = strlen(s);
    if (n == 0 || n >= LR_EVENT_NAME_MAX)
        return false;
    for (size_t i = 0; i < n; i++)
        if (!isalnum((unsigned char)s[i]) && s[i] != '_' && s[i] != '.' && s[i] != '-')
            return false;
    return true;
}

/* Every message comes here (one catch-all method): the address is matched by hand, since
 * liblo's patterns cannot say "PREFIX/control/ANY". */
static int on_message(const char *path, const char *types, lo_arg **argv, int argc,
                      lo_message msg, void *user)
{
    (void)msg;
    lr_osc *o = user;
    o->handled = true;
    size_t pl = strlen(o->prefix);
    if (!path || strncmp(path, o->prefix, pl) != 0 || path[pl] != '/') {
        bad(o, LR_OSC_BAD_ADDRESS, path);
        return 0;
    }
    const char *rest = path + pl + 1;
    double v;
    if (strcmp(rest, "dimmer") == 0 || strncmp(rest, "control/", 8) == 0) {
        const char *control = rest[0] == 'd' ? "dimmer" : rest + 8;
        if (!number(types, argv, argc, &v)) {
            bad(o, LR_OSC_BAD_TYPES, path);
        } else if (!isfinite(v) || !valid_name(control)) {
            bad(o, LR_OSC_BAD_VALUE, path);
        } else {
            emit(o, control, v);
        }
        return 0;
    }
    if (strcmp(rest, "scene") == 0) {
        int k = -1;
        if (argc == 1 && types[0] == LO_STRING) {
            for (int i = 0; i < o->n_scenes; i++)
                if (strcmp(o->scenes[i], &argv[0]->s) == 0)
                    k = i;
        } else if (argc == 1 && types[0] == LO_INT32) {
            k = argv[0]->i >= 0 && argv[0]->i < o->n_scenes ? argv[0]->i : -1;
        } else {
            bad(o, LR_OSC_BAD_TYPES, path);
            return 0;
        }
        if (k < 0)
            bad(o, LR_OSC_BAD_SCENE, path);
        else
            emit(o, o->scene_control, (k + 0.5) / o->n_scenes);
        return 0;
    }
    bad(o, LR_OSC_BAD_ADDRESS, path);
    return 0;
}

static void osc_close(lr_dev *d)
{
    lr_osc *o = (lr_osc *)d;
    if (o->srv)
        lo_server_free(o->srv);
    o->srv = NULL;
}

static int osc_open(lr_dev *d, int64_t now_ns, lr_err *e)
{
    (void)now_ns;
    lr_osc *o = (lr_osc *)d;
    char port[16];
    snprintf(port, sizeof port, "%d", o->port);
    /* No error handler: liblo's has no user pointer (it would need global state); a message
     * liblo drops is seen as a read that reached none of our methods. */
    o->srv = lo_server_new_with_proto(port, LO_UDP, NULL);
    if (!o->srv)
        return lr_err_set(e, LR_EIO, "cannot open UDP port %d (in use?)", o->port);
    lo_server_enable_queue(o->srv, 0, 1);
    lo_server_add_method(o->srv, NULL, NULL, on_message, o);
    return LR_OK;
}

static int osc_pollfds(lr_dev *d, struct pollfd *fds, int max)
{
    lr_osc *o = (lr_osc *)d;
    if (max > 0)
        fds[0] = (struct pollfd){.fd = lo_server_get_socket_fd(o->srv), .events = POLLIN};
    return 1;
}

static void osc_dispatch(lr_dev *d, int64_t now_ns)
{
    lr_osc *o = (lr_osc *)d;
    o->more = false;
    o->now = now_ns;
    for (int i = 0; i < o->max_packets; i++) {
        /* liblo returns 0 both for "nothing there" and for a datagram it read and could not
         * parse: asking the socket first tells the two apart. */
        struct pollfd p = {.fd = lo_server_get_socket_fd(o->srv), .events = POLLIN};
        if (poll(&p, 1, 0) != 1)
            return;
        o->handled = false;
        lo_server_recv_noblock(o->srv, 0);
        o->c.messages++;
        if (!o->handled)
            bad(o, LR_OSC_BAD_PACKET, NULL);
        if (i == o->max_packets - 1)
            o->more = true;
    }
}

static int64_t osc_next_deadline(lr_dev *d)
{
    lr_osc *o = (lr_osc *)d;
    return o->more ? 0 : LR_NO_DEADLINE;
}

static void osc_destroy(lr_dev *d) { free(d); }

static const lr_dev_ops OSC_OPS = {
    .kind = "osc",
    .open = osc_open,
    .close = osc_close,
    .pollfds = osc_pollfds,
    .dispatch = osc_dispatch,
    .next_deadline = osc_next_deadline,
    .destroy = osc_destroy,
};

static int configure(lr_osc *o, const lr_osc_desc *desc, lr_err *e)
{
    const lr_opt *op = lr_osc_opts;
    const char *pf = o->base.prefix;
    if (!lr_opt_hal_ok(&op[LR_OSC_OPT_PORT], desc->port) ||
        !lr_opt_hal_ok(&op[LR_OSC_OPT_MAX_PACKETS], desc->max_packets))
        return lr_err_set(e, LR_EINVAL, "%s: port %d / max_packets %d out of range", pf,
                          desc->port, desc->max_packets);
    o->port = (int)lr_opt_or_default(&op[LR_OSC_OPT_PORT], desc->port);
    o->max_packets = (int)lr_opt_or_default(&op[LR_OSC_OPT_MAX_PACKETS], desc->max_packets);
    const char *p = desc->prefix ? desc->prefix : op[LR_OSC_OPT_PREFIX].dflt_text;
    size_t pl = strlen(p);
    if (pl < 2 || pl >= sizeof o->prefix || p[0] != '/' || p[pl - 1] == '/')
        return lr_err_set(e, LR_EINVAL, "%s: prefix '%s' is not /NAME[/NAME...] (at most %zu "
                          "characters, no trailing '/')", pf, p, sizeof o->prefix - 1);
    memcpy(o->prefix, p, pl + 1);
    const char *sc = desc->scene_control ? desc->scene_control
                                         : op[LR_OSC_OPT_SCENE_CONTROL].dflt_text;
    if (!valid_name(sc))
        return lr_err_set(e, LR_EINVAL, "%s: scene_control '%s' is not a name", pf, sc);
    snprintf(o->scene_control, sizeof o->scene_control, "%s", sc);
    if (desc->n_scenes < 0 || desc->n_scenes > LR_OSC_MAX_SCENES ||
        (desc->n_scenes && !desc->scenes))
        return lr_err_set(e, LR_EINVAL, "%s: %d scenes (0..%d)", pf, desc->n_scenes,
                          LR_OSC_MAX_SCENES);
    for (int i = 0; i < desc->n_scenes; i++) {
        if (!desc->scenes[i] || !valid_name(desc->scenes[i]))
            return lr_err_set(e, LR_EINVAL, "%s: scenes[%d] is not a name (1..31 of A-Z a-z "
                              "0-9 _ . -)", pf, i);
        snprintf(o->scenes[i], sizeof o->scenes[i], "%s", desc->scenes[i]);
    }
    o->n_scenes = desc->n_scenes;
    snprintf(o->base.ident, sizeof o->base.ident, "udp port %d, %s/...", o->port, o->prefix);
    return LR_OK;
}

int lr_osc_create(const lr_osc_desc *desc, lr_osc **out, lr_err *e)
{
    *out = NULL;
    lr_osc *o = calloc(1, sizeof *o);
    if (!o)
        return lr_err_set(e, LR_ENOMEM, "osc: out of memory");
    int rc = lr_dev_init(&o->base, &OSC_OPS, &desc->dev, e);
    if (rc == LR_OK)
        rc = configure(o, desc, e);
    if (rc == LR_OK)
        rc = lr_dev_start(&o->base, desc->dev.required, lr_now_ns(), e);
    if (rc != LR_OK) {
        osc_close(&o->base);
        free(o);
        return rc;
    }
    *out = o;
    return LR_OK;
}

void lr_osc_destroy(lr_osc *o)
{
    if (o)
        lr_dev_destroy(&o->base);
}

lr_dev *lr_osc_dev(lr_osc *o) { return &o->base; }
void lr_osc_get_counters(const lr_osc *o, lr_osc_counters *out) { *out = o->c; }
