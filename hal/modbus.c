/* Modbus master back end: see hal/modbus.h for the loop design. */
#include "hal/modbus.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <modbus.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "hal/dev_impl.h"

#define MAX_INPUTS 16
#define MS 1000000LL

const lr_opt lr_modbus_opts[] = {
    [LR_MODBUS_OPT_URL] = {"url", LR_OPT_STRING, .required = true,
                           .help = "tcp://HOST:PORT or rtu:DEVICE?baud=..."},
    [LR_MODBUS_OPT_POLL_MS] = {"poll_ms", LR_OPT_INT, 1, 60000, 50,
                               .help = "input polling period"},
    [LR_MODBUS_OPT_TIMEOUT_MS] = {"timeout_ms", LR_OPT_INT, 1, 10000, 100,
                                  .help = "bound of a whole answer (and of the TCP connect)"},
    [LR_MODBUS_OPT_BYTE_TIMEOUT_MS] = {"byte_timeout_ms", LR_OPT_INT, 1, 10000, 50,
                                       .help = "RTU: gap that ends a frame"},
    [LR_MODBUS_OPT_MAX_TIMEOUTS] = {"max_timeouts", LR_OPT_INT, 1, 1000, 3,
                                    .help = "consecutive timeouts that drop the link"},
    [LR_MODBUS_OPT_INPUTS] = {"inputs", LR_OPT_LIST, .help = "panel registers (below)"},
    [LR_MODBUS_OPT_LAMP] = {"lamp", LR_OPT_OBJECT, .help = "the lamp driver's register (below)"},
    LR_OPT_END,
};

static const char *const REG_TYPES[] = {"holding", "input", NULL}; /* lr_modbus_reg_type */

/* The fields an input and the output share. Unit ids: 1..247 on a serial line, TCP also
 * 248..255 (checked per transport below); registers 0..65535 counted from base (below). */
#define CH_UNIT {"unit", LR_OPT_INT, 1, 255, 1, .help = "unit (slave) id"}
#define CH_BASE(help_) {"base", LR_OPT_INT, 0, 1, 0, .help = help_}
/* reg's range is that of the address reg - base. */
#define CH_REG(help_) {"reg", LR_OPT_INT, 0, 65535, 0, .required = true, .help = help_}
#define CH_RAW_MIN {"raw_min", LR_OPT_INT, 0, 65535, 0, .help = "raw value of 0"}
#define CH_RAW_MAX(dflt_) {"raw_max", LR_OPT_INT, 0, 65535, dflt_, .help = "raw value of 1 (> raw_min)"}

const lr_opt lr_modbus_input_opts[] = {
    [LR_MODBUS_IN_CONTROL] = {"control", LR_OPT_STRING, .dflt_text = "dimmer",
                              .help = "event control name"},
    [LR_MODBUS_IN_UNIT] = CH_UNIT,
    [LR_MODBUS_IN_REG] = CH_REG("register number; the range is of reg - base"),
    [LR_MODBUS_IN_BASE] = CH_BASE("1: 1-based numbering as panel manuals print it"),
    [LR_MODBUS_IN_TYPE] = {"type", LR_OPT_ENUM, .dflt = LR_MODBUS_HOLDING, .names = REG_TYPES,
                           .help = "FC 3 or FC 4"},
    [LR_MODBUS_IN_RAW_MIN] = CH_RAW_MIN,
    [LR_MODBUS_IN_RAW_MAX] = CH_RAW_MAX(1000),
    LR_OPT_END,
};

const lr_opt lr_modbus_output_opts[] = {
    [LR_MODBUS_OUT_UNIT] = CH_UNIT,
    [LR_MODBUS_OUT_REG] = CH_REG("holding register; the range is of reg - base"),
    [LR_MODBUS_OUT_BASE] = CH_BASE("as for inputs"),
    [LR_MODBUS_OUT_RAW_MIN] = CH_RAW_MIN,
    [LR_MODBUS_OUT_RAW_MAX] = CH_RAW_MAX(255),
    [LR_MODBUS_OUT_MULTIPLE] = {"multiple", LR_OPT_BOOL, .dflt = 0,
                                .help = "write with FC 16 instead of FC 6"},
    LR_OPT_END,
};

typedef struct channel {
    char what[96];   /* "input 'dimmer' (unit 1, holding register 0)" */
    bool failing;    /* an error was logged; the next success logs the recovery */
    char last[256];  /* the problem last logged: the same one again is only counted */
} channel;

typedef struct input {
    char control[LR_EVENT_NAME_MAX];
    int unit, addr;
    lr_modbus_reg_type type;
    int raw_min, raw_max;
    int last_raw;
    bool have; /* last_raw valid since the last (re)connect */
    channel ch;
} input;

typedef struct output {
    bool enabled;
    int unit, addr;
    int raw_min, raw_max;
    bool multiple;
    int want;     /* raw value to be written, -1 none yet */
    int acked;    /* raw value the driver acknowledged, -1 none */
    int rejected; /* raw value answered with an exception: not resent until the level changes */
    channel ch;
} output;

enum { IDLE, WAIT };
enum { REQ_READ, REQ_WRITE };

