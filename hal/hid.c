#include "hal/hid.h"

#include <hidapi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <wchar.h>

#include "hal/dev_impl.h"

const lr_opt lr_hid_opts[] = {
    [LR_HID_OPT_VID] = {"vid", LR_OPT_HEX16, .required = true, .help = "USB vendor id"},
    [LR_HID_OPT_PID] = {"pid", LR_OPT_HEX16, .required = true, .help = "USB product id"},
    [LR_HID_OPT_SERIAL] = {"serial", LR_OPT_STRING, .help = "match this serial number"},
    [LR_HID_OPT_POLL_MS] = {"poll_ms", LR_OPT_INT, 1, 1000, 8,
                            .help = "report queue polling period (the PowerMate's 125 Hz)"},
    [LR_HID_OPT_PROTO] = {"proto", LR_OPT_ENUM, .dflt = LR_HID_AUTO, .names = lr_hid_proto_names,
                          .help = "report parser; auto: by VID:PID"},
    [LR_HID_OPT_REPORT_ID] = {"report_id", LR_OPT_INT, 0, 255, 0,
                              .help = "0: reports carry no ID byte"},
    LR_OPT_END,
};

struct lr_hid {
    lr_dev base;
    uint16_t vid, pid;
    char serial[128];
    wchar_t wserial[128];
    char ident[192]; /* "077d:0410 (powermate)" or with the serial: for messages */
    lr_hid_parser_desc pdesc;
    lr_hid_parser parser;
    int64_t poll_ns;
    int64_t next_poll;
    hid_device *h;
    bool garbage_logged;
};

static int hid_dev_open(lr_dev *d, int64_t now_ns, lr_err *e)
{
    lr_hid *h = (lr_hid *)d;
    if (hid_init() != 0)
        return lr_err_set(e, LR_EIO, "%s: hidapi initialisation failed", h->ident);
    struct hid_device_info *list = hid_enumerate(h->vid, h->pid), *pick = NULL;
    int found = 0;
    for (struct hid_device_info *it = list; it; it = it->next) {
        found++;
        if (h->serial[0] && (!it->serial_number || wcscmp(it->serial_number, h->wserial) != 0))
            continue;
        if (!pick)
            pick = it;
    }
    int rc = LR_OK;
    if (!pick) {
        if (found)
            rc = lr_err_set(e, LR_ENODEV, "%s: %d device%s with this VID:PID, none with serial '%s'",
                            h->ident, found, found == 1 ? "" : "s", h->serial);
        else
            rc = lr_err_set(e, LR_ENODEV,
                            "%s: not present (no such USB HID device, or no permission to see it)",
                            h->ident);
    } else {
        h->h = hid_open_path(pick->path);
        if (!h->h)
            rc = lr_err_set(e, LR_EIO,
                            "%s: found at %s but cannot open it (permissions? a udev rule giving "
                            "the rig's user access to the device fixes it)",
                            h->ident, pick->path);
        else if (hid_set_nonblocking(h->h, 1) != 0) {
            hid_close(h->h);
            h->h = NULL;
            rc = lr_err_set(e, LR_EIO, "%s: cannot switch to non-blocking reads", h->ident);
        }
    }
    hid_free_enumeration(list);
    if (rc != LR_OK)
        return rc;
    /* A reopened device starts from a fresh state (no stale jog counter or buttons held);
     * the counters carry on. */
    h->parser.have_prev = 0;
    h->parser.buttons = 0;
    h->parser.jog = 0;
    h->parser.shuttle = 0;
    h->parser.n_cc = 0;
    h->garbage_logged = false;
    h->next_poll = now_ns;
    return LR_OK;
}

static void hid_dev_close(lr_dev *d)
{
    lr_hid *h = (lr_hid *)d;
    if (h->h)
        hid_close(h->h);
    h->h = NULL;
}

static int hid_dev_pollfds(lr_dev *d, struct pollfd *fds, int max)
{
    (void)d;
    (void)fds;
    (void)max;
    return 0; /* hidapi has no pollable descriptor: see next_deadline */
}

