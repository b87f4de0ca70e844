/* Modbus endpoint URL parsing (pure; see hal/modbus.h for the grammar). */
#include "hal/modbus.h"

#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* Parses all of [s, s+n) as a decimal integer in [lo, hi]. */
static bool parse_int(const char *s, size_t n, long lo, long hi, long *out)
{
    if (n == 0 || n > 12)
        return false;
    char tmp[16];
    memcpy(tmp, s, n);
    tmp[n] = '\0';
    for (size_t i = 0; i < n; i++)
        if (!isdigit((unsigned char)tmp[i]))
            return false;
    errno = 0;
    long v = strtol(tmp, NULL, 10);
    if (errno || v < lo || v > hi)
        return false;
    *out = v;
    return true;
}

static int parse_tcp(const char *url, const char *p, lr_modbus_url *u, lr_err *e)
{
    const char *host, *host_end, *rest;
    if (*p == '[') {
        host = p + 1;
        host_end = strchr(host, ']');
        if (!host_end)
            return lr_err_set(e, LR_EPARSE, "modbus URL '%s': missing ']' after IPv6 address",
                              url);
        rest = host_end + 1;
    } else {
        host = p;
        host_end = p + strcspn(p, ":/?#");
        rest = host_end;
    }
    size_t hn = (size_t)(host_end - host);
    if (hn == 0)
        return lr_err_set(e, LR_EPARSE, "modbus URL '%s': missing host (tcp://HOST:PORT)", url);
    if (hn >= sizeof u->host)
        return lr_err_set(e, LR_EPARSE, "modbus URL '%s': host longer than %zu characters", url,
                          sizeof u->host - 1);
    for (size_t i = 0; i < hn; i++)
        if (isspace((unsigned char)host[i]) || host[i] == '@')
            return lr_err_set(e, LR_EPARSE, "modbus URL '%s': invalid character in host", url);
    memcpy(u->host, host, hn);
    u->host[hn] = '\0';
    u->port = 502;
    if (*rest == ':') {
        const char *port = rest + 1;
        size_t pn = strcspn(port, "/?#");
        long v;
        if (!parse_int(port, pn, 1, 65535, &v))
            return lr_err_set(e, LR_EPARSE, "modbus URL '%s': port '%.*s' is not 1..65535", url,
                              (int)pn, port);
        u->port = (int)v;
        rest = port + pn;
    }
    if (*rest == '/' && rest[1] == '\0')
        rest++;
    if (*rest)
        return lr_err_set(e, LR_EPARSE, "modbus URL '%s': unexpected '%s' after host:port", url,
                          rest);
    return LR_OK;
}

static bool valid_baud(long b)
{
    static const long B[] = {1200,  2400,  4800,   9600,   19200,  38400,
                             57600, 115200, 230400, 460800, 921600};
    for (size_t i = 0; i < sizeof B / sizeof B[0]; i++)
        if (b == B[i])
            return true;
    return false;
}

