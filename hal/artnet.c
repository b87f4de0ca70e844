/* Art-Net receiver: see hal/artnet.h. */
#include "hal/artnet.h"

#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "hal/artnet_packet.h"
#include "hal/dmx_core.h"
#include "hal/reply_limit.h"

#define MS 1000000LL

static const char *const MERGE_NAMES[] = {"htp", "ltp", NULL}; /* lr_dmx_merge_mode */
static const char *const LOSS_NAMES[] = {"hold", "fade", NULL}; /* lr_dmx_loss */

const lr_opt lr_artnet_opts[] = {
    [LR_ARTNET_OPT_BIND] = {"bind", LR_OPT_STRING, .dflt_text = "0.0.0.0",
                            .help = "IPv4 address to receive on"},
    [LR_ARTNET_OPT_PORT] = {"port", LR_OPT_INT, 1, 65535, LR_ARTNET_PORT, .help = "UDP port"},
    [LR_ARTNET_OPT_ANNOUNCE] = {"announce", LR_OPT_STRING, .dflt_text = "255.255.255.255",
                                .help = "where the ArtPollReply at start goes; `none`: nowhere"},
    [LR_ARTNET_OPT_SHORT_NAME] = {"short_name", LR_OPT_STRING, .dflt_text = "lamprig",
                                  .help = "node name in ArtPollReply"},
    [LR_ARTNET_OPT_MERGE] = {"merge", LR_OPT_ENUM, .dflt = LR_DMX_HTP, .names = MERGE_NAMES,
                             .help = "two senders on one port-address"},
    [LR_ARTNET_OPT_MERGE_TIMEOUT_MS] = {"merge_timeout_ms", LR_OPT_INT, 100, 600000, 10000,
                                        .help = "a quiet sender leaves the merge (Art-Net: 10 s)"},
    [LR_ARTNET_OPT_LOSS] = {"loss", LR_OPT_ENUM, .dflt = LR_DMX_HOLD, .names = LOSS_NAMES,
                            .help = "on loss of every sender: hold the look, or fade"},
    [LR_ARTNET_OPT_FADE_MS] = {"fade_ms", LR_OPT_INT, 1, 600000, 2000,
                               .help = "loss fade to the scene's values"},
    [LR_ARTNET_OPT_MAX_PACKETS] = {"max_packets", LR_OPT_INT, 1, 4096, 64,
                                   .help = "datagrams read per loop turn"},
    [LR_ARTNET_OPT_CHANNELS] = {"channels", LR_OPT_LIST, .required = true,
                                .help = "DMX channels as controls (below)"},
    LR_OPT_END,
};

struct lr_artnet {
    lr_dev base;
    dmx_core core;
    char bind[64], announce[64], short_name[18];
    int port, max_packets;
    int fd;
    bool more;
    bool send_logged;
    uint64_t send_failures;
    lr_reply_limit limit; /* ArtPollReply per poller and overall (reply_limit.h) */
};

static const char *const *result_names(void)
{
    static const char *names[LR_ARTNET_N_RESULTS + 1];
    for (int i = 0; i < LR_ARTNET_N_RESULTS; i++)
        names[i] = lr_artnet_result_name((lr_artnet_result)i);
    return names;
}

static void an_close(lr_dev *d)
{
    lr_artnet *a = (lr_artnet *)d;
    if (a->fd >= 0)
        close(a->fd);
    a->fd = -1;
}

/* The local address the kernel would send to `to` from: the IP an ArtPollReply names. */
static uint32_t local_ip_for(const lr_artnet *a, const struct sockaddr_in *to)
{
    struct in_addr b;
    if (a->bind[0] && inet_pton(AF_INET, a->bind, &b) == 1 && b.s_addr != htonl(INADDR_ANY))
        return ntohl(b.s_addr);
    int s = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    uint32_t ip = 0;
    if (s < 0)
        return 0;
    struct sockaddr_in l;
    socklen_t ll = sizeof l;
    /* connect() on UDP only picks the route; nothing is sent. */
    if (connect(s, (const struct sockaddr *)to, sizeof *to) == 0 &&
        getsockname(s, (struct sockaddr *)&l, &ll) == 0)
        ip = ntohl(l.sin_addr.s_addr);
    close(s);
    return ip;
}