static void hid_dev_dispatch(lr_dev *d, int64_t now_ns)
{
    lr_hid *h = (lr_hid *)d;
    if (now_ns < h->next_poll)
        return;
    h->next_poll = now_ns + h->poll_ns;
    uint8_t buf[256];
    /* Bounded: a device cannot keep us here however fast it reports. */
    for (int i = 0; i < 64; i++) {
        int n = hid_read(h->h, buf, sizeof buf);
        if (n == 0)
            return;
        if (n < 0) {
            lr_dev_lost(d, LR_ENODEV, now_ns, "%s: read failed (unplugged?)", h->ident);
            return;
        }
        lr_event ev[LR_HID_MAX_EVENTS];
        int nev = 0;
        lr_err pe = {0};
        if (lr_hid_parse(&h->parser, buf, (size_t)n, ev, &nev, &pe) != LR_OK) {
            if (!h->garbage_logged)
                lr_dev_log(d, LR_LOG_WARN, "%s: garbage report ignored: %s", h->ident, pe.msg);
            h->garbage_logged = true;
            continue;
        }
        h->garbage_logged = false;
        for (int k = 0; k < nev; k++)
            lr_dev_emit(d, NULL, ev[k].control, ev[k].kind, ev[k].value, now_ns);
    }
}

static int64_t hid_dev_next_deadline(lr_dev *d) { return ((lr_hid *)d)->next_poll; }

static void hid_dev_destroy(lr_dev *d) { free(d); }

static const lr_dev_ops HID_OPS = {
    .kind = "hid",
    .open = hid_dev_open,
    .close = hid_dev_close,
    .pollfds = hid_dev_pollfds,
    .dispatch = hid_dev_dispatch,
    .next_deadline = hid_dev_next_deadline,
    .destroy = hid_dev_destroy,
};

int lr_hid_create(const lr_hid_desc *desc, lr_hid **out, lr_err *e)
{
    *out = NULL;
    lr_hid *h = calloc(1, sizeof *h);
    if (!h)
        return lr_err_set(e, LR_ENOMEM, "hid: out of memory");
    int rc = lr_dev_init(&h->base, &HID_OPS, &desc->dev, e);
    const char *pf = h->base.prefix;
    if (rc == LR_OK && (desc->vid == 0 || desc->pid == 0))
        rc = lr_err_set(e, LR_EINVAL, "%s: vid and pid are required (e.g. 077d:0410)", pf);
    if (rc == LR_OK && desc->serial && strlen(desc->serial) >= sizeof h->serial)
        rc = lr_err_set(e, LR_EINVAL, "%s: serial too long", pf);
    const lr_opt *po = &lr_hid_opts[LR_HID_OPT_POLL_MS];
    if (rc == LR_OK && !lr_opt_hal_ok(po, desc->poll_ms))
        rc = lr_err_set(e, LR_EINVAL, "%s: poll_ms %d is not 0..%ld", pf, desc->poll_ms, po->hi);
    if (rc == LR_OK) {
        h->vid = desc->vid;
        h->pid = desc->pid;
        if (desc->serial) {
            strcpy(h->serial, desc->serial);
            /* Serial numbers are ASCII in practice; widen byte by byte (no locale needed). */
            for (size_t i = 0; i <= strlen(h->serial); i++)
                h->wserial[i] = (wchar_t)(unsigned char)h->serial[i];
        }
        h->pdesc = desc->parser;
        if (h->pdesc.proto == LR_HID_AUTO)
            h->pdesc.proto = lr_hid_proto_for(desc->vid, desc->pid);
        rc = lr_hid_parser_init(&h->parser, &h->pdesc, e);
        if (rc != LR_OK)
            lr_err_prefix(e, "%s", pf);
    }
    if (rc == LR_OK) {
        snprintf(h->ident, sizeof h->ident, "%04x:%04x (%s%s%s)", h->vid, h->pid,
                 lr_hid_proto_name(h->pdesc.proto), h->serial[0] ? ", serial " : "", h->serial);
        snprintf(h->base.ident, sizeof h->base.ident, "%s", h->ident);
        h->poll_ns = (int64_t)lr_opt_or_default(po, desc->poll_ms) * 1000000;
        rc = lr_dev_start(&h->base, desc->dev.required, lr_now_ns(), e);
    }
    if (rc != LR_OK) {
        hid_dev_close(&h->base);
        free(h);
        return rc;
    }
    *out = h;
    return LR_OK;
}

void lr_hid_destroy(lr_hid *h)
{
    if (h)
        lr_dev_destroy(&h->base);
}

lr_dev *lr_hid_dev(lr_hid *h) { return &h->base; }
const lr_hid_parser *lr_hid_parser_of(const lr_hid *h) { return &h->parser; }

void lr_hid_library_exit(void) { hid_exit(); }
