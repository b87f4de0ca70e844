/* sACN receiver: see hal/sacn.h. */
#include "hal/sacn.h"

#include <arpa/inet.h>
#include <errno.h>
#include <math.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "hal/dmx_core.h"
#include "hal/sacn_packet.h"

#define MS 1000000LL

static const char *const LOSS_NAMES[] = {"hold", "fade", NULL}; /* lr_dmx_loss */

const lr_opt lr_sacn_opts[] = {
    [LR_SACN_OPT_BIND] = {"bind", LR_OPT_STRING, .dflt_text = "0.0.0.0",
                          .help = "IPv4 address to receive on"},
    [LR_SACN_OPT_PORT] = {"port", LR_OPT_INT, 1, 65535, LR_SACN_PORT, .help = "UDP port"},
    [LR_SACN_OPT_INTERFACE] = {"interface", LR_OPT_STRING,
                               .help = "IPv4 address of the NIC joining the multicast groups"},
    [LR_SACN_OPT_UNICAST_ONLY] = {"unicast_only", LR_OPT_BOOL, .dflt = 0,
                                  .help = "do not join 239.255.hi.lo"},
    [LR_SACN_OPT_MAX_SOURCES] = {"max_sources", LR_OPT_INT, 1, 16, 4,
                                 .help = "sources merged per universe; more are refused"},
    [LR_SACN_OPT_LOSS_MS] = {"loss_ms", LR_OPT_INT, 100, 600000, 2500,
                             .help = "a source quiet this long is lost (E1.31: 2.5 s)"},
    [LR_SACN_OPT_LOSS] = {"loss", LR_OPT_ENUM, .dflt = LR_DMX_HOLD, .names = LOSS_NAMES,
                          .help = "on loss of every source: hold the look, or fade"},
    [LR_SACN_OPT_FADE_MS] = {"fade_ms", LR_OPT_INT, 1, 600000, 2000,
                             .help = "loss fade to the scene's values"},
    [LR_SACN_OPT_PREVIEW] = {"preview", LR_OPT_BOOL, .dflt = 0,
                             .help = "take preview data (E1.31: for visualisers only)"},
    [LR_SACN_OPT_MAX_PACKETS] = {"max_packets", LR_OPT_INT, 1, 4096, 64,
                                 .help = "datagrams read per loop turn"},
    [LR_SACN_OPT_CHANNELS] = {"channels", LR_OPT_LIST, .required = true,
                              .help = "DMX channels as controls (below)"},
    LR_OPT_END,
};

struct lr_sacn {
    lr_dev base;
    dmx_core core;
    char bind[64], interface[64];
    bool unicast_only, preview;
    int port, max_packets;
    int fd;
    bool more; /* the last dispatch stopped at max_packets */
    bool join_logged;
    bool joined[LR_DMX_MAX_UNIVERSES];
    int64_t join_retry_at; /* LR_NO_DEADLINE: every group joined (or unicast only) */
};

static const char *const *result_names(void)
{
    static const char *names[LR_SACN_N_RESULTS + 1];
    for (int i = 0; i < LR_SACN_N_RESULTS; i++)
        names[i] = lr_sacn_result_name((lr_sacn_result)i);
    return names;
}

static void sa_close(lr_dev *d)
{
    lr_sacn *s = (lr_sacn *)d;
    if (s->fd >= 0)
        close(s->fd);
    s->fd = -1;
}

/* Joins the groups not joined yet. A rig that starts before its network is up (no route,
 * no such interface yet) tries again every JOIN_RETRY_NS; the first shortfall and the
 * recovery are logged, the retries are not. */
#define JOIN_RETRY_NS (5000 * MS)
static void join_groups(lr_sacn *s, int64_t now_ns)
{
    struct in_addr ifa = {.s_addr = htonl(INADDR_ANY)};
    if (s->interface[0])
        inet_pton(AF_INET, s->interface, &ifa); /* checked at create */
    int joined = 0, err = 0;
    for (int u = 0; u < s->core.n_uni; u++) {
        if (!s->joined[u]) {
            struct ip_mreq mr = {
                .imr_multiaddr.s_addr = htonl(lr_sacn_multicast_group(s->core.uni[u].number)),
                .imr_interface = ifa};
            if (setsockopt(s->fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mr, sizeof mr) == 0)
                s->joined[u] = true;
            else
                err = errno;
        }
        joined += s->joined[u];
    }
    if (joined == s->core.n_uni) {
        s->join_retry_at = LR_NO_DEADLINE;
        if (s->join_logged)
            lr_dev_log(&s->base, LR_LOG_INFO, "joined all %d multicast groups", joined);
        s->join_logged = false;
        return;
    }
    s->join_retry_at = now_ns + JOIN_RETRY_NS;
    if (!s->join_logged) {
        /* No multicast route (a host with only loopback) or no such interface: unicast works. */
        s->join_logged = true;
        lr_dev_log(&s->base, LR_LOG_WARN, "joined %d of %d multicast groups (%s); unicast to "
                   "port %d still taken; trying again every %d s", joined, s->core.n_uni,
                   strerror(err), s->port, (int)(JOIN_RETRY_NS / (1000 * MS)));
    }
}

