/* The receivers' shared core: see hal/dmx_core.h. */
#include "hal/dmx_core.h"

#include <arpa/inet.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <netinet/in.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#define MS 1000000LL
/* Steps of a loss fade: 40 per second is smoother than a console's own fader resolution at
 * the usual 1-3 s fades, and the control map may smooth further (fade_s). */
#define FADE_STEP_NS (25 * MS)
/* Loss and recovery lines. OLA sends only on change, so a quiet OLA is lost and back at every
 * pause of a show: LOSS_BURST lines per LOSS_WINDOW_NS, the rest counted (losses) and the
 * next line let through says how many were dropped. */
#define LOSS_BURST 4
#define LOSS_WINDOW_NS (60000 * MS)

/* The channel options shared by both receivers; only the universe range differs. */
#define CH_CONTROL {"control", LR_OPT_STRING, .required = true, .help = "event control name"}
#define CH_CHANNEL {"channel", LR_OPT_INT, 1, 512, 1, .required = true, \
                    .help = "DMX channel (the coarse byte of a 16-bit pair)"}
#define CH_FINE {"fine", LR_OPT_INT, 1, 512, 0, .help = "16-bit: the fine byte's channel"}

const lr_opt lr_sacn_channel_opts[] = {
    [LR_DMX_CH_CONTROL] = CH_CONTROL,
    [LR_DMX_CH_UNIVERSE] = {"universe", LR_OPT_INT, 1, 63999, 1, .help = "sACN universe"},
    [LR_DMX_CH_CHANNEL] = CH_CHANNEL,
    [LR_DMX_CH_FINE] = CH_FINE,
    LR_OPT_END,
};

const lr_opt lr_artnet_channel_opts[] = {
    [LR_DMX_CH_CONTROL] = CH_CONTROL,
    [LR_DMX_CH_UNIVERSE] = {"universe", LR_OPT_INT, 0, 32767, 0,
                            .help = "port-address: Net << 8 | Sub-Net << 4 | Universe"},
    [LR_DMX_CH_CHANNEL] = CH_CHANNEL,
    [LR_DMX_CH_FINE] = CH_FINE,
    LR_OPT_END,
};

int dmx_core_init(dmx_core *k, lr_dev *dev, const dmx_core_cfg *cfg, lr_err *e)
{
    memset(k, 0, sizeof *k);
    k->dev = dev;
    k->loss = cfg->loss;
    k->fade_ns = (int64_t)cfg->fade_ms * MS;
    k->kind_names = cfg->kind_names;
    lr_log_limit_init(&k->loss_limit, LOSS_BURST, LOSS_WINDOW_NS);
    const char *pf = dev->prefix;
    if (cfg->n_channels < 1 || cfg->n_channels > LR_DMX_MAX_CHANNELS || !cfg->channels)
        return lr_err_set(e, LR_EINVAL, "%s: %d channels (1..%d)", pf, cfg->n_channels,
                          LR_DMX_MAX_CHANNELS);
    const lr_opt *uo = &cfg->channel_opts[LR_DMX_CH_UNIVERSE];
    const lr_opt *co = &cfg->channel_opts[LR_DMX_CH_CHANNEL];
    for (int i = 0; i < cfg->n_channels; i++) {
        const lr_dmx_channel *c = &cfg->channels[i];
        dmx_chan *d = &k->ch[i];
        if (!c->control || !c->control[0] || strlen(c->control) >= LR_EVENT_NAME_MAX)
            return lr_err_set(e, LR_EINVAL, "%s: channels[%d]: control name missing or longer "
                              "than %d characters", pf, i, LR_EVENT_NAME_MAX - 1);
        for (int j = 0; j < i; j++)
            if (strcmp(k->ch[j].control, c->control) == 0)
                return lr_err_set(e, LR_EINVAL, "%s: channels[%d]: control '%s' used twice", pf,
                                  i, c->control);
        if (!lr_opt_in_range(uo, c->universe))
            return lr_err_set(e, LR_EINVAL, "%s: channels[%d]: universe %d is not %ld..%ld", pf,
                              i, c->universe, uo->lo, uo->hi);
        if (!lr_opt_in_range(co, c->channel) || (c->fine && !lr_opt_in_range(co, c->fine)) ||
            c->fine == c->channel)
            return lr_err_set(e, LR_EINVAL, "%s: channels[%d]: channel %d / fine %d is not "
                              "1..512 (fine 0: none; not the channel itself)", pf, i, c->channel,
                              c->fine);
        if (!isnan(c->home) && (c->home < 0 || c->home > 1))
            return lr_err_set(e, LR_EINVAL, "%s: channels[%d]: home %g is not 0..1", pf, i,
                              c->home);
        int u = dmx_core_universe(k, c->universe);
        if (u < 0) {
            if (k->n_uni == LR_DMX_MAX_UNIVERSES)
                return lr_err_set(e, LR_EINVAL, "%s: more than %d universes", pf,
                                  LR_DMX_MAX_UNIVERSES);
            u = k->n_uni++;
            k->uni[u].number = c->universe;
            lr_dmx_merge_init(&k->uni[u].merge, &cfg->merge);
        }
        snprintf(d->control, sizeof d->control, "%s", c->control);
        d->uni = u;
        d->coarse = c->channel - 1;
        d->fine = c->fine ? c->fine - 1 : -1;
        d->home = c->home;
        k->n_ch = i + 1;
    }
    return LR_OK;
}