/* Kinds of log line a peer can cause; each is rate-limited on its own (LOG_BURST lines per
 * LOG_WINDOW_NS per device), since a peer answering at random varies the text of every line. */
enum { K_TIMEOUT, K_CRC, K_EXCEPTION, K_BAD, K_STALE, K_RECOVERY, N_KINDS };
#define LOG_BURST 4
#define LOG_WINDOW_NS (10 * 1000 * MS)

/* Two of the longest frames: a partial one behind a complete one. */
#define RX_MAX (2 * MODBUS_MAX_ADU_LENGTH)

struct lr_modbus {
    lr_dev base;
    lr_modbus_url url;
    char url_text[LR_MODBUS_HOST_MAX + 64];
    modbus_t *ctx; /* connect, serial setup, close and tcflush only: the frames are ours */
    int fd;
    input in[MAX_INPUTS];
    int n_in;
    output out;
    int64_t poll_ns, timeout_ns;
    int64_t byte_timeout_ns;
    int max_timeouts;
    int64_t gap_ns; /* RTU: silence owed to the bus between frames (3.5 characters) */
    /* received bytes not yet framed */
    uint8_t rx[RX_MAX];
    int rx_len;
    int64_t rx_last_ns; /* when the last byte came */
    /* the transaction in flight */
    int phase;
    int req;       /* REQ_READ / REQ_WRITE */
    int req_input; /* for REQ_READ */
    int req_raw;   /* for REQ_WRITE */
    int req_unit, req_func, req_addr;
    int req_tid;   /* TCP: the MBAP transaction id sent */
    uint16_t next_tid;
    int64_t deadline; /* of the whole transaction: send + timeout_ms, however the bytes drip */
    int64_t earliest_send;
    /* polling */
    int next_input;
    int64_t next_cycle;
    int consecutive_timeouts;
    lr_log_limit limit[N_KINDS];
    lr_modbus_counters c;
};

static channel *req_channel(lr_modbus *m)
{
    return m->req == REQ_WRITE ? &m->out.ch : &m->in[m->req_input].ch;
}

/* One line of kind `kind`, unless that kind is over its rate; the next line let through
 * says how many were dropped. */
static void note(lr_modbus *m, int kind, lr_log_level level, int64_t now_ns, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));
static void note(lr_modbus *m, int kind, lr_log_level level, int64_t now_ns, const char *fmt, ...)
{
    unsigned dropped;
    if (!lr_log_limit_take(&m->limit[kind], now_ns, &dropped))
        return;
    char msg[LR_ERR_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (dropped)
        lr_dev_log(&m->base, level, "%s (%u similar lines dropped)", msg, dropped);
    else
        lr_dev_log(&m->base, level, "%s", msg);
}

/* Logs a channel problem once, until the channel works again or fails differently; and a
 * peer varying its answers still gets at most LOG_BURST lines of each kind per window. */
static void ch_fail(lr_modbus *m, channel *ch, int kind, int64_t now_ns, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));
static void ch_fail(lr_modbus *m, channel *ch, int kind, int64_t now_ns, const char *fmt, ...)
{
    char msg[sizeof ch->last];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (ch->failing && strcmp(msg, ch->last) == 0)
        return;
    ch->failing = true;
    memcpy(ch->last, msg, sizeof msg);
    note(m, kind, LR_LOG_WARN, now_ns, "%s: %s: %s (counted; repeats not logged)", m->url_text,
         ch->what, msg);
}

static void ch_ok(lr_modbus *m, channel *ch, int64_t now_ns)
{
    if (!ch->failing)
        return;
    ch->failing = false;
    ch->last[0] = '\0';
    note(m, K_RECOVERY, LR_LOG_INFO, now_ns, "%s: %s: answering again", m->url_text, ch->what);
}

static const char *exception_name(int code)
{
    switch (code) {
    case 1: return "illegal function";
    case 2: return "illegal data address";
    case 3: return "illegal data value";
    case 4: return "server device failure";
    case 5: return "acknowledge";
    case 6: return "server device busy";
    case 8: return "memory parity error";
    case 10: return "gateway path unavailable";
    case 11: return "gateway target device failed to respond";
    }
    return "unknown exception";
}

static bool errno_means_missing(int err)
{
    return err == ENOENT || err == ENODEV || err == ENXIO || err == ECONNREFUSED ||
           err == EHOSTUNREACH || err == ENETUNREACH || err == EHOSTDOWN;
}

/* Modbus over serial line v1.02, 6.2.2: CRC-16 (polynomial 0xA001 reflected, init 0xFFFF),
 * sent low byte first. */
static uint16_t crc16(const uint8_t *b, int n)
{
    uint16_t crc = 0xffff;
    for (int i = 0; i < n; i++) {
        crc ^= b[i];
        for (int k = 0; k < 8; k++)
            crc = crc & 1 ? (uint16_t)((crc >> 1) ^ 0xa001) : (uint16_t)(crc >> 1);
    }
    return crc;
}