/* ArtPollReply packets to `to`: the port-addresses grouped by Net/Sub-Net, four per packet. */
static void send_replies(lr_artnet *a, const struct sockaddr_in *to)
{
    bool done[LR_DMX_MAX_UNIVERSES] = {false};
    int bind_index = 1;
    uint32_t ip = local_ip_for(a, to);
    for (int i = 0; i < a->core.n_uni; i++) {
        if (done[i])
            continue;
        int group = a->core.uni[i].number >> 4; /* Net << 4 | Sub-Net */
        lr_artnet_node n = {.ip = ip, .short_name = a->short_name,
                            .long_name = "lamprig light table (Art-Net input)",
                            .net = group >> 4, .sub_net = group & 0x0f,
                            .report = "#0001 [0000] lamprig ok"};
        for (int k = i; k < a->core.n_uni && n.n_ports < 4; k++) {
            if (done[k] || a->core.uni[k].number >> 4 != group)
                continue;
            done[k] = true;
            n.universe[n.n_ports] = a->core.uni[k].number & 0x0f;
            n.active[n.n_ports] = lr_dmx_merge_count(&a->core.uni[k].merge) > 0;
            n.n_ports++;
        }
        n.bind_index = bind_index++;
        uint8_t pkt[LR_ARTNET_POLL_REPLY_LEN];
        size_t len = lr_artnet_poll_reply(&n, pkt);
        if (sendto(a->fd, pkt, len, MSG_DONTWAIT, (const struct sockaddr *)to, sizeof *to) ==
            (ssize_t)len) {
            a->core.c.replies++;
        } else {
            /* Logged once: a poller without a route back would repeat it every poll. */
            a->send_failures++;
            if (!a->send_logged) {
                char t[64];
                dmx_addr_text(to, t, sizeof t);
                a->send_logged = true;
                lr_dev_log(&a->base, LR_LOG_WARN, "ArtPollReply to %s: %s (later failures only "
                           "counted)", t, strerror(errno));
            }
            return;
        }
    }
}

static int an_open(lr_dev *d, int64_t now_ns, lr_err *e)
{
    (void)now_ns;
    lr_artnet *a = (lr_artnet *)d;
    int rc = dmx_udp_open(a->bind, a->port, true, &a->fd, e);
    if (rc)
        return rc;
    if (a->announce[0]) {
        struct sockaddr_in to = {.sin_family = AF_INET, .sin_port = htons(LR_ARTNET_PORT)};
        if (inet_pton(AF_INET, a->announce, &to.sin_addr) == 1)
            send_replies(a, &to);
    }
    return LR_OK;
}

static int an_pollfds(lr_dev *d, struct pollfd *fds, int max)
{
    lr_artnet *a = (lr_artnet *)d;
    if (max > 0)
        fds[0] = (struct pollfd){.fd = a->fd, .events = POLLIN};
    return 1;
}

static void handle(lr_artnet *a, const uint8_t *buf, size_t len, const struct sockaddr_in *from,
                   int64_t now_ns)
{
    lr_artnet_packet p;
    lr_artnet_result r = lr_artnet_parse(buf, len, &p);
    switch (r) {
    case LR_ARTNET_DMX: {
        int u = dmx_core_universe(&a->core, p.port_address);
        if (u < 0) {
            a->core.c.other++;
            return;
        }
        /* A sender is its address and port (Art-Net has no source id). */
        uint8_t key[LR_DMX_KEY_LEN] = {0};
        memcpy(key, &from->sin_addr, 4);
        memcpy(key + 4, &from->sin_port, 2);
        dmx_core_put(&a->core, u, key, 0, -1, p.slots, p.n_slots, now_ns);
        return;
    }
    case LR_ARTNET_POLL: {
        uint8_t key[LR_REPLY_LIMIT_KEY];
        memcpy(key, &from->sin_addr, 4);
        memcpy(key + 4, &from->sin_port, 2);
        if (!lr_reply_limit_take(&a->limit, key, now_ns)) {
            a->core.c.polls_limited++;
            return;
        }
        a->core.c.polls++;
        send_replies(a, from);
        return;
    }
    case LR_ARTNET_OTHER:
        a->core.c.other++;
        return;
    default: {
        char t[64];
        dmx_addr_text(from, t, sizeof t);
        dmx_core_bad(&a->core, (int)r, t, now_ns);
        return;
    }
    }
}

static void an_dispatch(lr_dev *d, int64_t now_ns)
{
    lr_artnet *a = (lr_artnet *)d;
    a->more = false;
    uint8_t buf[2048];
    for (int i = 0; i < a->max_packets; i++) {
        /* The last datagram this turn may take: more may wait behind it. */
        a->more = i == a->max_packets - 1;
        struct sockaddr_in from = {0};
        socklen_t fl = sizeof from;
        ssize_t n = recvfrom(a->fd, buf, sizeof buf, MSG_TRUNC | MSG_DONTWAIT,
                             (struct sockaddr *)&from, &fl);
        if (n < 0) {
            if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) {
                a->more = false; /* all read */
                break;
            }
            lr_dev_lost(d, LR_EIO, now_ns, "receive: %s", strerror(errno));
            return;
        }
        a->core.c.packets++;
        if ((size_t)n > sizeof buf) {
            char t[64];
            dmx_addr_text(&from, t, sizeof t);
            dmx_core_bad(&a->core, LR_ARTNET_LONG, t, now_ns);
            continue;
        }
        handle(a, buf, (size_t)n, &from, now_ns);
    }
    dmx_core_tick(&a->core, now_ns);
}

static int64_t an_next_deadline(lr_dev *d)
{
    lr_artnet *a = (lr_artnet *)d;
    if (a->more)
        return 0;
    int64_t t = dmx_core_deadline(&a->core);
    return t == INT64_MAX ? LR_NO_DEADLINE : t;
}