static int sa_open(lr_dev *d, int64_t now_ns, lr_err *e)
{
    lr_sacn *s = (lr_sacn *)d;
    int rc = dmx_udp_open(s->bind, s->port, false, &s->fd, e);
    if (rc)
        return rc;
    memset(s->joined, 0, sizeof s->joined);
    s->join_retry_at = LR_NO_DEADLINE;
    if (!s->unicast_only)
        join_groups(s, now_ns);
    return LR_OK;
}

static int sa_pollfds(lr_dev *d, struct pollfd *fds, int max)
{
    lr_sacn *s = (lr_sacn *)d;
    if (max > 0)
        fds[0] = (struct pollfd){.fd = s->fd, .events = POLLIN};
    return 1;
}

static void handle(lr_sacn *s, const uint8_t *buf, size_t len, const struct sockaddr_in *from,
                   int64_t now_ns)
{
    lr_sacn_packet p;
    lr_sacn_result r = lr_sacn_parse(buf, len, &p);
    if (r == LR_SACN_EXTENDED || r == LR_SACN_START_CODE) {
        s->core.c.other++;
        return;
    }
    if (r != LR_SACN_OK) {
        char a[64];
        dmx_addr_text(from, a, sizeof a);
        dmx_core_bad(&s->core, (int)r, a, now_ns);
        return;
    }
    int u = dmx_core_universe(&s->core, p.universe);
    if (u < 0) {
        s->core.c.other++;
        return;
    }
    uint8_t key[LR_DMX_KEY_LEN];
    memcpy(key, p.cid, sizeof key);
    if (p.terminated) {
        dmx_core_terminate(&s->core, u, key, now_ns);
        return;
    }
    if (p.preview && !s->preview) {
        s->core.c.preview++;
        return;
    }
    dmx_core_put(&s->core, u, key, p.priority, p.sequence, p.slots, p.n_slots, now_ns);
}

static void sa_dispatch(lr_dev *d, int64_t now_ns)
{
    lr_sacn *s = (lr_sacn *)d;
    s->more = false;
    uint8_t buf[2048];
    for (int i = 0; i < s->max_packets; i++) {
        /* The last datagram this turn may take: more may wait behind it. */
        s->more = i == s->max_packets - 1;
        struct sockaddr_in from = {0};
        socklen_t fl = sizeof from;
        /* MSG_TRUNC: the datagram's real length, so an oversized one is seen as such. */
        ssize_t n = recvfrom(s->fd, buf, sizeof buf, MSG_TRUNC | MSG_DONTWAIT,
                             (struct sockaddr *)&from, &fl);
        if (n < 0) {
            if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) {
                s->more = false; /* all read */
                break;
            }
            lr_dev_lost(d, LR_EIO, now_ns, "receive: %s", strerror(errno));
            return;
        }
        s->core.c.packets++;
        size_t len = (size_t)n;
        if (len > sizeof buf) {
            char a[64];
            dmx_addr_text(&from, a, sizeof a);
            dmx_core_bad(&s->core, LR_SACN_LONG, a, now_ns);
            continue;
        }
        handle(s, buf, len, &from, now_ns);
    }
    dmx_core_tick(&s->core, now_ns);
    if (now_ns >= s->join_retry_at)
        join_groups(s, now_ns);
}

static int64_t sa_next_deadline(lr_dev *d)
{
    lr_sacn *s = (lr_sacn *)d;
    if (s->more)
        return 0; /* the rest of a burst, after the other devices had their turn */
    int64_t t = dmx_core_deadline(&s->core);
    if (s->join_retry_at < t)
        t = s->join_retry_at;
    return t == INT64_MAX ? LR_NO_DEADLINE : t;
}

static void sa_destroy(lr_dev *d) { free(d); }

static const lr_dev_ops SACN_OPS = {
    .kind = "sacn",
    .open = sa_open,
    .close = sa_close,
    .pollfds = sa_pollfds,
    .dispatch = sa_dispatch,
    .next_deadline = sa_next_deadline,
    .destroy = sa_destroy,
};

