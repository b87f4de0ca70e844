/* lamprig hal — USB presence (hotplug) and driverless USB controls through libusb.
 *
 * Watches a list of VID:PID devices. When one arrives or leaves, it logs one line and emits
 * {source = watch name, control = "present", LR_EV_ABSOLUTE, 1 or 0}; the firmware can use the
 * arrival to call lr_dev_retry_now() on a hid device waiting for it. Arrival and removal come
 * from libusb_hotplug_register_callback when libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG)
 * (callbacks run inside libusb_handle_events and only queue the news; it is handled right
 * after), otherwise from re-enumerating every rescan_ms.
 *
 * With read_reports, a present device is also opened (kernel driver detached while claimed),
 * its first interrupt IN endpoint on `interface` read with an asynchronous transfer, and each
 * report parsed by hal/hid_report.h (PowerMate, Shuttle, consumer knobs), so such a knob works
 * with no HID driver and no thread, entirely from the main loop's poll. A device that returns
 * is reopened; an open that fails (permissions, interface busy) is retried with backoff.
 *
 * The main loop sees libusb's own descriptors: lr_dev_pollfds returns libusb_get_pollfds(),
 * dispatch calls libusb_handle_events_timeout_completed with a zero timeout, and the pollfd
 * notifiers bump lr_dev_fd_generation when libusb adds or removes one. Each lr_usb has its own
 * libusb context.
 */
#ifndef LR_HAL_USB_H
#define LR_HAL_USB_H

#include <stdbool.h>
#include <stdint.h>

#include "hal/dev.h"
#include "hal/opt.h"
#include "hal/hid_report.h"
#include "render/base/err.h"

typedef struct lr_usb_watch {
    const char *name;            /* required: event source and log name, e.g. "powermate" */
    uint16_t vid, pid;           /* required */
    bool read_reports;           /* open the device and parse its interrupt IN reports */
    int interface;               /* interface to claim for read_reports; default 0 */
    lr_hid_parser_desc parser;   /* proto LR_HID_AUTO: by VID:PID */
} lr_usb_watch;

#define LR_USB_MAX_WATCH 16

typedef struct lr_usb_desc {
    lr_dev_desc dev;             /* name default "usb"; dev.required: every watched device must
                                  * be present at create */
    const lr_usb_watch *watch;
    int n_watch;                 /* 1..LR_USB_MAX_WATCH */
    int rescan_ms;               /* re-enumeration period without hotplug (lr_usb_opts) */
    bool no_hotplug;             /* re-enumerate even when libusb offers hotplug */
} lr_usb_desc;

/* The options above as the rig config reads them (hal/opt.h). */
enum { LR_USB_OPT_WATCH = 0, LR_USB_OPT_RESCAN_MS, LR_USB_OPT_NO_HOTPLUG };
extern const lr_opt lr_usb_opts[];
enum {
    LR_USB_W_NAME = 0,
    LR_USB_W_VID,
    LR_USB_W_PID,
    LR_USB_W_READ_REPORTS,
    LR_USB_W_INTERFACE,
    LR_USB_W_PROTO,
};
extern const lr_opt lr_usb_watch_opts[];

typedef struct lr_usb lr_usb;

int lr_usb_create(const lr_usb_desc *desc, lr_usb **out, lr_err *e);
void lr_usb_destroy(lr_usb *u);
lr_dev *lr_usb_dev(lr_usb *u);

/* True when arrivals come from libusb hotplug callbacks rather than re-enumeration. */
bool lr_usb_uses_hotplug(const lr_usb *u);
bool lr_usb_present(const lr_usb *u, int i);
/* True when watch i is present, read_reports is set and its reports are being read. */
bool lr_usb_reading(const lr_usb *u, int i);
/* The last line logged for watch i, e.g. "usb: powermate (077d:0410): not present; waiting
 * for it to be plugged in". */
const char *lr_usb_watch_status(const lr_usb *u, int i);

#endif