static void mb_close(lr_dev *d)
{
    lr_modbus *m = (lr_modbus *)d;
    if (m->ctx) {
        modbus_close(m->ctx);
        modbus_free(m->ctx);
    }
    m->ctx = NULL;
    m->fd = -1;
    m->phase = IDLE;
    m->rx_len = 0;
}

static int mb_open(lr_dev *d, int64_t now_ns, lr_err *e)
{
    lr_modbus *m = (lr_modbus *)d;
    const lr_modbus_url *u = &m->url;
    errno = 0;
    if (u->transport == LR_MODBUS_TCP) {
        char port[16];
        snprintf(port, sizeof port, "%d", u->port);
        m->ctx = modbus_new_tcp_pi(u->host, port);
    } else {
        m->ctx = modbus_new_rtu(u->device, u->baud, u->parity, u->data_bits, u->stop_bits);
    }
    if (!m->ctx)
        return lr_err_set(e, LR_EINVAL, "%s: cannot set up libmodbus: %s", m->url_text,
                          modbus_strerror(errno));
    /* The response timeout bounds modbus_connect on TCP; no other libmodbus call waits. */
    uint32_t to_us = (uint32_t)(m->timeout_ns / 1000);
    modbus_set_error_recovery(m->ctx, MODBUS_ERROR_RECOVERY_NONE);
    modbus_set_response_timeout(m->ctx, to_us / 1000000u, to_us % 1000000u);
    if (modbus_connect(m->ctx) == -1) {
        int err = errno;
        int code = errno_means_missing(err) ? LR_ENODEV : LR_EIO;
        const char *why = err == EINPROGRESS ? "connect timed out" : modbus_strerror(err);
        modbus_free(m->ctx);
        m->ctx = NULL;
        return lr_err_set(e, code, "%s: cannot connect: %s", m->url_text, why);
    }
    if (u->transport == LR_MODBUS_RTU && u->rs485 &&
        modbus_rtu_set_serial_mode(m->ctx, MODBUS_RTU_RS485) == -1) {
        int err = errno;
        mb_close(d);
        return lr_err_set(e, LR_EUNSUPPORTED,
                          "%s: rs485=1 but the port refuses RS-485 mode (TIOCSRS485): %s",
                          m->url_text, modbus_strerror(err));
    }
    m->fd = modbus_get_socket(m->ctx);
    int fl = fcntl(m->fd, F_GETFL);
    if (fl >= 0)
        fcntl(m->fd, F_SETFL, fl | O_NONBLOCK);
    if (u->transport == LR_MODBUS_RTU)
        modbus_flush(m->ctx); /* bytes left from before we opened the port */
    m->phase = IDLE;
    m->rx_len = 0;
    m->next_input = 0;
    m->next_cycle = now_ns;
    m->earliest_send = now_ns;
    m->consecutive_timeouts = 0;
    /* After a reconnect: report every input again and resend the level (the driver may have
     * restarted with its own default). */
    for (int i = 0; i < m->n_in; i++)
        m->in[i].have = false;
    m->out.acked = -1;
    m->out.rejected = -1;
    m->c.connects++;
    return LR_OK;
}

/* Sends unit + PDU (raw[0..len)) as one ADU: MBAP header on TCP (with a fresh transaction id),
 * CRC on RTU. Small frames on a non-blocking socket or tty: a short write is an I/O error. */
static bool send_request(lr_modbus *m, int64_t now_ns, const uint8_t *raw, int len)
{
    uint8_t adu[7 + 16];
    int n;
    m->req_unit = raw[0];
    m->req_func = raw[1];
    m->req_addr = raw[2] << 8 | raw[3];
    ssize_t w;
    if (m->url.transport == LR_MODBUS_TCP) {
        uint16_t tid = m->next_tid++;
        m->req_tid = tid;
        adu[0] = (uint8_t)(tid >> 8);
        adu[1] = (uint8_t)tid;
        adu[2] = adu[3] = 0; /* protocol: Modbus */
        adu[4] = (uint8_t)(len >> 8);
        adu[5] = (uint8_t)len;
        memcpy(adu + 6, raw, (size_t)len);
        n = 6 + len;
        w = send(m->fd, adu, (size_t)n, MSG_NOSIGNAL);
    } else {
        memcpy(adu, raw, (size_t)len);
        uint16_t crc = crc16(raw, len);
        adu[len] = (uint8_t)crc;
        adu[len + 1] = (uint8_t)(crc >> 8);
        n = len + 2;
        w = write(m->fd, adu, (size_t)n);
    }
    if (w != n) {
        int err = w < 0 ? errno : EAGAIN;
        m->c.io_errors++;
        lr_dev_lost(&m->base, LR_EIO, now_ns, "%s: send failed: %s", m->url_text,
                    err == EPIPE || err == ECONNRESET ? "connection closed by the server"
                                                      : strerror(err));
        return false;
    }
    m->c.requests++;
    m->phase = WAIT;
    m->deadline = now_ns + m->timeout_ns;
    return true;
}

