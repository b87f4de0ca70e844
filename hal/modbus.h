/* lamprig hal — Modbus master (libmodbus) for the dimmer panel and the lamp driver.
 *
 * Endpoint URL (lr_modbus_url_parse, pure):
 *   tcp://HOST[:PORT]          PORT default 502; HOST a name, an IPv4 address or [IPv6]
 *   rtu:DEVICE[?baud=B&parity=N|E|O&data=D&stop=S&rs485=0|1]
 *                              defaults 19200 baud, parity E, 8 data bits, 1 stop bit (the
 *                              Modbus serial-line default, 8E1), rs485=0 (adapter switches the
 *                              direction itself; rs485=1 asks the kernel via TIOCSRS485)
 *
 * Inputs (the panel): each configured register is read every poll_ms; when its raw value
 * changes an LR_EV_ABSOLUTE event {source = device name, control = input's control,
 * value = (raw - raw_min) / (raw_max - raw_min) clamped to 0..1} is emitted (also once after
 * every (re)connect, so the firmware learns the current position).
 * Output (the lamp driver): lr_modbus_write_level(m, level01) scales 0..1 to raw_min..raw_max,
 * rounds, and writes the register (FC 6, or FC 16 with `multiple`). The dimmer *curve* is not
 * applied here: the firmware applies it in one place; this layer only scales. Only the latest
 * level is kept: a burst of knob events becomes one write when the link is busy.
 *
 * Loop design: no call waits for the peer. libmodbus only connects (TCP: a non-blocking
 * connect bounded by timeout_ms; RTU: open(2) and termios of the tty) and closes; the frames
 * are built and parsed here (modbus_receive_confirmation bounds each byte, not the frame: a
 * peer dripping a long answer one byte per byte_timeout would block it for seconds). A request
 * is one write to the non-blocking socket or tty; dispatch reads whatever bytes are there
 * (at most two frames' worth per call) into a buffer and frames them: TCP by the MBAP length,
 * RTU by the function's answer length. The whole transaction has one deadline, timeout_ms
 * after the request, however the bytes arrive: so a dispatch returns in microseconds and no
 * peer holds the loop, or the other devices, longer than that. RTU also ends a frame at a gap
 * of byte_timeout_ms. DNS: give an address, or a name /etc/hosts resolves, since getaddrinfo
 * may block.
 *
 * Matching: a TCP answer is taken for the request in flight only when its MBAP transaction id
 * is the request's; others are late answers to earlier requests (after a timeout) and are
 * dropped and counted (`stale`), the wait going on. Unit, function, byte count / echo are
 * checked too (`bad_responses`). RTU has no transaction id: after a timeout or a broken frame
 * the line is flushed, so a late answer cannot be taken for the next one.
 *
 * Errors are counted (lr_modbus_get_counters), logged once per change of condition per channel
 * and at most 4 lines of a kind (timeouts, CRC, exceptions, malformed, stale, recoveries) per
 * 10 s per device, never fatal: exception responses (illegal address ...) and garbage (bad CRC,
 * wrong function or length) keep the link; max_timeouts consecutive timeouts, a closed
 * connection, an I/O error or a TCP stream that is not Modbus drop it, and it is reopened with
 * exponential backoff (lr_dev_desc.retry_min_ms/max_ms). The backoff restarts from
 * retry_min_ms on a good answer, not on a connect: a peer that accepts and closes at once is
 * retried ever later, up to retry_max_ms.
 */
#ifndef LR_HAL_MODBUS_H
#define LR_HAL_MODBUS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "hal/dev.h"
#include "hal/opt.h"
#include "render/base/err.h"

/* ---- endpoint URL ---- */

typedef enum lr_modbus_transport {
    LR_MODBUS_TCP = 1,
    LR_MODBUS_RTU,
} lr_modbus_transport;

#define LR_MODBUS_HOST_MAX 256

typedef struct lr_modbus_url {
    lr_modbus_transport transport;
    char host[LR_MODBUS_HOST_MAX];   /* tcp; without the IPv6 brackets */
    int port;                        /* tcp */
    char device[LR_MODBUS_HOST_MAX]; /* rtu: /dev/ttyUSB0 ... */
    int baud;                        /* rtu */
    char parity;                     /* rtu: 'N', 'E' or 'O' */
    int data_bits;                   /* rtu: 5..8 */
    int stop_bits;                   /* rtu: 1 or 2 */
    bool rs485;                      /* rtu */
} lr_modbus_url;

/* Parses url into *out. LR_EPARSE with a message quoting the URL and naming the bad part. */
int lr_modbus_url_parse(const char *url, lr_modbus_url *out, lr_err *e);
/* Canonical text form ("tcp://127.0.0.1:1502", "rtu:/dev/ttyUSB0?baud=19200&parity=E&data=8&
 * stop=1"); returns what snprintf returns. */
int lr_modbus_url_format(const lr_modbus_url *u, char *buf, size_t n);

/* ---- the device ---- */

typedef enum lr_modbus_reg_type {
    LR_MODBUS_HOLDING = 0, /* FC 3 read holding registers */
    LR_MODBUS_INPUT,       /* FC 4 read input registers */
} lr_modbus_reg_type;