static int parse_rtu(const char *url, const char *p, lr_modbus_url *u, lr_err *e)
{
    /* rtu:/dev/ttyUSB0 and rtu:///dev/ttyUSB0 name the same device. */
    if (p[0] == '/' && p[1] == '/' && p[2] == '/')
        p += 2;
    size_t dn = strcspn(p, "?");
    if (dn == 0)
        return lr_err_set(e, LR_EPARSE, "modbus URL '%s': missing device (rtu:DEVICE?baud=...)",
                          url);
    if (dn >= sizeof u->device)
        return lr_err_set(e, LR_EPARSE, "modbus URL '%s': device longer than %zu characters",
                          url, sizeof u->device - 1);
    memcpy(u->device, p, dn);
    u->device[dn] = '\0';
    u->baud = 19200;
    u->parity = 'E';
    u->data_bits = 8;
    u->stop_bits = 1;
    u->rs485 = false;
    const char *q = p + dn;
    if (*q == '\0')
        return LR_OK;
    q++; /* '?' */
    unsigned seen = 0;
    while (*q) {
        size_t pn = strcspn(q, "&");
        const char *eq = memchr(q, '=', pn);
        if (!eq)
            return lr_err_set(e, LR_EPARSE, "modbus URL '%s': option '%.*s' is not key=value",
                              url, (int)pn, q);
        size_t kn = (size_t)(eq - q);
        const char *val = eq + 1;
        size_t vn = pn - kn - 1;
        static const char *const KEYS[] = {"baud", "parity", "data", "stop", "rs485"};
        int k = -1;
        for (int i = 0; i < 5; i++)
            if (strlen(KEYS[i]) == kn && strncmp(q, KEYS[i], kn) == 0)
                k = i;
        if (k < 0)
            return lr_err_set(e, LR_EPARSE,
                              "modbus URL '%s': unknown option '%.*s' (baud, parity, data, stop, "
                              "rs485)",
                              url, (int)kn, q);
        if (seen & (1u << k))
            return lr_err_set(e, LR_EPARSE, "modbus URL '%s': option '%s' given twice", url,
                              KEYS[k]);
        seen |= 1u << k;
        long v = 0;
        switch (k) {
        case 0:
            if (!parse_int(val, vn, 1, 4000000, &v) || !valid_baud(v))
                return lr_err_set(e, LR_EPARSE,
                                  "modbus URL '%s': baud '%.*s' is not a standard rate "
                                  "(1200..921600)",
                                  url, (int)vn, val);
            u->baud = (int)v;
            break;
        case 1:
            if (vn != 1 || !strchr("NEOneo", val[0]))
                return lr_err_set(e, LR_EPARSE, "modbus URL '%s': parity '%.*s' is not N, E or O",
                                  url, (int)vn, val);
            u->parity = (char)toupper((unsigned char)val[0]);
            break;
        case 2:
            if (!parse_int(val, vn, 5, 8, &v))
                return lr_err_set(e, LR_EPARSE, "modbus URL '%s': data bits '%.*s' is not 5..8",
                                  url, (int)vn, val);
            u->data_bits = (int)v;
            break;
        case 3:
            if (!parse_int(val, vn, 1, 2, &v))
                return lr_err_set(e, LR_EPARSE, "modbus URL '%s': stop bits '%.*s' is not 1 or 2",
                                  url, (int)vn, val);
            u->stop_bits = (int)v;
            break;
        case 4:
            if (!parse_int(val, vn, 0, 1, &v))
                return lr_err_set(e, LR_EPARSE, "modbus URL '%s': rs485 '%.*s' is not 0 or 1",
                                  url, (int)vn, val);
            u->rs485 = v == 1;
            break;
        }
        q += pn;
        if (*q == '&') {
            q++;
            if (*q == '\0')
                return lr_err_set(e, LR_EPARSE, "modbus URL '%s': trailing '&'", url);
        }
    }
    return LR_OK;
}

int lr_modbus_url_parse(const char *url, lr_modbus_url *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    if (!url || !url[0])
        return lr_err_set(e, LR_EPARSE, "modbus URL is empty (tcp://HOST:PORT or rtu:DEVICE?...)");
    if (strncasecmp(url, "tcp://", 6) == 0) {
        out->transport = LR_MODBUS_TCP;
        return parse_tcp(url, url + 6, out, e);
    }
    if (strncasecmp(url, "rtu:", 4) == 0) {
        out->transport = LR_MODBUS_RTU;
        return parse_rtu(url, url + 4, out, e);
    }
    return lr_err_set(e, LR_EPARSE,
                      "modbus URL '%s': unknown scheme (expected tcp://HOST:PORT or "
                      "rtu:DEVICE?baud=...&parity=N|E|O&data=8&stop=1)",
                      url);
}

int lr_modbus_url_format(const lr_modbus_url *u, char *buf, size_t n)
{
    if (u->transport == LR_MODBUS_TCP)
        return snprintf(buf, n, strchr(u->host, ':') ? "tcp://[%s]:%d" : "tcp://%s:%d", u->host,
                        u->port);
    return snprintf(buf, n, "rtu:%s?baud=%d&parity=%c&data=%d&stop=%d%s", u->device, u->baud,
                    u->parity, u->data_bits, u->stop_bits, u->rs485 ? "&rs485=1" : "");
}