static bool send_read(lr_modbus *m, int i, int64_t now_ns)
{
    const input *in = &m->in[i];
    uint8_t raw[6] = {(uint8_t)in->unit,
                      in->type == LR_MODBUS_INPUT ? MODBUS_FC_READ_INPUT_REGISTERS
                                                  : MODBUS_FC_READ_HOLDING_REGISTERS,
                      (uint8_t)(in->addr >> 8), (uint8_t)in->addr, 0, 1};
    m->req = REQ_READ;
    m->req_input = i;
    return send_request(m, now_ns, raw, 6);
}

static bool send_write(lr_modbus *m, int64_t now_ns)
{
    const output *o = &m->out;
    uint8_t raw[9];
    int len;
    raw[0] = (uint8_t)o->unit;
    raw[2] = (uint8_t)(o->addr >> 8);
    raw[3] = (uint8_t)o->addr;
    if (o->multiple) {
        raw[1] = MODBUS_FC_WRITE_MULTIPLE_REGISTERS;
        raw[4] = 0;
        raw[5] = 1; /* quantity */
        raw[6] = 2; /* byte count */
        raw[7] = (uint8_t)(o->want >> 8);
        raw[8] = (uint8_t)o->want;
        len = 9;
    } else {
        raw[1] = MODBUS_FC_WRITE_SINGLE_REGISTER;
        raw[4] = (uint8_t)(o->want >> 8);
        raw[5] = (uint8_t)o->want;
        len = 6;
    }
    m->req = REQ_WRITE;
    m->req_raw = o->want;
    return send_request(m, now_ns, raw, len);
}

static bool write_pending(const lr_modbus *m)
{
    const output *o = &m->out;
    return o->enabled && o->want >= 0 && o->want != o->acked && o->want != o->rejected;
}

/* Starts the next request when the link is idle: a pending level first (the lamp is what the
 * designer looks at), then the next input of the current poll cycle. */
static void start_next(lr_modbus *m, int64_t now_ns)
{
    if (m->phase != IDLE || now_ns < m->earliest_send)
        return;
    if (write_pending(m)) {
        send_write(m, now_ns);
        return;
    }
    if (m->n_in == 0)
        return;
    if (m->next_input == 0) {
        if (now_ns < m->next_cycle)
            return;
        /* A late loop does not cause a burst of catch-up polls. */
        m->next_cycle = m->next_cycle + m->poll_ns > now_ns ? m->next_cycle + m->poll_ns
                                                            : now_ns + m->poll_ns;
    }
    int i = m->next_input;
    m->next_input = (i + 1) % m->n_in;
    send_read(m, i, now_ns);
}

/* RTU frames have no length field and no transaction id: after a broken or missing answer
 * the bytes on the line are dropped (a late answer must not be taken for the next one). TCP
 * keeps its bytes: the MBAP length keeps the stream framed, and the transaction id tells a
 * late answer from the current one. */
static void rtu_resync(lr_modbus *m)
{
    if (m->url.transport != LR_MODBUS_RTU)
        return;
    modbus_flush(m->ctx);
    m->rx_len = 0;
}

/* The transaction ends: the bus silence counts from now, the end of the answer. */
static void end_transaction(lr_modbus *m, int64_t now_ns)
{
    m->phase = IDLE;
    m->earliest_send = m->gap_ns ? lr_now_ns() + m->gap_ns : now_ns;
}

static void handle_timeout(lr_modbus *m, int64_t now_ns)
{
    end_transaction(m, now_ns);
    m->c.timeouts++;
    m->consecutive_timeouts++;
    if (m->rx_len > 0)
        ch_fail(m, req_channel(m), K_TIMEOUT, now_ns,
                "answer incomplete after %lld ms (%d bytes so far)",
                (long long)(m->timeout_ns / MS), m->rx_len);
    else
        ch_fail(m, req_channel(m), K_TIMEOUT, now_ns, "no answer within %lld ms",
                (long long)(m->timeout_ns / MS));
    if (m->consecutive_timeouts >= m->max_timeouts) {
        lr_dev_lost(&m->base, LR_ETIMEOUT, now_ns, "%s: no answer to %d requests in a row",
                    m->url_text, m->consecutive_timeouts);
        return;
    }
    rtu_resync(m);
}

/* Length of the frame at the start of b[0..n): > 0 complete, 0 incomplete, -1 unframeable
 * (TCP: a header that is not Modbus; RTU: a function whose answer length is unknown). */
static int frame_length(const lr_modbus *m, const uint8_t *b, int n)
{
    int len;
    if (m->url.transport == LR_MODBUS_TCP) {
        if (n < 7)
            return 0;
        int proto = b[2] << 8 | b[3], mlen = b[4] << 8 | b[5];
        if (proto != 0 || mlen < 2 || mlen > MODBUS_TCP_MAX_ADU_LENGTH - 6)
            return -1;
        len = 6 + mlen;
    } else {
        if (n < 2)
            return 0;
        int fc = b[1];
        if (fc & 0x80)
            len = 5;
        else if (fc == MODBUS_FC_READ_HOLDING_REGISTERS || fc == MODBUS_FC_READ_INPUT_REGISTERS)
            len = n < 3 ? 0 : 5 + b[2];
        else if (fc == MODBUS_FC_WRITE_SINGLE_REGISTER || fc == MODBUS_FC_WRITE_MULTIPLE_REGISTERS)
            len = 8;
        else
            return -1;
        if (len == 0)
            return 0;
    }
    return n >= len ? len : 0;
}

