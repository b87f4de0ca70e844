#include "hal/hid_report.h"

#include <stdio.h>
#include <string.h>

#define USAGE_VOL_UP 0x00E9
#define USAGE_VOL_DOWN 0x00EA
#define USAGE_MUTE 0x00E2
#define USAGE_PLAY_PAUSE 0x00CD

lr_hid_proto lr_hid_proto_for(uint16_t vid, uint16_t pid)
{
    if (vid == 0x077d && (pid == 0x0410 || pid == 0x04aa))
        return LR_HID_POWERMATE;
    if (vid == 0x0b33 && pid == 0x0020)
        return LR_HID_SHUTTLEXPRESS;
    if (vid == 0x0b33 && (pid == 0x0010 || pid == 0x0030))
        return LR_HID_SHUTTLEPRO;
    return LR_HID_CONSUMER;
}

const char *const lr_hid_proto_names[] = {
    [LR_HID_AUTO] = "auto",
    [LR_HID_POWERMATE] = "powermate",
    [LR_HID_SHUTTLEXPRESS] = "shuttlexpress",
    [LR_HID_SHUTTLEPRO] = "shuttlepro",
    [LR_HID_CONSUMER] = "consumer",
    NULL,
};

const char *lr_hid_proto_name(lr_hid_proto proto)
{
    return (unsigned)proto <= LR_HID_CONSUMER ? lr_hid_proto_names[proto] : "?";
}

int lr_hid_parser_init(lr_hid_parser *p, const lr_hid_parser_desc *desc, lr_err *e)
{
    memset(p, 0, sizeof *p);
    p->desc = *desc;
    switch (desc->proto) {
    case LR_HID_POWERMATE:
    case LR_HID_SHUTTLEXPRESS:
    case LR_HID_SHUTTLEPRO:
        return LR_OK;
    case LR_HID_CONSUMER:
        if (desc->cc_layout == LR_HID_CC_BITMAP) {
            for (int i = 0; i < 16; i++)
                if (desc->cc_bitmap[i])
                    return LR_OK;
            return lr_err_set(e, LR_EINVAL,
                              "hid consumer: bitmap layout needs cc_bitmap (usage of each bit)");
        }
        if (desc->cc_layout != LR_HID_CC_ARRAY16)
            return lr_err_set(e, LR_EINVAL, "hid consumer: unknown layout %d",
                              (int)desc->cc_layout);
        return LR_OK;
    case LR_HID_AUTO:
        break;
    }
    return lr_err_set(e, LR_EINVAL, "hid: parser protocol %d not resolved (auto or unknown)",
                      (int)desc->proto);
}

static void put(lr_event *out, int *n, const char *control, lr_event_kind kind, double value)
{
    if (*n >= LR_HID_MAX_EVENTS)
        return;
    lr_event_set(&out[*n], "", control, kind, value, 0);
    (*n)++;
}

static int too_short(lr_hid_parser *p, lr_err *e, size_t got, size_t need)
{
    p->short_reports++;
    return lr_err_set(e, LR_EPROTO, "%s: short report (%zu byte%s, need %zu)",
                      lr_hid_proto_name(p->desc.proto), got, got == 1 ? "" : "s", need);
}

/* Press/release events for the buttons that changed; button numbers are 1-based. */
static void button_events(lr_event *out, int *n, uint16_t old, uint16_t now, const int *bits,
                          int nbits)
{
    for (int i = 0; i < nbits; i++) {
        uint16_t m = (uint16_t)(1u << bits[i]);
        if ((old ^ now) & m) {
            char name[LR_EVENT_NAME_MAX];
            snprintf(name, sizeof name, "button%d", i + 1);
            put(out, n, name, (now & m) ? LR_EV_PRESS : LR_EV_RELEASE, (now & m) ? 1 : 0);
        }
    }
}

static int parse_powermate(lr_hid_parser *p, const uint8_t *b, size_t len, lr_event *out, int *n,
                           lr_err *e)
{
    if (len < 3)
        return too_short(p, e, len, 3);
    if (len > 6)
        p->oversized_reports++;
    int delta = (int8_t)b[1];
    uint16_t buttons = b[0] & 1;
    if (delta)
        put(out, n, "knob", LR_EV_DELTA, delta);
    if (buttons != p->buttons)
        put(out, n, "button", buttons ? LR_EV_PRESS : LR_EV_RELEASE, buttons ? 1 : 0);
    p->buttons = buttons;
    p->have_prev = 1;
    return LR_OK;
}

