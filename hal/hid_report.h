/* lamprig hal — HID input report parsers (pure functions over bytes; no hidapi here).
 *
 * Layouts, as the devices send them (hidapi returns the same bytes; for devices with numbered
 * reports the first byte is the report ID):
 *
 * PowerMate (Griffin, 077d:0410; the older SoundKnob 077d:04aa), 3..6 byte reports, no ID:
 *   byte 0  bit 0 = knob pressed          byte 1  rotation since last report, signed int8
 *   bytes 2..5 LED state (ignored). Source: Linux drivers/input/misc/powermate.c, powermate_irq()
 *   (BTN_0 <- data[0] & 1, REL_DIAL <- (signed char)data[1]; POWERMATE_PAYLOAD_SIZE_MIN 3, MAX 6).
 *
 * ShuttleXpress (Contour, 0b33:0020) and ShuttlePRO v1/v2 (0b33:0010, 0b33:0030), 5 bytes, no ID:
 *   byte 0  shuttle ring position, int8 -7..7 (0 = centre)
 *   byte 1  jog wheel counter, uint8, +1 per click clockwise, wraps 255 <-> 0
 *   byte 2  unused
 *   bytes 3,4  buttons, uint16 little-endian: ShuttleXpress buttons 1..5 = bits 4..8,
 *              ShuttlePRO buttons 1..15 = bits 0..14.
 *   Sources: hopejr/ShuttleControlUSB lib/ShuttleDefs.js (offsets, int8/uint8/uint16le, button
 *   masks 0x0010..0x0100 for the Xpress), vrpn_Contour.C, node-red-contrib-shuttlexpress README
 *   (jog click = <00 FF 00 00 00>: counter 0 -> 255 is one step back).
 *
 * Consumer-control knobs (USB HID usage page 0x0C; cheap "volume knobs", TinyUSB/Arduino
 * builds), two layouts in the wild:
 *   ARRAY16  [report ID] then one or more 16-bit little-endian usage codes of the controls held
 *            down, 0 = none (TinyUSB TUD_HID_REPORT_DESC_CONSUMER: Report Size 16, Usage 0..0x3FF,
 *            Input Data,Array,Abs). The default.
 *   BITMAP   [report ID] then one bit per control (e.g. XMOS lib_xua: Play, Next, Prev,
 *            Volume Up, Volume Down, Mute); which usage each bit is comes from the descriptor.
 *   Usages: 0xE9 Volume Increment and 0xEA Volume Decrement become delta +1/-1 on "volume" (one
 *   per press: a knob detent is a press/release pair); 0xE2 Mute -> press/release "mute";
 *   0xCD Play/Pause -> "play"; any other usage U -> press/release "cc_U" (hex, e.g. "cc_0b5").
 *
 * Short reports and out-of-range values are garbage: LR_EPROTO with a message, counted, no
 * events. Oversized reports (longer than the layout) are parsed by their known prefix and
 * counted: some firmware pads reports to the endpoint size.
 */
#ifndef LR_HAL_HID_REPORT_H
#define LR_HAL_HID_REPORT_H

#include <stddef.h>
#include <stdint.h>

#include "hal/event.h"
#include "render/base/err.h"

typedef enum lr_hid_proto {
    LR_HID_AUTO = 0, /* pick by VID:PID (lr_hid_proto_for); unknown devices: consumer control */
    LR_HID_POWERMATE,
    LR_HID_SHUTTLEXPRESS,
    LR_HID_SHUTTLEPRO,
    LR_HID_CONSUMER,
} lr_hid_proto;

typedef enum lr_hid_cc_layout {
    LR_HID_CC_ARRAY16 = 0,
    LR_HID_CC_BITMAP,
} lr_hid_cc_layout;

typedef struct lr_hid_parser_desc {
    lr_hid_proto proto;
    /* 0: reports carry no ID byte. Otherwise the first byte must equal it (other reports of a
     * composite device are ignored, not garbage) and is skipped. */
    uint8_t report_id;
    lr_hid_cc_layout cc_layout;   /* consumer only */
    uint16_t cc_bitmap[16];       /* consumer BITMAP: usage of bit i (0 = unused bit) */
} lr_hid_parser_desc;

#define LR_HID_CC_MAX 8 /* usages tracked per ARRAY16 report */

typedef struct lr_hid_parser {
    lr_hid_parser_desc desc;
    int have_prev;            /* a previous report set the state below */
    uint16_t buttons;         /* PowerMate/Shuttle buttons down */
    uint8_t jog;              /* Shuttle jog counter */
    int8_t shuttle;           /* Shuttle ring position */
    uint16_t cc[LR_HID_CC_MAX]; /* consumer usages down */
    int n_cc;
    uint32_t reports, short_reports, oversized_reports, bad_values, ignored_reports;
} lr_hid_parser;

/* Most events one report can produce (15 buttons + shuttle + jog, or 8 usages up + 8 down). */
#define LR_HID_MAX_EVENTS 20

/* Known devices: PowerMate, ShuttleXpress, ShuttlePRO; LR_HID_CONSUMER otherwise. */
lr_hid_proto lr_hid_proto_for(uint16_t vid, uint16_t pid);
/* "auto", "powermate", ... in lr_hid_proto order, NULL-terminated (an LR_OPT_ENUM's names). */
extern const char *const lr_hid_proto_names[];
const char *lr_hid_proto_name(lr_hid_proto proto);

/* desc->proto must not be LR_HID_AUTO (resolve it with lr_hid_proto_for first). LR_EINVAL when
 * the descriptor is inconsistent (BITMAP layout without any usage). */
int lr_hid_parser_init(lr_hid_parser *p, const lr_hid_parser_desc *desc, lr_err *e);

/* Parses one input report. Events (control, kind, value; source empty, t_ns 0: the caller
 * stamps them) go to out[0..*n_out), at most LR_HID_MAX_EVENTS. LR_OK, or LR_EPROTO with a
 * message naming the layout and the problem; the parser state is unchanged by garbage. */
int lr_hid_parse(lr_hid_parser *p, const uint8_t *buf, size_t len, lr_event *out, int *n_out,
                 lr_err *e);

#endif