/* The answer's PDU (function code first) to the request in flight. */
static void handle_answer(lr_modbus *m, int unit, const uint8_t *p, int pl, int64_t now_ns)
{
    end_transaction(m, now_ns);
    channel *ch = req_channel(m);
    m->consecutive_timeouts = 0;
    int func = p[0];
    if (unit != m->req_unit) {
        m->c.bad_responses++;
        ch_fail(m, ch, K_BAD, now_ns, "answer from unit %d", unit);
        return;
    }
    if (func == (m->req_func | 0x80) && pl == 2) {
        int code = p[1];
        m->c.exceptions++;
        m->c.last_exception = (uint64_t)code;
        ch_fail(m, ch, K_EXCEPTION, now_ns, "exception %d (%s)", code, exception_name(code));
        if (m->req == REQ_WRITE)
            m->out.rejected = m->req_raw;
        return;
    }
    if (func != m->req_func) {
        m->c.bad_responses++;
        ch_fail(m, ch, K_BAD, now_ns, "answer to function %d, asked %d", func, m->req_func);
        return;
    }
    if (m->req == REQ_READ) {
        if (pl != 4 || p[1] != 2) {
            m->c.bad_responses++;
            ch_fail(m, ch, K_BAD, now_ns, "read answer with %d data bytes, expected 2",
                    pl >= 2 ? p[1] : 0);
            return;
        }
        input *in = &m->in[m->req_input];
        int raw = p[2] << 8 | p[3];
        m->c.responses++;
        lr_dev_proven(&m->base);
        ch_ok(m, ch, now_ns);
        if (!in->have || raw != in->last_raw) {
            in->have = true;
            in->last_raw = raw;
            double v = (double)(raw - in->raw_min) / (double)(in->raw_max - in->raw_min);
            v = v < 0 ? 0 : v > 1 ? 1 : v;
            lr_dev_emit(&m->base, NULL, in->control, LR_EV_ABSOLUTE, v, now_ns);
        }
        return;
    }
    /* Write echo: FC 6 echoes address and value, FC 16 address and quantity. */
    int echo_addr = pl == 5 ? (p[1] << 8 | p[2]) : -1;
    int echo_val = pl == 5 ? (p[3] << 8 | p[4]) : -1;
    int expect_val = m->out.multiple ? 1 : m->req_raw;
    if (echo_addr != m->req_addr || echo_val != expect_val) {
        m->c.bad_responses++;
        ch_fail(m, ch, K_BAD, now_ns, "write echo does not match the request");
        return;
    }
    m->c.responses++;
    m->c.writes++;
    m->out.acked = m->req_raw;
    lr_dev_proven(&m->base);
    ch_ok(m, ch, now_ns);
}

/* One complete frame f[0..n). */
static void handle_frame(lr_modbus *m, const uint8_t *f, int n, int64_t now_ns)
{
    if (m->url.transport == LR_MODBUS_TCP) {
        int tid = f[0] << 8 | f[1];
        if (m->phase != WAIT || tid != m->req_tid) {
            /* An answer to an earlier request (one that timed out): never the current one. */
            m->c.stale++;
            if (m->phase == WAIT)
                note(m, K_STALE, LR_LOG_WARN, now_ns,
                     "%s: stale answer dropped (transaction %d, waiting for %d; counted)",
                     m->url_text, tid, m->req_tid);
            else
                note(m, K_STALE, LR_LOG_WARN, now_ns,
                     "%s: stale answer dropped (transaction %d, nothing asked; counted)",
                     m->url_text, tid);
            return;
        }
        handle_answer(m, f[6], f + 7, n - 7, now_ns);
        return;
    }
    if (m->phase != WAIT) {
        m->c.bad_responses++; /* stray bytes on the bus */
        rtu_resync(m);
        return;
    }
    uint16_t crc = crc16(f, n - 2);
    if (f[n - 2] != (uint8_t)crc || f[n - 1] != (uint8_t)(crc >> 8)) {
        end_transaction(m, now_ns);
        m->c.crc_errors++;
        ch_fail(m, req_channel(m), K_CRC, now_ns, "answer with a bad CRC");
        rtu_resync(m);
        return;
    }
    handle_answer(m, f[0], f + 1, n - 3, now_ns);
}

/* Frames what rx holds; false when the device was dropped. */
static bool parse_rx(lr_modbus *m, int64_t now_ns)
{
    int off = 0;
    while (off < m->rx_len) {
        int n = frame_length(m, m->rx + off, m->rx_len - off);
        if (n == 0)
            break;
        if (n < 0) {
            m->c.bad_responses++;
            if (m->url.transport == LR_MODBUS_TCP) {
                /* Without a valid MBAP header the stream cannot be framed again. */
                m->c.io_errors++;
                lr_dev_lost(&m->base, LR_EPROTO, now_ns,
                            "%s: not a Modbus/TCP answer (bad MBAP header); reconnecting",
                            m->url_text);
                return false;
            }
            if (m->phase == WAIT) {
                end_transaction(m, now_ns);
                ch_fail(m, req_channel(m), K_BAD, now_ns, "malformed answer");
            }
            rtu_resync(m);
            return true;
        }
        handle_frame(m, m->rx + off, n, now_ns);
        if (m->base.state != LR_DEV_OPEN)
            return false;
        if (m->rx_len == 0)
            return true; /* resynchronized: the rest was dropped */
        off += n;
    }
    memmove(m->rx, m->rx + off, (size_t)(m->rx_len - off));
    m->rx_len -= off;
    return true;
}

