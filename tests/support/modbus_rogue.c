/* lamprig tests — a misbehaving Modbus/TCP peer (see modbus_rogue.h). Plain sockets, frames
 * built by hand: libmodbus's server side cannot be made to answer wrongly. */
#include "tests/support/modbus_rogue.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#define NREG 16
#define DRIP_BYTES 250

struct lr_test_rogue {
    lr_test_rogue_mode mode;
    int drip_ms;
    int port, listen_fd;
    int stop[2];
    pthread_t th;
    pthread_mutex_t mu;
    int regs[2][NREG]; /* [0]: every unit but 2 (the panel); [1]: unit 2 (the lamp driver) */
    int accepted, requests;
    /* thread only */
    int client;
    uint8_t in[1024];
    int in_len;
    uint8_t prev[300];
    int prev_len;
    uint8_t drip[300];
    int drip_len, drip_off;
    int64_t drip_next_ms;
    unsigned k; /* RANDOM: answers so far */
};

static void die(const char *what)
{
    fprintf(stderr, "modbus rogue peer: %s failed\n", what);
    abort();
}

static int64_t now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000 + ts.tv_nsec / 1000000;
}

static void put16(uint8_t *p, int v)
{
    p[0] = (uint8_t)(v >> 8);
    p[1] = (uint8_t)v;
}

static void tx(lr_test_rogue *r, const uint8_t *b, int n)
{
    if (r->client >= 0 && send(r->client, b, (size_t)n, MSG_NOSIGNAL) != n) {
        close(r->client);
        r->client = -1;
    }
}

/* The correct answer ADU to request q (MBAP + PDU); its length. */
static int answer(lr_test_rogue *r, const uint8_t *q, uint8_t *a)
{
    int fc = q[7], addr = q[8] << 8 | q[9], qty = q[10] << 8 | q[11];
    int *regs = r->regs[q[6] == 2];
    memcpy(a, q, 7);
    a[7] = (uint8_t)fc;
    int pl;
    pthread_mutex_lock(&r->mu);
    if (fc == 3 || fc == 4) {
        if (qty < 1 || addr + qty > NREG) {
            a[7] = (uint8_t)(fc | 0x80);
            a[8] = 2;
            pl = 2;
        } else {
            a[8] = (uint8_t)(2 * qty);
            for (int i = 0; i < qty; i++)
                put16(a + 9 + 2 * i, regs[addr + i]);
            pl = 2 + 2 * qty;
        }
    } else if (fc == 6 || fc == 16) {
        if (addr < NREG)
            regs[addr] = fc == 6 ? qty : (q[13] << 8 | q[14]);
        memcpy(a + 8, q + 8, 4); /* address and value / quantity */
        pl = 5;
    } else {
        a[7] = (uint8_t)(fc | 0x80);
        a[8] = 1;
        pl = 2;
    }
    pthread_mutex_unlock(&r->mu);
    put16(a + 4, 1 + pl);
    return 7 + pl;
}

static void serve(lr_test_rogue *r, const uint8_t *q)
{
    uint8_t a[300];
    int n = answer(r, q, a);
    switch (r->mode) {
    case LR_ROGUE_DRIP:
        if (r->drip_len || (q[7] != 3 && q[7] != 4))
            return; /* busy dripping: the request is ignored */
        memcpy(r->drip, q, 7);
        put16(r->drip + 4, 3 + DRIP_BYTES);
        r->drip[7] = q[7];
        r->drip[8] = DRIP_BYTES;
        memset(r->drip + 9, 0x11, DRIP_BYTES);
        r->drip_len = 9 + DRIP_BYTES;
        tx(r, r->drip, 9);
        r->drip_off = 9;
        r->drip_next_ms = now_ms() + r->drip_ms;
        return;
    case LR_ROGUE_LATE:
        if (r->prev_len)
            tx(r, r->prev, r->prev_len);
        tx(r, a, n);
        memcpy(r->prev, a, (size_t)n);
        r->prev_len = n;
        return;
    case LR_ROGUE_RANDOM: {
        unsigned k = r->k++, v = k / 4;
        switch (k % 4) {
        case 0: a[6] = (uint8_t)(a[6] + 1 + v % 200); break;  /* another unit */
        case 1: a[7] = (uint8_t)(7 + v % 9); break;          /* another function */
        case 2:                                              /* an exception */
            a[7] |= 0x80;
            a[8] = (uint8_t)(1 + v % 11);
            put16(a + 4, 3);
            n = 9;
            break;
        default: break;                                      /* a good answer */
        }
        tx(r, a, n);
        return;
    }
    case LR_ROGUE_CLOSE: return;
    }
}

static void drip_step(lr_test_rogue *r)
{
    if (!r->drip_len || now_ms() < r->drip_next_ms)
        return;
    tx(r, r->drip + r->drip_off, 1);
    if (++r->drip_off == r->drip_len)
        r->drip_len = 0;
    r->drip_next_ms += r->drip_ms;
}