static int parse_shuttle(lr_hid_parser *p, const uint8_t *b, size_t len, lr_event *out, int *n,
                         lr_err *e)
{
    static const int XPRESS[] = {4, 5, 6, 7, 8};
    static const int PRO[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14};
    if (len < 5)
        return too_short(p, e, len, 5);
    int shuttle = (int8_t)b[0];
    if (shuttle < -7 || shuttle > 7) {
        p->bad_values++;
        return lr_err_set(e, LR_EPROTO, "%s: shuttle position %d out of range -7..7",
                          lr_hid_proto_name(p->desc.proto), shuttle);
    }
    if (len > 5)
        p->oversized_reports++;
    uint8_t jog = b[1];
    uint16_t buttons = (uint16_t)(b[3] | (b[4] << 8));
    if (p->have_prev) {
        /* The counter is 8 bits: the signed difference modulo 256 is the motion, so 255 -> 0 is
         * one step forward and 0 -> 255 one step back. (Reports come every click, far fewer than
         * 128 counts apart.) */
        int d = (int8_t)(uint8_t)(jog - p->jog);
        if (d)
            put(out, n, "jog", LR_EV_DELTA, d);
    }
    if (shuttle != p->shuttle)
        put(out, n, "shuttle", LR_EV_ABSOLUTE, shuttle / 7.0);
    if (p->desc.proto == LR_HID_SHUTTLEXPRESS)
        button_events(out, n, p->buttons, buttons, XPRESS, 5);
    else
        button_events(out, n, p->buttons, buttons, PRO, 15);
    p->jog = jog;
    p->shuttle = (int8_t)shuttle;
    p->buttons = buttons;
    p->have_prev = 1;
    return LR_OK;
}

static void usage_name(uint16_t u, char name[LR_EVENT_NAME_MAX])
{
    switch (u) {
    case USAGE_MUTE: snprintf(name, LR_EVENT_NAME_MAX, "mute"); break;
    case USAGE_PLAY_PAUSE: snprintf(name, LR_EVENT_NAME_MAX, "play"); break;
    default: snprintf(name, LR_EVENT_NAME_MAX, "cc_%03x", u); break;
    }
}

static int has(const uint16_t *set, int n, uint16_t u)
{
    for (int i = 0; i < n; i++)
        if (set[i] == u)
            return 1;
    return 0;
}

/* Diffs the set of usages held down against the previous report. */
static void consumer_events(lr_hid_parser *p, const uint16_t *down, int n_down, lr_event *out,
                            int *n)
{
    char name[LR_EVENT_NAME_MAX];
    for (int i = 0; i < p->n_cc; i++) {
        uint16_t u = p->cc[i];
        if (has(down, n_down, u) || u == USAGE_VOL_UP || u == USAGE_VOL_DOWN)
            continue;
        usage_name(u, name);
        put(out, n, name, LR_EV_RELEASE, 0);
    }
    for (int i = 0; i < n_down; i++) {
        uint16_t u = down[i];
        if (has(p->cc, p->n_cc, u))
            continue;
        if (u == USAGE_VOL_UP || u == USAGE_VOL_DOWN) {
            put(out, n, "volume", LR_EV_DELTA, u == USAGE_VOL_UP ? 1 : -1);
        } else {
            usage_name(u, name);
            put(out, n, name, LR_EV_PRESS, 1);
        }
    }
    memcpy(p->cc, down, (size_t)n_down * sizeof *down);
    p->n_cc = n_down;
}

static int parse_consumer(lr_hid_parser *p, const uint8_t *b, size_t len, lr_event *out, int *n,
                          lr_err *e)
{
    uint16_t down[LR_HID_CC_MAX];
    int n_down = 0;
    if (p->desc.cc_layout == LR_HID_CC_BITMAP) {
        if (len < 1)
            return too_short(p, e, len, 1);
        if (len > 2)
            p->oversized_reports++;
        unsigned bits = b[0] | (len > 1 ? (unsigned)b[1] << 8 : 0u);
        for (int i = 0; i < 16 && n_down < LR_HID_CC_MAX; i++) {
            uint16_t u = p->desc.cc_bitmap[i];
            if ((bits & (1u << i)) && u && !has(down, n_down, u))
                down[n_down++] = u;
        }
    } else {
        if (len < 2)
            return too_short(p, e, len, 2);
        size_t slots = len / 2;
        if (slots > LR_HID_CC_MAX || (len & 1))
            p->oversized_reports++;
        if (slots > LR_HID_CC_MAX)
            slots = LR_HID_CC_MAX;
        for (size_t i = 0; i < slots; i++) {
            uint16_t u = (uint16_t)(b[2 * i] | (b[2 * i + 1] << 8));
            if (u && !has(down, n_down, u))
                down[n_down++] = u;
        }
    }
    consumer_events(p, down, n_down, out, n);
    p->have_prev = 1;
    return LR_OK;
}

int lr_hid_parse(lr_hid_parser *p, const uint8_t *buf, size_t len, lr_event *out, int *n_out,
                 lr_err *e)
{
    *n_out = 0;
    if (p->desc.report_id) {
        if (len < 1)
            return too_short(p, e, len, 1);
        if (buf[0] != p->desc.report_id) {
            p->ignored_reports++;
            return LR_OK;
        }
        buf++;
        len--;
    }
    p->reports++;
    switch (p->desc.proto) {
    case LR_HID_POWERMATE: return parse_powermate(p, buf, len, out, n_out, e);
    case LR_HID_SHUTTLEXPRESS:
    case LR_HID_SHUTTLEPRO: return parse_shuttle(p, buf, len, out, n_out, e);
    case LR_HID_CONSUMER: return parse_consumer(p, buf, len, out, n_out, e);
    case LR_HID_AUTO: break;
    }
    return lr_err_set(e, LR_EINVAL, "hid: parser not initialised");
}