/* Reads what is there without waiting; *got: bytes read. 0: fine; 1: end of stream (TCP);
 * -1: error (errno). */
static int rx_fill(lr_modbus *m, int64_t now_ns, int *got)
{
    *got = 0;
    for (;;) {
        if (m->rx_len == RX_MAX)
            return 0; /* parse_rx makes room: a complete frame is always shorter */
        ssize_t n = read(m->fd, m->rx + m->rx_len, (size_t)(RX_MAX - m->rx_len));
        if (n > 0) {
            m->rx_len += (int)n;
            *got += (int)n;
            m->rx_last_ns = now_ns;
            continue;
        }
        if (n == 0) /* TCP: closed. A tty with VMIN = VTIME = 0 (libmodbus): nothing there. */
            return m->url.transport == LR_MODBUS_TCP ? 1 : 0;
        if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)
            return 0;
        return -1;
    }
}

static void mb_dispatch(lr_dev *d, int64_t now_ns)
{
    lr_modbus *m = (lr_modbus *)d;
    struct pollfd p = {.fd = m->fd, .events = POLLIN};
    if (poll(&p, 1, 0) < 0)
        p.revents = 0;
    if (p.revents & (POLLIN | POLLHUP | POLLERR)) {
        /* Bounded work: at most RX_MAX bytes per call, however fast the peer sends. */
        int got;
        int r = rx_fill(m, now_ns, &got);
        int err = errno;
        if (!parse_rx(m, now_ns))
            return; /* answers that came before the end are taken first */
        if (r != 0 || (got == 0 && (p.revents & (POLLHUP | POLLERR)))) {
            m->c.io_errors++;
            lr_dev_lost(d, LR_EIO, now_ns, "%s: %s", m->url_text,
                        r == 1 || (r < 0 && err == ECONNRESET) ? "connection closed by the server"
                        : r < 0                                ? strerror(err)
                                                               : "connection lost");
            return;
        }
    }
    /* RTU: a gap longer than byte_timeout_ms inside a frame ends it. */
    if (m->url.transport == LR_MODBUS_RTU && m->rx_len > 0 &&
        now_ns - m->rx_last_ns >= m->byte_timeout_ns) {
        if (m->phase == WAIT) {
            handle_timeout(m, now_ns);
        } else {
            m->c.bad_responses++;
            rtu_resync(m);
        }
    }
    if (d->state != LR_DEV_OPEN)
        return;
    if (m->phase == WAIT && now_ns >= m->deadline)
        handle_timeout(m, now_ns);
    if (d->state == LR_DEV_OPEN)
        start_next(m, now_ns);
}

static int mb_pollfds(lr_dev *d, struct pollfd *fds, int max)
{
    lr_modbus *m = (lr_modbus *)d;
    if (max > 0)
        fds[0] = (struct pollfd){.fd = m->fd, .events = POLLIN};
    return 1;
}

static int64_t mb_next_deadline(lr_dev *d)
{
    lr_modbus *m = (lr_modbus *)d;
    int64_t t;
    if (m->phase == WAIT)
        t = m->deadline;
    else if (write_pending(m) || (m->n_in && m->next_input != 0))
        t = m->earliest_send;
    else if (m->n_in == 0)
        t = LR_NO_DEADLINE;
    else
        t = m->next_cycle > m->earliest_send ? m->next_cycle : m->earliest_send;
    if (m->url.transport == LR_MODBUS_RTU && m->rx_len > 0 &&
        m->rx_last_ns + m->byte_timeout_ns < t)
        t = m->rx_last_ns + m->byte_timeout_ns;
    return t;
}

static void mb_destroy(lr_dev *d) { free(d); }

static const lr_dev_ops MODBUS_OPS = {
    .kind = "modbus",
    .open = mb_open,
    .close = mb_close,
    .pollfds = mb_pollfds,
    .dispatch = mb_dispatch,
    .next_deadline = mb_next_deadline,
    .destroy = mb_destroy,
    .open_needs_proof = true, /* a TCP peer may accept and close at once */
};