static void take_requests(lr_test_rogue *r)
{
    ssize_t n = recv(r->client, r->in + r->in_len, sizeof r->in - (size_t)r->in_len, 0);
    if (n <= 0) {
        close(r->client);
        r->client = -1;
        r->in_len = 0;
        return;
    }
    r->in_len += (int)n;
    while (r->in_len >= 7) {
        int len = 6 + (r->in[4] << 8 | r->in[5]);
        if (len < 12 || len > (int)sizeof r->in) {
            r->in_len = 0;
            return;
        }
        if (r->in_len < len)
            return;
        pthread_mutex_lock(&r->mu);
        r->requests++;
        pthread_mutex_unlock(&r->mu);
        serve(r, r->in);
        if (r->client < 0)
            return;
        memmove(r->in, r->in + len, (size_t)(r->in_len - len));
        r->in_len -= len;
    }
}

static void *thread(void *arg)
{
    lr_test_rogue *r = arg;
    for (;;) {
        struct pollfd p[3] = {{r->stop[0], POLLIN, 0}, {r->listen_fd, POLLIN, 0},
                              {r->client, POLLIN, 0}};
        int timeout = -1;
        if (r->drip_len) {
            int64_t t = r->drip_next_ms - now_ms();
            timeout = t < 0 ? 0 : (int)t;
        }
        if (poll(p, r->client >= 0 ? 3 : 2, timeout) < 0)
            continue;
        if (p[0].revents)
            break;
        if (p[1].revents & POLLIN) {
            int c = accept4(r->listen_fd, NULL, NULL, SOCK_CLOEXEC);
            if (c >= 0) {
                pthread_mutex_lock(&r->mu);
                r->accepted++;
                pthread_mutex_unlock(&r->mu);
                if (r->mode == LR_ROGUE_CLOSE) {
                    close(c);
                } else {
                    if (r->client >= 0)
                        close(r->client);
                    r->client = c;
                    r->in_len = r->prev_len = r->drip_len = 0;
                }
            }
            continue;
        }
        if (r->client >= 0 && p[2].revents)
            take_requests(r);
        drip_step(r);
    }
    if (r->client >= 0)
        close(r->client);
    return NULL;
}

lr_test_rogue *lr_test_rogue_start(lr_test_rogue_mode mode, int drip_ms)
{
    lr_test_rogue *r = calloc(1, sizeof *r);
    if (!r)
        die("calloc");
    r->mode = mode;
    r->drip_ms = drip_ms > 0 ? drip_ms : 45;
    r->client = -1;
    pthread_mutex_init(&r->mu, NULL);
    /* Close-on-exec, like every descriptor here: a test that forks the rig after starting a
     * peer must not hand the peer's descriptors to the rig (its descriptor count is watched). */
    if (pipe2(r->stop, O_CLOEXEC) != 0)
        die("pipe");
    r->listen_fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (r->listen_fd < 0)
        die("socket");
    struct sockaddr_in a = {.sin_family = AF_INET};
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t al = sizeof a;
    if (bind(r->listen_fd, (struct sockaddr *)&a, sizeof a) != 0 ||
        getsockname(r->listen_fd, (struct sockaddr *)&a, &al) != 0 || listen(r->listen_fd, 8) != 0)
        die("bind/listen");
    r->port = ntohs(a.sin_port);
    if (pthread_create(&r->th, NULL, thread, r) != 0)
        die("pthread_create");
    return r;
}

int lr_test_rogue_port(const lr_test_rogue *r) { return r->port; }

void lr_test_rogue_set_reg(lr_test_rogue *r, int reg, int value)
{
    pthread_mutex_lock(&r->mu);
    r->regs[0][reg] = value;
    pthread_mutex_unlock(&r->mu);
}

int lr_test_rogue_driver(lr_test_rogue *r, int reg)
{
    pthread_mutex_lock(&r->mu);
    int v = r->regs[1][reg];
    pthread_mutex_unlock(&r->mu);
    return v;
}

int lr_test_rogue_accepted(lr_test_rogue *r)
{
    pthread_mutex_lock(&r->mu);
    int n = r->accepted;
    pthread_mutex_unlock(&r->mu);
    return n;
}

int lr_test_rogue_requests(lr_test_rogue *r)
{
    pthread_mutex_lock(&r->mu);
    int n = r->requests;
    pthread_mutex_unlock(&r->mu);
    return n;
}

void lr_test_rogue_free(lr_test_rogue *r)
{
    if (!r)
        return;
    if (write(r->stop[1], "x", 1) != 1)
        die("write");
    pthread_join(r->th, NULL);
    close(r->stop[0]);
    close(r->stop[1]);
    close(r->listen_fd);
    pthread_mutex_destroy(&r->mu);
    free(r);
}
