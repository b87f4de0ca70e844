#include "hal/usb.h"

#include <libusb.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hal/dev_impl.h"

#define QMAX 64
#define MS 1000000LL

const lr_opt lr_usb_opts[] = {
    [LR_USB_OPT_WATCH] = {"watch", LR_OPT_LIST, .required = true,
                          .help = "devices to watch (below), 1..16"},
    [LR_USB_OPT_RESCAN_MS] = {"rescan_ms", LR_OPT_INT, 1, 600000, 1000,
                              .help = "re-enumeration period without hotplug"},
    [LR_USB_OPT_NO_HOTPLUG] = {"no_hotplug", LR_OPT_BOOL, .dflt = 0,
                               .help = "re-enumerate even when libusb offers hotplug"},
    LR_OPT_END,
};

const lr_opt lr_usb_watch_opts[] = {
    [LR_USB_W_NAME] = {"name", LR_OPT_STRING, .required = true, .help = "event source name"},
    [LR_USB_W_VID] = {"vid", LR_OPT_HEX16, .required = true, .help = "USB vendor id"},
    [LR_USB_W_PID] = {"pid", LR_OPT_HEX16, .required = true, .help = "USB product id"},
    [LR_USB_W_READ_REPORTS] = {"read_reports", LR_OPT_BOOL, .dflt = 0,
                               .help = "open it and parse its interrupt IN reports"},
    [LR_USB_W_INTERFACE] = {"interface", LR_OPT_INT, 0, 255, 0,
                            .help = "interface to claim for read_reports"},
    [LR_USB_W_PROTO] = {"proto", LR_OPT_ENUM, .dflt = LR_HID_AUTO, .names = lr_hid_proto_names,
                        .help = "report parser; auto: by VID:PID"},
    LR_OPT_END,
};

struct lr_usb;

typedef struct watch {
    struct lr_usb *u;
    char name[LR_EVENT_NAME_MAX];
    char ident[LR_EVENT_NAME_MAX + 32]; /* "powermate (077d:0410)" */
    uint16_t vid, pid;
    bool read;
    int iface;
    lr_hid_parser_desc pdesc;
    lr_hid_parser parser;
    libusb_device *dev; /* referenced while present */
    libusb_device_handle *h;
    struct libusb_transfer *tr;
    uint8_t buf[64];
    bool claimed;
    bool transfer_active;
    bool broken;        /* the transfer failed: close the reader and retry */
    bool garbage_logged;
    lr_backoff bo;
    int64_t retry_at;
    char status[LR_DEV_LINE_MAX];
} watch;

typedef struct news {
    libusb_device *dev; /* referenced */
    bool arrived;
} news;

struct lr_usb {
    lr_dev base;
    libusb_context *ctx;
    bool want_hotplug;
    bool hotplug;
    libusb_hotplug_callback_handle cb[LR_USB_MAX_WATCH];
    int n_cb;
    int64_t rescan_ns, next_rescan;
    bool starting, required;
    watch w[LR_USB_MAX_WATCH];
    int n;
    news q[QMAX];
    int nq;
    bool q_overflow;
};