/* Validates unit, register/base and raw range of one channel; fills unit/addr. */
static int check_channel(lr_modbus *m, const char *field, int unit, int reg, int base,
                         int raw_min, int raw_max, int *unit_out, int *addr_out, lr_err *e)
{
    const char *pf = m->base.prefix;
    const lr_opt *uo = &lr_modbus_input_opts[LR_MODBUS_IN_UNIT];
    const lr_opt *bo = &lr_modbus_input_opts[LR_MODBUS_IN_BASE];
    const lr_opt *ro = &lr_modbus_input_opts[LR_MODBUS_IN_RAW_MIN];
    const lr_opt *rg = &lr_modbus_input_opts[LR_MODBUS_IN_REG];
    int u = (int)lr_opt_or_default(uo, unit);
    int umax = m->url.transport == LR_MODBUS_TCP ? (int)uo->hi : 247;
    if (u < 1 || u > umax)
        return lr_err_set(e, LR_EINVAL, "%s: %s.unit %d is not 1..%d", pf, field, unit, umax);
    if (!lr_opt_in_range(bo, base))
        return lr_err_set(e, LR_EINVAL, "%s: %s.base %d is not 0 or 1", pf, field, base);
    int addr = reg - base;
    if (!lr_opt_in_range(rg, addr))
        return lr_err_set(e, LR_EINVAL, "%s: %s.reg %d is not %ld..%ld (base %d)", pf, field, reg,
                          rg->lo + base, rg->hi + base, base);
    if (raw_min < ro->lo || raw_max > ro->hi || raw_min >= raw_max)
        return lr_err_set(e, LR_EINVAL, "%s: %s: raw range %d..%d is not within 0..65535 and "
                          "increasing", pf, field, raw_min, raw_max);
    *unit_out = u;
    *addr_out = addr;
    return LR_OK;
}

static int configure(lr_modbus *m, const lr_modbus_desc *desc, lr_err *e)
{
    const char *pf = m->base.prefix;
    int rc = lr_modbus_url_parse(desc->url, &m->url, e);
    if (rc != LR_OK)
        return lr_err_prefix(e, "%s", pf);
    lr_modbus_url_format(&m->url, m->url_text, sizeof m->url_text);
    snprintf(m->base.ident, sizeof m->base.ident, "%s", m->url_text);
    if (desc->n_inputs < 0 || desc->n_inputs > MAX_INPUTS || (desc->n_inputs && !desc->inputs))
        return lr_err_set(e, LR_EINVAL, "%s: n_inputs %d is not 0..%d", pf, desc->n_inputs,
                          MAX_INPUTS);
    if (desc->n_inputs == 0 && !desc->output.enabled)
        return lr_err_set(e, LR_EINVAL, "%s: neither inputs nor an output configured", pf);
    char field[32];
    for (int i = 0; i < desc->n_inputs; i++) {
        const lr_modbus_input *c = &desc->inputs[i];
        input *in = &m->in[i];
        snprintf(field, sizeof field, "inputs[%d]", i);
        const char *ctl = c->control && c->control[0] ? c->control : "dimmer";
        if (strlen(ctl) >= LR_EVENT_NAME_MAX)
            return lr_err_set(e, LR_EINVAL, "%s: %s.control '%s' too long", pf, field, ctl);
        for (int k = 0; k < i; k++)
            if (strcmp(m->in[k].control, ctl) == 0)
                return lr_err_set(e, LR_EINVAL, "%s: %s.control '%s' used twice", pf, field, ctl);
        if (c->type != LR_MODBUS_HOLDING && c->type != LR_MODBUS_INPUT)
            return lr_err_set(e, LR_EINVAL, "%s: %s.type %d unknown", pf, field, (int)c->type);
        in->raw_min = c->raw_min;
        in->raw_max = (int)lr_opt_or_default(&lr_modbus_input_opts[LR_MODBUS_IN_RAW_MAX],
                                             c->raw_max);
        rc = check_channel(m, field, c->unit, c->reg, c->base, in->raw_min, in->raw_max,
                           &in->unit, &in->addr, e);
        if (rc != LR_OK)
            return rc;
        strcpy(in->control, ctl);
        in->type = c->type;
        snprintf(in->ch.what, sizeof in->ch.what, "input '%s' (unit %d, %s register %d)", ctl,
                 in->unit, c->type == LR_MODBUS_INPUT ? "input" : "holding", in->addr);
        m->n_in = i + 1;
    }
    output *o = &m->out;
    o->want = o->acked = o->rejected = -1;
    if (desc->output.enabled) {
        const lr_modbus_output *c = &desc->output;
        o->enabled = true;
        o->raw_min = c->raw_min;
        o->raw_max = (int)lr_opt_or_default(&lr_modbus_output_opts[LR_MODBUS_OUT_RAW_MAX],
                                            c->raw_max);
        o->multiple = c->multiple;
        rc = check_channel(m, "output", c->unit, c->reg, c->base, o->raw_min, o->raw_max,
                           &o->unit, &o->addr, e);
        if (rc != LR_OK)
            return rc;
        snprintf(o->ch.what, sizeof o->ch.what, "lamp driver (unit %d, holding register %d)",
                 o->unit, o->addr);
    }
    const lr_opt *op = lr_modbus_opts;
    if (!lr_opt_hal_ok(&op[LR_MODBUS_OPT_POLL_MS], desc->poll_ms) ||
        !lr_opt_hal_ok(&op[LR_MODBUS_OPT_TIMEOUT_MS], desc->timeout_ms) ||
        !lr_opt_hal_ok(&op[LR_MODBUS_OPT_BYTE_TIMEOUT_MS], desc->byte_timeout_ms) ||
        !lr_opt_hal_ok(&op[LR_MODBUS_OPT_MAX_TIMEOUTS], desc->max_timeouts))
        return lr_err_set(e, LR_EINVAL,
                          "%s: poll_ms %d / timeout_ms %d / byte_timeout_ms %d / max_timeouts %d "
                          "out of range",
                          pf, desc->poll_ms, desc->timeout_ms, desc->byte_timeout_ms,
                          desc->max_timeouts);
    m->poll_ns = lr_opt_or_default(&op[LR_MODBUS_OPT_POLL_MS], desc->poll_ms) * MS;
    m->timeout_ns = lr_opt_or_default(&op[LR_MODBUS_OPT_TIMEOUT_MS], desc->timeout_ms) * MS;
    m->byte_timeout_ns = lr_opt_or_default(&op[LR_MODBUS_OPT_BYTE_TIMEOUT_MS],
                                           desc->byte_timeout_ms) * MS;
    m->max_timeouts = (int)lr_opt_or_default(&op[LR_MODBUS_OPT_MAX_TIMEOUTS],
                                             desc->max_timeouts);
    if (m->url.transport == LR_MODBUS_RTU) {
        /* Modbus over serial line v1.02, 2.5.1.1: 3.5 character times of silence between
         * frames, fixed at 1.75 ms above 19200 baud. A character is 11 bits on the wire. */
        int64_t t35 = (int64_t)(3.5 * 11 * 1e9 / m->url.baud);
        m->gap_ns = m->url.baud > 19200 ? 1750000 : t35;
    }
    return LR_OK;
}