static void an_destroy(lr_dev *d) { free(d); }

static const lr_dev_ops ARTNET_OPS = {
    .kind = "artnet",
    .open = an_open,
    .close = an_close,
    .pollfds = an_pollfds,
    .dispatch = an_dispatch,
    .next_deadline = an_next_deadline,
    .destroy = an_destroy,
};

static int configure(lr_artnet *a, const lr_artnet_desc *desc, lr_err *e)
{
    const lr_opt *o = lr_artnet_opts;
    const char *pf = a->base.prefix;
    if (!lr_opt_hal_ok(&o[LR_ARTNET_OPT_PORT], desc->port) ||
        !lr_opt_hal_ok(&o[LR_ARTNET_OPT_MERGE_TIMEOUT_MS], desc->merge_timeout_ms) ||
        !lr_opt_hal_ok(&o[LR_ARTNET_OPT_FADE_MS], desc->fade_ms) ||
        !lr_opt_hal_ok(&o[LR_ARTNET_OPT_MAX_PACKETS], desc->max_packets))
        return lr_err_set(e, LR_EINVAL, "%s: port %d / merge_timeout_ms %d / fade_ms %d / "
                          "max_packets %d out of range", pf, desc->port, desc->merge_timeout_ms,
                          desc->fade_ms, desc->max_packets);
    if ((desc->merge != LR_DMX_HTP && desc->merge != LR_DMX_LTP) ||
        (desc->loss != LR_DMX_HOLD && desc->loss != LR_DMX_FADE))
        return lr_err_set(e, LR_EINVAL, "%s: merge %d / loss %d unknown", pf, (int)desc->merge,
                          (int)desc->loss);
    snprintf(a->bind, sizeof a->bind, "%s", desc->bind ? desc->bind : "");
    snprintf(a->announce, sizeof a->announce, "%s",
             desc->announce ? desc->announce : o[LR_ARTNET_OPT_ANNOUNCE].dflt_text);
    if (strcmp(a->announce, "none") == 0)
        a->announce[0] = '\0';
    struct in_addr ia;
    if (a->announce[0] && inet_pton(AF_INET, a->announce, &ia) != 1)
        return lr_err_set(e, LR_EINVAL, "%s: announce '%s' is not an IPv4 address", pf,
                          a->announce);
    snprintf(a->short_name, sizeof a->short_name, "%s",
             desc->short_name ? desc->short_name : o[LR_ARTNET_OPT_SHORT_NAME].dflt_text);
    a->port = (int)lr_opt_or_default(&o[LR_ARTNET_OPT_PORT], desc->port);
    a->max_packets = (int)lr_opt_or_default(&o[LR_ARTNET_OPT_MAX_PACKETS], desc->max_packets);
    dmx_core_cfg cc = {
        .channels = desc->channels,
        .n_channels = desc->n_channels,
        .channel_opts = lr_artnet_channel_opts,
        .merge = {.max_sources = 2,
                  .timeout_ns = lr_opt_or_default(&o[LR_ARTNET_OPT_MERGE_TIMEOUT_MS],
                                                  desc->merge_timeout_ms) * MS,
                  .mode = desc->merge},
        .loss = desc->loss,
        .fade_ms = (int)lr_opt_or_default(&o[LR_ARTNET_OPT_FADE_MS], desc->fade_ms),
        .kind_names = result_names(),
    };
    int rc = dmx_core_init(&a->core, &a->base, &cc, e);
    if (rc)
        return rc;
    char unis[160];
    dmx_core_universes_text(&a->core, unis, sizeof unis);
    snprintf(a->base.ident, sizeof a->base.ident, "udp %s:%d, port-address%s %s",
             a->bind[0] ? a->bind : "0.0.0.0", a->port, a->core.n_uni > 1 ? "es" : "", unis);
    return LR_OK;
}

int lr_artnet_create(const lr_artnet_desc *desc, lr_artnet **out, lr_err *e)
{
    *out = NULL;
    lr_artnet *a = calloc(1, sizeof *a);
    if (!a)
        return lr_err_set(e, LR_ENOMEM, "artnet: out of memory");
    a->fd = -1;
    lr_reply_limit_init(&a->limit, 1000, 20.0, 20.0);
    int rc = lr_dev_init(&a->base, &ARTNET_OPS, &desc->dev, e);
    if (rc == LR_OK)
        rc = configure(a, desc, e);
    if (rc == LR_OK)
        rc = lr_dev_start(&a->base, desc->dev.required, lr_now_ns(), e);
    if (rc != LR_OK) {
        an_close(&a->base);
        free(a);
        return rc;
    }
    *out = a;
    return LR_OK;
}

void lr_artnet_destroy(lr_artnet *a)
{
    if (a)
        lr_dev_destroy(&a->base);
}

lr_dev *lr_artnet_dev(lr_artnet *a) { return &a->base; }
void lr_artnet_get_counters(const lr_artnet *a, lr_dmx_counters *out) { *out = a->core.c; }
