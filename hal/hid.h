/* lamprig hal — USB HID knob controllers through hidapi (hidapi-libusb).
 *
 * Opens the first device matching VID:PID (and serial number, when given), reads its input
 * reports non-blocking and turns them into events with the parsers of hal/hid_report.h
 * (PowerMate, ShuttleXpress/PRO, consumer-control knobs; protocol picked by VID:PID unless
 * given). Controls: PowerMate "knob" (delta) and "button"; Shuttle "shuttle" (absolute -1..1),
 * "jog" (delta), "button1".."button15"; consumer "volume" (delta), "mute", "play", "cc_XXX".
 *
 * hidapi offers no file descriptor to poll (its libusb back end reads on an internal thread and
 * queues reports), so while open this device asks for a dispatch every poll_ms through
 * lr_dev_next_deadline and drains the queue then: a timer, not a busy wait. A device that
 * cannot be found is MISSING and retried with backoff; a read error (unplugged) closes it and
 * it is reopened when it returns — at the next backoff step, or at once when the firmware calls
 * lr_dev_retry_now() on a usb arrival (hal/usb.h). For a fully fd-driven knob, the usb back end
 * can read the same reports itself (lr_usb_watch.read_reports).
 *
 * Garbage reports are counted and logged once per run of them (the first one after a good
 * report), never fatal.
 */
#ifndef LR_HAL_HID_H
#define LR_HAL_HID_H

#include <stdint.h>

#include "hal/dev.h"
#include "hal/opt.h"
#include "hal/hid_report.h"
#include "render/base/err.h"

typedef struct lr_hid_desc {
    lr_dev_desc dev;            /* name default "hid" */
    uint16_t vid, pid;          /* required */
    const char *serial;         /* optional: match this serial number (ASCII) */
    lr_hid_parser_desc parser;  /* parser.proto LR_HID_AUTO: by VID:PID */
    int poll_ms;                /* report queue polling period (lr_hid_opts: default 8 ms, 125 Hz,
                                 * the PowerMate's interrupt interval) */
} lr_hid_desc;

/* The options above as the rig config reads them (hal/opt.h). */
enum {
    LR_HID_OPT_VID = 0,
    LR_HID_OPT_PID,
    LR_HID_OPT_SERIAL,
    LR_HID_OPT_POLL_MS,
    LR_HID_OPT_PROTO,
    LR_HID_OPT_REPORT_ID,
};
extern const lr_opt lr_hid_opts[];

typedef struct lr_hid lr_hid;

int lr_hid_create(const lr_hid_desc *desc, lr_hid **out, lr_err *e);
void lr_hid_destroy(lr_hid *h);
lr_dev *lr_hid_dev(lr_hid *h);
/* The parser, for its counters (reports, short_reports, oversized_reports, bad_values). */
const lr_hid_parser *lr_hid_parser_of(const lr_hid *h);

/* hidapi keeps process-wide state (its libusb context); call once at program exit, after every
 * lr_hid is destroyed. */
void lr_hid_library_exit(void);

#endif