int lr_modbus_create(const lr_modbus_desc *desc, lr_modbus **out, lr_err *e)
{
    *out = NULL;
    lr_modbus *m = calloc(1, sizeof *m);
    if (!m)
        return lr_err_set(e, LR_ENOMEM, "modbus: out of memory");
    m->fd = -1;
    for (int k = 0; k < N_KINDS; k++)
        lr_log_limit_init(&m->limit[k], LOG_BURST, LOG_WINDOW_NS);
    int rc = lr_dev_init(&m->base, &MODBUS_OPS, &desc->dev, e);
    if (rc == LR_OK)
        rc = configure(m, desc, e);
    if (rc == LR_OK)
        rc = lr_dev_start(&m->base, desc->dev.required, lr_now_ns(), e);
    if (rc != LR_OK) {
        mb_close(&m->base);
        free(m);
        return rc;
    }
    *out = m;
    return LR_OK;
}

void lr_modbus_destroy(lr_modbus *m)
{
    if (m)
        lr_dev_destroy(&m->base);
}

lr_dev *lr_modbus_dev(lr_modbus *m) { return &m->base; }

int lr_modbus_write_level(lr_modbus *m, double level01)
{
    output *o = &m->out;
    if (!o->enabled)
        return LR_EUNSUPPORTED;
    if (isnan(level01))
        return LR_EINVAL;
    double l = level01 < 0 ? 0 : level01 > 1 ? 1 : level01;
    o->want = (int)lround(o->raw_min + l * (o->raw_max - o->raw_min));
    /* Send now when the link is idle: the lamp follows the knob without waiting for a poll. */
    if (m->base.state == LR_DEV_OPEN && m->phase == IDLE)
        start_next(m, lr_now_ns());
    return LR_OK;
}

int lr_modbus_output_raw(const lr_modbus *m) { return m->out.want; }

bool lr_modbus_output_synced(const lr_modbus *m)
{
    return m->out.enabled && m->out.want >= 0 && m->out.acked == m->out.want;
}

int lr_modbus_flush(lr_modbus *m, int timeout_ms, lr_err *e)
{
    int64_t now = lr_now_ns();
    int64_t end = now + (int64_t)timeout_ms * MS;
    lr_dev_retry_now(&m->base, now);
    while (!lr_modbus_output_synced(m)) {
        if (!m->out.enabled || m->out.want < 0)
            return LR_OK;
        if (m->out.want == m->out.rejected)
            return lr_err_set(e, LR_EPROTO, "%s: %s: %s rejected the level (raw %d)",
                              m->base.prefix, m->url_text, m->out.ch.what, m->out.want);
        now = lr_now_ns();
        if (now >= end)
            break;
        int64_t t = lr_dev_next_deadline(&m->base);
        if (t > end)
            t = end;
        int wait_ms = t <= now ? 0 : (int)((t - now + MS - 1) / MS);
        struct pollfd p;
        int n = lr_dev_pollfds(&m->base, &p, 1);
        poll(&p, (nfds_t)n, wait_ms);
        lr_dev_dispatch(&m->base, lr_now_ns());
    }
    if (lr_modbus_output_synced(m))
        return LR_OK;
    return lr_err_set(e, m->base.state == LR_DEV_OPEN ? LR_ETIMEOUT : LR_ENODEV,
                      "%s: %s: level (raw %d) not acknowledged within %d ms (%s)", m->base.prefix,
                      m->url_text, m->out.want, timeout_ms, lr_dev_state_name(m->base.state));
}

void lr_modbus_get_counters(const lr_modbus *m, lr_modbus_counters *out) { *out = m->c; }