int dmx_core_universe(const dmx_core *k, int number)
{
    for (int i = 0; i < k->n_uni; i++)
        if (k->uni[i].number == number)
            return i;
    return -1;
}

static void state_line(dmx_core *k, int64_t now_ns, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void state_line(dmx_core *k, int64_t now_ns, const char *fmt, ...)
{
    unsigned dropped;
    if (!lr_log_limit_take(&k->loss_limit, now_ns, &dropped))
        return;
    char msg[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (dropped)
        lr_dev_log(k->dev, LR_LOG_INFO, "%s (%u similar lines dropped)", msg, dropped);
    else
        lr_dev_log(k->dev, LR_LOG_INFO, "%s", msg);
}

static void emit(dmx_core *k, dmx_chan *d, double v, int64_t now_ns)
{
    if (d->have && v == d->last)
        return;
    d->have = true;
    d->last = v;
    lr_dev_emit(k->dev, NULL, d->control, LR_EV_ABSOLUTE, v, now_ns);
    k->c.events++;
}

/* The merged universe moved: every channel on it that it carries follows. */
static void follow(dmx_core *k, int uni, int64_t now_ns)
{
    const uint8_t *s;
    int n = lr_dmx_merge_get(&k->uni[uni].merge, &s);
    for (int i = 0; i < k->n_ch; i++) {
        dmx_chan *d = &k->ch[i];
        if (d->uni != uni || d->coarse >= n || d->fine >= n)
            continue;
        d->fading = false;
        double v = d->fine < 0 ? s[d->coarse] / 255.0
                               : (s[d->coarse] * 256 + s[d->fine]) / 65535.0;
        emit(k, d, v, now_ns);
    }
}

static void lost(dmx_core *k, int uni, int64_t now_ns)
{
    dmx_universe *u = &k->uni[uni];
    if (!u->live || lr_dmx_merge_count(&u->merge) > 0)
        return;
    u->live = false;
    u->was_lost = true;
    k->c.losses++;
    state_line(k, now_ns, "universe %d: no source left; %s", u->number,
               k->loss == LR_DMX_FADE ? "fading to the scene's values" : "holding the look");
    if (k->loss != LR_DMX_FADE)
        return;
    for (int i = 0; i < k->n_ch; i++) {
        dmx_chan *d = &k->ch[i];
        if (d->uni != uni || isnan(d->home) || !d->have)
            continue;
        d->fading = true;
        d->fade_from = d->last;
        d->fade_start = now_ns;
        k->fade_next = now_ns + FADE_STEP_NS;
    }
}

lr_dmx_take dmx_core_put(dmx_core *k, int uni, const uint8_t key[LR_DMX_KEY_LEN], int priority,
                         int seq, const uint8_t *slots, int n, int64_t now_ns)
{
    dmx_universe *u = &k->uni[uni];
    /* Timeouts first: a source back after a pause is a new source (no stale sequence). */
    if (lr_dmx_merge_expire(&u->merge, now_ns)) {
        if (lr_dmx_merge_count(&u->merge) > 0)
            follow(k, uni, now_ns); /* the others' look, even if this packet is refused */
        else
            lost(k, uni, now_ns);
    }
    lr_dmx_take t = lr_dmx_merge_put(&u->merge, key, priority, seq, slots, n, now_ns);
    switch (t) {
    case LR_DMX_TAKEN:
        k->c.taken++;
        if (!u->live) {
            u->live = true;
            if (u->was_lost)
                state_line(k, now_ns, "universe %d: receiving again", u->number);
        }
        follow(k, uni, now_ns);
        break;
    case LR_DMX_SEQUENCE: k->c.sequence++; break;
    case LR_DMX_FULL: k->c.full++; break;
    }
    return t;
}

void dmx_core_terminate(dmx_core *k, int uni, const uint8_t key[LR_DMX_KEY_LEN], int64_t now_ns)
{
    k->c.terminated++;
    if (lr_dmx_merge_terminate(&k->uni[uni].merge, key)) {
        if (lr_dmx_merge_count(&k->uni[uni].merge) > 0)
            follow(k, uni, now_ns);
        else
            lost(k, uni, now_ns);
    }
}

void dmx_core_tick(dmx_core *k, int64_t now_ns)
{
    for (int u = 0; u < k->n_uni; u++)
        if (lr_dmx_merge_expire(&k->uni[u].merge, now_ns)) {
            if (lr_dmx_merge_count(&k->uni[u].merge) > 0)
                follow(k, u, now_ns);
            else
                lost(k, u, now_ns);
        }
    for (int i = 0; i < k->n_ch; i++) {
        dmx_chan *d = &k->ch[i];
        if (!d->fading)
            continue;
        double f = k->fade_ns > 0 ? (double)(now_ns - d->fade_start) / (double)k->fade_ns : 1;
        if (f >= 1) {
            f = 1;
            d->fading = false;
        }
        emit(k, d, d->fade_from + (d->home - d->fade_from) * f, now_ns);
        k->fade_next = now_ns + FADE_STEP_NS;
    }
}

int64_t dmx_core_deadline(const dmx_core *k)
{
    int64_t t = INT64_MAX;
    for (int u = 0; u < k->n_uni; u++) {
        int64_t x = lr_dmx_merge_next_expiry(&k->uni[u].merge);
        if (x < t)
            t = x;
    }
    for (int i = 0; i < k->n_ch; i++)
        if (k->ch[i].fading) {
            int64_t x = k->fade_next < k->ch[i].fade_start + k->fade_ns
                            ? k->fade_next : k->ch[i].fade_start + k->fade_ns;
            if (x < t)
                t = x;
        }
    return t;
}

void dmx_core_bad(dmx_core *k, int kind, const char *from, int64_t now_ns)
{
    (void)now_ns;
    k->c.bad++;
    if (kind < 0 || kind >= LR_DMX_MAX_KINDS)
        return;
    k->c.bad_kind[kind]++;
    if (k->kind_logged[kind])
        return;
    k->kind_logged[kind] = true;
    lr_dev_log(k->dev, LR_LOG_WARN, "malformed packet (%s) from %s: dropped; later ones of this "
               "kind are only counted", k->kind_names ? k->kind_names[kind] : "?", from);
}

void dmx_core_universes_text(const dmx_core *k, char *buf, size_t n)
{
    size_t w = 0;
    buf[0] = '\0';
    for (int i = 0; i < k->n_uni && w < n; i++)
        w += (size_t)snprintf(buf + w, n - w, "%s%d", i ? ", " : "", k->uni[i].number);
}

int dmx_udp_open(const char *bind_addr, int port, bool broadcast, int *fd, lr_err *e)
{
    *fd = -1;
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    const char *ba = bind_addr && bind_addr[0] ? bind_addr : "0.0.0.0";
    if (inet_pton(AF_INET, ba, &a.sin_addr) != 1)
        return lr_err_set(e, LR_EINVAL, "bind address '%s' is not an IPv4 address", ba);
    int s = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (s < 0)
        return lr_err_set(e, LR_EIO, "socket: %s", strerror(errno));
    int one = 1;
    setsockopt(s, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    if (broadcast)
        setsockopt(s, SOL_SOCKET, SO_BROADCAST, &one, sizeof one);
    /* Room for a burst: a console sending 16 universes at once while the loop renders.
     * The kernel caps it at net.core.rmem_max (212992 bytes by default); failure is harmless. */
    int rcvbuf = 1 << 20;
    setsockopt(s, SOL_SOCKET, SO_RCVBUF, &rcvbuf, sizeof rcvbuf);
    if (bind(s, (struct sockaddr *)&a, sizeof a) != 0) {
        int err = errno;
        close(s);
        /* Not there (an address this host does not have): missing; else failing. */
        return lr_err_set(e, err == EADDRNOTAVAIL ? LR_ENODEV : LR_EIO, "bind %s:%d: %s", ba,
                          port, strerror(err));
    }
    *fd = s;
    return LR_OK;
}

void dmx_addr_text(const void *sockaddr_in, char *buf, size_t n)
{
    const struct sockaddr_in *a = sockaddr_in;
    char ip[INET_ADDRSTRLEN] = "?";
    inet_ntop(AF_INET, &a->sin_addr, ip, sizeof ip);
    snprintf(buf, n, "%s:%u", ip, (unsigned)ntohs(a->sin_port));
}