static void watch_status(watch *w, lr_log_level level, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void watch_status(watch *w, lr_log_level level, const char *fmt, ...)
{
    char msg[LR_ERR_MSG_MAX], line[LR_DEV_LINE_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    snprintf(line, sizeof line, "%s: %s: %s", w->u->base.prefix, w->ident, msg);
    if (strcmp(line, w->status) == 0)
        return; /* once per change */
    snprintf(w->status, sizeof w->status, "%s", line);
    lr_log_write(&w->u->base.log, level, "%s", line);
}

static void LIBUSB_CALL on_transfer(struct libusb_transfer *tr)
{
    watch *w = tr->user_data;
    w->transfer_active = false;
    if (tr->status == LIBUSB_TRANSFER_CANCELLED)
        return;
    if (tr->status == LIBUSB_TRANSFER_NO_DEVICE) {
        w->broken = true; /* the removal itself is reported by hotplug or the rescan */
        return;
    }
    if (tr->status == LIBUSB_TRANSFER_COMPLETED) {
        lr_event ev[LR_HID_MAX_EVENTS];
        int nev = 0;
        lr_err pe = {0};
        int64_t now = lr_now_ns();
        if (lr_hid_parse(&w->parser, tr->buffer, (size_t)tr->actual_length, ev, &nev, &pe) ==
            LR_OK) {
            w->garbage_logged = false;
            for (int k = 0; k < nev; k++)
                lr_dev_emit(&w->u->base, w->name, ev[k].control, ev[k].kind, ev[k].value, now);
        } else if (!w->garbage_logged) {
            w->garbage_logged = true;
            lr_dev_log(&w->u->base, LR_LOG_WARN, "%s: garbage report ignored: %s", w->ident,
                       pe.msg);
        }
        if (libusb_submit_transfer(tr) == 0) {
            w->transfer_active = true;
            return;
        }
    }
    /* Stall, overflow, error, or resubmit refused: reopen from scratch after a backoff. */
    w->broken = true;
}

static void close_reader(watch *w)
{
    lr_usb *u = w->u;
    if (w->tr && w->transfer_active && libusb_cancel_transfer(w->tr) == 0) {
        /* The cancelled callback must run before the transfer is freed; cancellation of an
         * interrupt URB completes at once, the bound only guards against a wedged host. */
        for (int i = 0; i < 20 && w->transfer_active; i++) {
            struct timeval tv = {0, 50000};
            libusb_handle_events_timeout_completed(u->ctx, &tv, NULL);
        }
    }
    if (w->tr && !w->transfer_active) {
        libusb_free_transfer(w->tr);
        w->tr = NULL;
    }
    if (w->h) {
        if (w->claimed)
            libusb_release_interface(w->h, w->iface);
        libusb_close(w->h);
    }
    w->h = NULL;
    w->claimed = false;
    w->broken = false;
}

static int find_in_endpoint(watch *w, uint8_t *ep, int *maxp)
{
    struct libusb_config_descriptor *cfg;
    int rc = libusb_get_active_config_descriptor(w->dev, &cfg);
    if (rc != 0)
        return rc;
    rc = LIBUSB_ERROR_NOT_FOUND;
    for (int i = 0; i < cfg->bNumInterfaces && rc != 0; i++) {
        if (cfg->interface[i].num_altsetting < 1)
            continue;
        const struct libusb_interface_descriptor *id = &cfg->interface[i].altsetting[0];
        if (id->bInterfaceNumber != w->iface)
            continue;
        for (int k = 0; k < id->bNumEndpoints; k++) {
            const struct libusb_endpoint_descriptor *ed = &id->endpoint[k];
            if ((ed->bEndpointAddress & LIBUSB_ENDPOINT_IN) &&
                (ed->bmAttributes & 3) == LIBUSB_TRANSFER_TYPE_INTERRUPT) {
                *ep = ed->bEndpointAddress;
                *maxp = ed->wMaxPacketSize & 0x7ff;
                rc = 0;
                break;
            }
        }
    }
    libusb_free_config_descriptor(cfg);
    return rc;
}

static void open_reader(watch *w, int64_t now_ns)
{
    const char *what = "open";
    if (w->tr && !w->transfer_active) {
        libusb_free_transfer(w->tr); /* its late cancellation has completed meanwhile */
        w->tr = NULL;
    }
    int rc = libusb_open(w->dev, &w->h);
    if (rc == 0) {
        what = "claim interface";
        libusb_set_auto_detach_kernel_driver(w->h, 1); /* not supported everywhere: optional */
        rc = libusb_claim_interface(w->h, w->iface);
        w->claimed = rc == 0;
    }
    uint8_t ep = 0;
    int maxp = 0;
    if (rc == 0) {
        what = "find an interrupt IN endpoint on the interface";
        rc = find_in_endpoint(w, &ep, &maxp);
    }
    if (rc == 0 && w->tr) {
        /* A transfer whose cancellation never completed is still owned by libusb. */
        what = "start reading (the previous transfer is still pending)";
        rc = LIBUSB_ERROR_BUSY;
    } else if (rc == 0) {
        what = "start reading";
        if (maxp <= 0 || maxp > (int)sizeof w->buf)
            maxp = (int)sizeof w->buf;
        w->tr = libusb_alloc_transfer(0);
        if (!w->tr) {
            rc = LIBUSB_ERROR_NO_MEM;
        } else {
            libusb_fill_interrupt_transfer(w->tr, w->h, ep, w->buf, maxp, on_transfer, w, 0);
            rc = libusb_submit_transfer(w->tr);
            w->transfer_active = rc == 0;
        }
    }
    if (rc != 0) {
        close_reader(w);
        w->retry_at = lr_backoff_fail(&w->bo, now_ns);
        watch_status(w, LR_LOG_WARN, "present but cannot %s (interface %d): %s%s; retrying with "
                     "backoff", what, w->iface, libusb_strerror(rc),
                     rc == LIBUSB_ERROR_ACCESS ? " (a udev rule must give the rig's user access)"
                                               : "");
        return;
    }
    /* Fresh state: no stale jog counter or buttons from before an unplug. */
    w->parser.have_prev = 0;
    w->parser.buttons = 0;
    w->parser.n_cc = 0;
    w->parser.shuttle = 0;
    lr_backoff_reset(&w->bo);
    w->retry_at = LR_NO_DEADLINE;
    watch_status(w, LR_LOG_INFO, "present, reading reports (%s) from endpoint 0x%02x",
                 lr_hid_proto_name(w->pdesc.proto), ep);
}

static void arrived(watch *w, libusb_device *dev, int64_t now_ns)
{
    w->dev = libusb_ref_device(dev);
    lr_dev_emit(&w->u->base, w->name, "present", LR_EV_ABSOLUTE, 1, now_ns);
    watch_status(w, LR_LOG_INFO, "arrived (bus %d, address %d)", libusb_get_bus_number(dev),
                 libusb_get_device_address(dev));
    if (w->read) {
        lr_backoff_reset(&w->bo);
        open_reader(w, now_ns);
    }
}

static void left(watch *w, int64_t now_ns)
{
    close_reader(w);
    libusb_unref_device(w->dev);
    w->dev = NULL;
    w->retry_at = LR_NO_DEADLINE;
    lr_dev_emit(&w->u->base, w->name, "present", LR_EV_ABSOLUTE, 0, now_ns);
    watch_status(w, LR_LOG_WARN, "removed; waiting for it to be plugged in again");
}

static bool matches(const watch *w, libusb_device *dev)
{
    struct libusb_device_descriptor dd;
    return libusb_get_device_descriptor(dev, &dd) == 0 && dd.idVendor == w->vid &&
           dd.idProduct == w->pid;
}

static int LIBUSB_CALL on_hotplug(libusb_context *ctx, libusb_device *dev,
                                  libusb_hotplug_event event, void *user)
{
    (void)ctx;
    lr_usb *u = user;
    /* Only queue: the callback runs inside libusb's event handling, where opening devices and
     * synchronous calls are not allowed. */
    if (u->nq < QMAX) {
        u->q[u->nq].dev = libusb_ref_device(dev);
        u->q[u->nq].arrived = event == LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED;
        u->nq++;
    } else {
        u->q_overflow = true; /* fall back to one full re-enumeration */
    }
    return 0;
}

static void process_news(lr_usb *u, int64_t now_ns)
{
    for (int i = 0; i < u->nq; i++) {
        news *nw = &u->q[i];
        /* Watches with the same VID:PID each registered a callback: one arrival, one owner. */
        bool taken = false;
        for (int k = 0; k < u->n; k++)
            taken |= nw->arrived && u->w[k].dev == nw->dev;
        for (int k = 0; k < u->n && !taken; k++) {
            watch *w = &u->w[k];
            if (nw->arrived && !w->dev && matches(w, nw->dev)) {
                arrived(w, nw->dev, now_ns);
                break;
            }
            if (!nw->arrived && w->dev == nw->dev) {
                left(w, now_ns);
                break;
            }
        }
        libusb_unref_device(nw->dev);
    }
    u->nq = 0;
}

static int rescan(lr_usb *u, int64_t now_ns)
{
    libusb_device **list;
    ssize_t n = libusb_get_device_list(u->ctx, &list);
    if (n < 0)
        return (int)n;
    for (int k = 0; k < u->n; k++) {
        watch *w = &u->w[k];
        libusb_device *found = NULL;
        for (ssize_t i = 0; i < n; i++) {
            if (w->dev && list[i] == w->dev) {
                found = w->dev;
                break;
            }
            if (!found && matches(w, list[i]))
                found = list[i];
        }
        if (w->dev && found != w->dev)
            left(w, now_ns);
        if (!w->dev && found) {
            /* Not claimed by an earlier watch for the same VID:PID? */
            bool taken = false;
            for (int j = 0; j < u->n; j++)
                taken |= j != k && u->w[j].dev == found;
            if (!taken)
                arrived(w, found, now_ns);
        }
    }
    libusb_free_device_list(list, 1);
    return 0;
}

static void LIBUSB_CALL fd_added(int fd, short events, void *user)
{
    (void)fd;
    (void)events;
    lr_dev_fds_changed(&((lr_usb *)user)->base);
}

static void LIBUSB_CALL fd_removed(int fd, void *user)
{
    (void)fd;
    lr_dev_fds_changed(&((lr_usb *)user)->base);
}

static void usb_close(lr_dev *d)
{
    lr_usb *u = (lr_usb *)d;
    if (!u->ctx)
        return;
    for (int i = 0; i < u->n_cb; i++)
        libusb_hotplug_deregister_callback(u->ctx, u->cb[i]);
    u->n_cb = 0;
    for (int k = 0; k < u->n; k++) {
        close_reader(&u->w[k]);
        if (u->w[k].tr) {
            /* Never completed its cancellation: leaking it beats freeing it under libusb. */
            u->w[k].tr = NULL;
        }
        if (u->w[k].dev)
            libusb_unref_device(u->w[k].dev);
        u->w[k].dev = NULL;
    }
    for (int i = 0; i < u->nq; i++)
        libusb_unref_device(u->q[i].dev);
    u->nq = 0;
    libusb_set_pollfd_notifiers(u->ctx, NULL, NULL, NULL);
    libusb_exit(u->ctx);
    u->ctx = NULL;
}

static int usb_open(lr_dev *d, int64_t now_ns, lr_err *e)
{
    lr_usb *u = (lr_usb *)d;
    int rc = libusb_init(&u->ctx);
    if (rc != 0) {
        u->ctx = NULL;
        return lr_err_set(e, LR_ENODEV, "cannot initialise libusb: %s", libusb_strerror(rc));
    }
    libusb_set_pollfd_notifiers(u->ctx, fd_added, fd_removed, u);
    u->hotplug = u->want_hotplug && libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG);
    for (int k = 0; k < u->n; k++) {
        u->w[k].status[0] = '\0';
        u->w[k].retry_at = LR_NO_DEADLINE;
    }
    if (u->hotplug) {
        for (int k = 0; k < u->n && rc == 0; k++) {
            /* ENUMERATE: devices already plugged in are reported as arrivals too. */
            rc = libusb_hotplug_register_callback(
                u->ctx, LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED | LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT,
                LIBUSB_HOTPLUG_ENUMERATE, u->w[k].vid, u->w[k].pid, LIBUSB_HOTPLUG_MATCH_ANY,
                on_hotplug, u, &u->cb[u->n_cb]);
            if (rc == 0)
                u->n_cb++;
        }
        if (rc != 0) {
            usb_close(d);
            return lr_err_set(e, LR_EIO, "cannot register hotplug callbacks: %s",
                              libusb_strerror(rc));
        }
        process_news(u, now_ns);
    } else {
        rc = rescan(u, now_ns);
        if (rc != 0) {
            usb_close(d);
            return lr_err_set(e, LR_EIO, "cannot list USB devices: %s", libusb_strerror(rc));
        }
        u->next_rescan = now_ns + u->rescan_ns;
    }
    for (int k = 0; k < u->n; k++) {
        watch *w = &u->w[k];
        if (w->dev)
            continue;
        if (u->starting && u->required) {
            usb_close(d);
            return lr_err_set(e, LR_ENODEV, "%s: not present", w->ident);
        }
        watch_status(w, LR_LOG_WARN, "not present; waiting for it to be plugged in%s",
                     u->hotplug ? "" : " (checking every rescan)");
    }
    return LR_OK;
}

static int usb_pollfds(lr_dev *d, struct pollfd *fds, int max)
{
    lr_usb *u = (lr_usb *)d;
    const struct libusb_pollfd **list = libusb_get_pollfds(u->ctx);
    if (!list)
        return 0;
    int n = 0;
    for (; list[n]; n++)
        if (n < max)
            fds[n] = (struct pollfd){.fd = list[n]->fd, .events = list[n]->events};
    libusb_free_pollfds(list);
    return n;
}

static void usb_dispatch(lr_dev *d, int64_t now_ns)
{
    lr_usb *u = (lr_usb *)d;
    struct timeval zero = {0, 0};
    libusb_handle_events_timeout_completed(u->ctx, &zero, NULL);
    process_news(u, now_ns);
    if (u->q_overflow || (!u->hotplug && now_ns >= u->next_rescan)) {
        u->q_overflow = false;
        rescan(u, now_ns);
        u->next_rescan = now_ns + u->rescan_ns;
    }
    for (int k = 0; k < u->n; k++) {
        watch *w = &u->w[k];
        if (w->broken && w->dev) {
            close_reader(w);
            w->retry_at = lr_backoff_fail(&w->bo, now_ns);
            watch_status(w, LR_LOG_WARN, "reading reports failed; reopening with backoff");
        }
        if (w->dev && w->read && !w->h && now_ns >= w->retry_at)
            open_reader(w, now_ns);
    }
}

static int64_t usb_next_deadline(lr_dev *d)
{
    lr_usb *u = (lr_usb *)d;
    int64_t t = u->hotplug ? LR_NO_DEADLINE : u->next_rescan;
    struct timeval tv;
    /* libusb on Linux handles its transfer timeouts with a timerfd among its pollfds; where it
     * cannot, it tells us when to call it. */
    if (!libusb_pollfds_handle_timeouts(u->ctx) && libusb_get_next_timeout(u->ctx, &tv) == 1) {
        int64_t lt = lr_now_ns() + (int64_t)tv.tv_sec * 1000000000LL + (int64_t)tv.tv_usec * 1000;
        if (lt < t)
            t = lt;
    }
    for (int k = 0; k < u->n; k++)
        if (u->w[k].dev && u->w[k].read && !u->w[k].h && u->w[k].retry_at < t)
            t = u->w[k].retry_at;
    return t;
}

static void usb_destroy(lr_dev *d) { free(d); }

static const lr_dev_ops USB_OPS = {
    .kind = "usb",
    .open = usb_open,
    .close = usb_close,
    .pollfds = usb_pollfds,
    .dispatch = usb_dispatch,
    .next_deadline = usb_next_deadline,
    .destroy = usb_destroy,
};

static int configure(lr_usb *u, const lr_usb_desc *desc, lr_err *e)
{
    const char *pf = u->base.prefix;
    if (desc->n_watch < 1 || desc->n_watch > LR_USB_MAX_WATCH || !desc->watch)
        return lr_err_set(e, LR_EINVAL, "%s: n_watch %d is not 1..%d", pf, desc->n_watch,
                          LR_USB_MAX_WATCH);
    if (!lr_opt_hal_ok(&lr_usb_opts[LR_USB_OPT_RESCAN_MS], desc->rescan_ms))
        return lr_err_set(e, LR_EINVAL, "%s: rescan_ms %d out of range", pf, desc->rescan_ms);
    for (int k = 0; k < desc->n_watch; k++) {
        const lr_usb_watch *c = &desc->watch[k];
        watch *w = &u->w[k];
        w->u = u;
        if (!c->name || !c->name[0] || strlen(c->name) >= LR_EVENT_NAME_MAX)
            return lr_err_set(e, LR_EINVAL, "%s: watch[%d].name missing or longer than %d", pf, k,
                              LR_EVENT_NAME_MAX - 1);
        for (int j = 0; j < k; j++)
            if (strcmp(u->w[j].name, c->name) == 0)
                return lr_err_set(e, LR_EINVAL, "%s: watch[%d].name '%s' used twice", pf, k,
                                  c->name);
        if (!c->vid || !c->pid)
            return lr_err_set(e, LR_EINVAL, "%s: watch[%d] (%s): vid and pid are required", pf, k,
                              c->name);
        if (!lr_opt_in_range(&lr_usb_watch_opts[LR_USB_W_INTERFACE], c->interface))
            return lr_err_set(e, LR_EINVAL, "%s: watch[%d].interface %d is not 0..255", pf, k,
                              c->interface);
        strcpy(w->name, c->name);
        snprintf(w->ident, sizeof w->ident, "%s (%04x:%04x)", c->name, c->vid, c->pid);
        w->vid = c->vid;
        w->pid = c->pid;
        w->read = c->read_reports;
        w->iface = c->interface;
        w->pdesc = c->parser;
        if (w->pdesc.proto == LR_HID_AUTO)
            w->pdesc.proto = lr_hid_proto_for(c->vid, c->pid);
        if (lr_hid_parser_init(&w->parser, &w->pdesc, e) != LR_OK)
            return lr_err_prefix(e, "%s: watch[%d] (%s)", pf, k, c->name);
        lr_backoff_init(&w->bo, desc->dev.retry_min_ms, desc->dev.retry_max_ms);
        w->retry_at = LR_NO_DEADLINE;
        u->n = k + 1;
    }
    u->rescan_ns = lr_opt_or_default(&lr_usb_opts[LR_USB_OPT_RESCAN_MS], desc->rescan_ms) * MS;
    u->want_hotplug = !desc->no_hotplug;
    return LR_OK;
}

int lr_usb_create(const lr_usb_desc *desc, lr_usb **out, lr_err *e)
{
    *out = NULL;
    lr_usb *u = calloc(1, sizeof *u);
    if (!u)
        return lr_err_set(e, LR_ENOMEM, "usb: out of memory");
    int rc = lr_dev_init(&u->base, &USB_OPS, &desc->dev, e);
    if (rc == LR_OK)
        rc = configure(u, desc, e);
    if (rc == LR_OK) {
        u->starting = true;
        u->required = desc->dev.required;
        rc = lr_dev_start(&u->base, desc->dev.required, lr_now_ns(), e);
        u->starting = false;
    }
    if (rc != LR_OK) {
        usb_close(&u->base);
        free(u);
        return rc;
    }
    *out = u;
    return LR_OK;
}

void lr_usb_destroy(lr_usb *u)
{
    if (u)
        lr_dev_destroy(&u->base);
}

lr_dev *lr_usb_dev(lr_usb *u) { return &u->base; }
bool lr_usb_uses_hotplug(const lr_usb *u) { return u->hotplug; }

bool lr_usb_present(const lr_usb *u, int i)
{
    return i >= 0 && i < u->n && u->w[i].dev != NULL;
}

bool lr_usb_reading(const lr_usb *u, int i)
{
    return i >= 0 && i < u->n && u->w[i].h != NULL && u->w[i].transfer_active;
}

const char *lr_usb_watch_status(const lr_usb *u, int i)
{
    return i >= 0 && i < u->n ? u->w[i].status : "";
}