typedef struct lr_modbus_input {
    const char *control;     /* event control name; default "dimmer" */
    int unit;                /* unit (slave) id 1..247 (TCP also 248..255); 0 means 1 */
    int reg;                 /* register number, counted from `base` */
    int base;                /* 0: reg is the protocol address; 1: 1-based numbering (reg 1 =
                              * address 0), as many panel manuals print it */
    lr_modbus_reg_type type;
    int raw_min, raw_max;    /* raw range mapped to 0..1; raw_max 0 means 1000 (raw_min 0) */
} lr_modbus_input;

typedef struct lr_modbus_output {
    bool enabled;            /* false: no lamp driver on this link */
    int unit;                /* 0 means 1 */
    int reg;
    int base;                /* as for inputs */
    int raw_min, raw_max;    /* 0..1 maps to raw_min..raw_max; raw_max 0 means 255 */
    bool multiple;           /* write with FC 16 (one register) instead of FC 6 */
} lr_modbus_output;

typedef struct lr_modbus_desc {
    lr_dev_desc dev;         /* name default "modbus" */
    const char *url;         /* required: tcp://... or rtu:... */
    const lr_modbus_input *inputs;
    int n_inputs;            /* at most 16 */
    lr_modbus_output output;
    /* Defaults and ranges of these: lr_modbus_opts below (0: the default). */
    int poll_ms;             /* input polling period */
    int timeout_ms;          /* bounds a whole answer from its request (and connect) */
    int byte_timeout_ms;     /* RTU: a gap this long inside a frame ends it */
    int max_timeouts;        /* consecutive timeouts that drop the link */
} lr_modbus_desc;

/* The options above as the rig config reads them (hal/opt.h); configure() checks with them. */
enum {
    LR_MODBUS_OPT_URL = 0,
    LR_MODBUS_OPT_POLL_MS,
    LR_MODBUS_OPT_TIMEOUT_MS,
    LR_MODBUS_OPT_BYTE_TIMEOUT_MS,
    LR_MODBUS_OPT_MAX_TIMEOUTS,
    LR_MODBUS_OPT_INPUTS,
    LR_MODBUS_OPT_LAMP,
};
extern const lr_opt lr_modbus_opts[];
/* One input (inputs[i]) and the output (the rig config's "lamp"). */
enum {
    LR_MODBUS_IN_CONTROL = 0,
    LR_MODBUS_IN_UNIT,
    LR_MODBUS_IN_REG,
    LR_MODBUS_IN_BASE,
    LR_MODBUS_IN_TYPE,
    LR_MODBUS_IN_RAW_MIN,
    LR_MODBUS_IN_RAW_MAX,
};
extern const lr_opt lr_modbus_input_opts[];
enum {
    LR_MODBUS_OUT_UNIT = 0,
    LR_MODBUS_OUT_REG,
    LR_MODBUS_OUT_BASE,
    LR_MODBUS_OUT_RAW_MIN,
    LR_MODBUS_OUT_RAW_MAX,
    LR_MODBUS_OUT_MULTIPLE,
};
extern const lr_opt lr_modbus_output_opts[];

typedef struct lr_modbus_counters {
    uint64_t requests;       /* sent */
    uint64_t responses;      /* valid, non-exception answers */
    uint64_t timeouts;
    uint64_t crc_errors;     /* RTU frames with a bad CRC */
    uint64_t exceptions;     /* exception responses (illegal address, device busy ...) */
    uint64_t last_exception; /* code of the latest one (2 = illegal data address) */
    uint64_t bad_responses;  /* wrong function, length, echo or unit */
    uint64_t stale;          /* TCP answers to an earlier request (transaction id), dropped */
    uint64_t io_errors;      /* send/receive failures that dropped the link */
    uint64_t connects;       /* successful (re)connects */
    uint64_t writes;         /* level writes acknowledged by the driver */
} lr_modbus_counters;

typedef struct lr_modbus lr_modbus;

int lr_modbus_create(const lr_modbus_desc *desc, lr_modbus **out, lr_err *e);
void lr_modbus_destroy(lr_modbus *m);
lr_dev *lr_modbus_dev(lr_modbus *m);

/* Sets the lamp driver level (0..1, clamped; NaN is LR_EINVAL). Sent at once when the link is
 * idle, else right after the request in flight; re-sent after a reconnect. LR_EUNSUPPORTED
 * when no output is configured. Never blocks. */
int lr_modbus_write_level(lr_modbus *m, double level01);
/* The raw register value the next or last write carries (for logs and tests); -1 before any. */
int lr_modbus_output_raw(const lr_modbus *m);
/* True when the driver acknowledged the latest level. */
bool lr_modbus_output_synced(const lr_modbus *m);
/* For shutdown only (the safe level must land before exit): runs this device's I/O until the
 * latest level is acknowledged or timeout_ms passes. LR_ETIMEOUT / LR_ENODEV otherwise. */
int lr_modbus_flush(lr_modbus *m, int timeout_ms, lr_err *e);

void lr_modbus_get_counters(const lr_modbus *m, lr_modbus_counters *out);

#endif