static int configure(lr_sacn *s, const lr_sacn_desc *desc, lr_err *e)
{
    const lr_opt *o = lr_sacn_opts;
    const char *pf = s->base.prefix;
    if (!lr_opt_hal_ok(&o[LR_SACN_OPT_PORT], desc->port) ||
        !lr_opt_hal_ok(&o[LR_SACN_OPT_MAX_SOURCES], desc->max_sources) ||
        !lr_opt_hal_ok(&o[LR_SACN_OPT_LOSS_MS], desc->loss_ms) ||
        !lr_opt_hal_ok(&o[LR_SACN_OPT_FADE_MS], desc->fade_ms) ||
        !lr_opt_hal_ok(&o[LR_SACN_OPT_MAX_PACKETS], desc->max_packets))
        return lr_err_set(e, LR_EINVAL, "%s: port %d / max_sources %d / loss_ms %d / fade_ms %d /"
                          " max_packets %d out of range", pf, desc->port, desc->max_sources,
                          desc->loss_ms, desc->fade_ms, desc->max_packets);
    if (desc->loss != LR_DMX_HOLD && desc->loss != LR_DMX_FADE)
        return lr_err_set(e, LR_EINVAL, "%s: loss %d unknown", pf, (int)desc->loss);
    snprintf(s->bind, sizeof s->bind, "%s", desc->bind ? desc->bind : "");
    snprintf(s->interface, sizeof s->interface, "%s", desc->interface ? desc->interface : "");
    struct in_addr ia;
    if (s->interface[0] && inet_pton(AF_INET, s->interface, &ia) != 1)
        return lr_err_set(e, LR_EINVAL, "%s: interface '%s' is not an IPv4 address", pf,
                          s->interface);
    s->unicast_only = desc->unicast_only;
    s->preview = desc->preview;
    s->port = (int)lr_opt_or_default(&o[LR_SACN_OPT_PORT], desc->port);
    s->max_packets = (int)lr_opt_or_default(&o[LR_SACN_OPT_MAX_PACKETS], desc->max_packets);
    dmx_core_cfg cc = {
        .channels = desc->channels,
        .n_channels = desc->n_channels,
        .channel_opts = lr_sacn_channel_opts,
        .merge = {.max_sources = (int)lr_opt_or_default(&o[LR_SACN_OPT_MAX_SOURCES],
                                                        desc->max_sources),
                  .timeout_ns = lr_opt_or_default(&o[LR_SACN_OPT_LOSS_MS], desc->loss_ms) * MS,
                  .mode = LR_DMX_HTP,
                  .check_sequence = true},
        .loss = desc->loss,
        .fade_ms = (int)lr_opt_or_default(&o[LR_SACN_OPT_FADE_MS], desc->fade_ms),
        .kind_names = result_names(),
    };
    int rc = dmx_core_init(&s->core, &s->base, &cc, e);
    if (rc)
        return rc;
    char unis[160];
    dmx_core_universes_text(&s->core, unis, sizeof unis);
    snprintf(s->base.ident, sizeof s->base.ident, "udp %s:%d, universe%s %s%s",
             s->bind[0] ? s->bind : "0.0.0.0", s->port, s->core.n_uni > 1 ? "s" : "", unis,
             s->unicast_only ? " (unicast)" : "");
    return LR_OK;
}

int lr_sacn_create(const lr_sacn_desc *desc, lr_sacn **out, lr_err *e)
{
    *out = NULL;
    lr_sacn *s = calloc(1, sizeof *s);
    if (!s)
        return lr_err_set(e, LR_ENOMEM, "sacn: out of memory");
    s->fd = -1;
    int rc = lr_dev_init(&s->base, &SACN_OPS, &desc->dev, e);
    if (rc == LR_OK)
        rc = configure(s, desc, e);
    if (rc == LR_OK)
        rc = lr_dev_start(&s->base, desc->dev.required, lr_now_ns(), e);
    if (rc != LR_OK) {
        sa_close(&s->base);
        free(s);
        return rc;
    }
    *out = s;
    return LR_OK;
}

void lr_sacn_destroy(lr_sacn *s)
{
    if (s)
        lr_dev_destroy(&s->base);
}

lr_dev *lr_sacn_dev(lr_sacn *s) { return &s->base; }
void lr_sacn_get_counters(const lr_sacn *s, lr_dmx_counters *out) { *out = s->core.c; }

int lr_sacn_port(const lr_sacn *s)
{
    if (s->fd < 0)
        return 0;
    struct sockaddr_in a;
    socklen_t l = sizeof a;
    if (getsockname(s->fd, (struct sockaddr *)&a, &l) != 0)
        return 0;
    return ntohs(a.sin_port);
}
