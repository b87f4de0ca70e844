/* lamprig tests — libmodbus server in a thread, over TCP or RTU on a pty (see modbus_server.h). */
#include "tests/support/modbus_server.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <modbus.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

struct lr_test_mb_server {
    bool rtu;
    int port;
    int listen_fd;
    int pty_master, pty_keep; /* rtu: the bus end, and a slave fd that keeps it from hanging up */
    char pty_path[64];
    char *link;
    int stop[2];
    pthread_t th;
    bool running;
    pthread_mutex_t mu;
    modbus_mapping_t *panel, *driver;
    bool silent;
    int corrupt;
    int answered;
};

static void die(const char *what)
{
    fprintf(stderr, "modbus test server: %s failed\n", what);
    abort();
}

/* Answers one request with libmodbus's own server logic (modbus_reply). For RTU the reply goes
 * through a pipe first so that its CRC can be damaged. */
static void serve(lr_test_mb_server *s, modbus_t *ctx, const uint8_t *q, int len, int capture[2])
{
    int unit = q[modbus_get_header_length(ctx) - 1];
    pthread_mutex_lock(&s->mu);
    modbus_mapping_t *map = unit == 1 ? s->panel : unit == 2 ? s->driver : NULL;
    if (map && !s->silent) {
        if (!s->rtu) {
            modbus_reply(ctx, q, len, map);
        } else {
            modbus_set_socket(ctx, capture[1]);
            int n = modbus_reply(ctx, q, len, map);
            uint8_t rsp[MODBUS_RTU_MAX_ADU_LENGTH];
            if (n > 0 && read(capture[0], rsp, (size_t)n) == n) {
                if (s->corrupt > 0) {
                    rsp[n - 1] ^= 0x5a;
                    s->corrupt--;
                }
                if (write(s->pty_master, rsp, (size_t)n) != n)
                    n = -1;
            }
        }
        s->answered++;
    }
    pthread_mutex_unlock(&s->mu);
}

static void *tcp_thread(void *arg)
{
    lr_test_mb_server *s = arg;
    modbus_t *ctx = modbus_new_tcp("127.0.0.1", s->port);
    int clients[8], nc = 0;
    for (;;) {
        struct pollfd p[10] = {{s->stop[0], POLLIN, 0}, {s->listen_fd, POLLIN, 0}};
        for (int i = 0; i < nc; i++)
            p[2 + i] = (struct pollfd){clients[i], POLLIN, 0};
        if (poll(p, (nfds_t)(2 + nc), -1) < 0)
            continue;
        if (p[0].revents)
            break;
        if (p[1].revents & POLLIN) {
            int c = accept(s->listen_fd, NULL, NULL);
            if (c >= 0 && nc < 8)
                clients[nc++] = c;
            else if (c >= 0)
                close(c);
        }
        for (int i = 0; i < nc; i++) {
            if (!p[2 + i].revents)
                continue;
            uint8_t q[MODBUS_TCP_MAX_ADU_LENGTH];
            modbus_set_socket(ctx, clients[i]);
            int rc = modbus_receive(ctx, q);
            if (rc > 0) {
                serve(s, ctx, q, rc, NULL);
            } else if (rc < 0) {
                close(clients[i]);
                clients[i] = clients[--nc];
                break; /* p[] no longer matches clients[]: poll again */
            }
        }
    }
    for (int i = 0; i < nc; i++)
        close(clients[i]);
    modbus_set_socket(ctx, -1);
    modbus_free(ctx);
    return NULL;
}

/* Bytes of an RTU request by function code (with CRC); 0 = need more; -1 = unknown. */
static int rtu_frame_len(const uint8_t *b, int n)
{
    if (n < 2)
        return 0;
    switch (b[1]) {
    case MODBUS_FC_READ_HOLDING_REGISTERS:
    case MODBUS_FC_READ_INPUT_REGISTERS:
    case MODBUS_FC_WRITE_SINGLE_REGISTER: return 8;
    case MODBUS_FC_WRITE_MULTIPLE_REGISTERS: return n < 7 ? 0 : 9 + b[6];
    }
    return -1;
}

static void *rtu_thread(void *arg)
{
    lr_test_mb_server *s = arg;
    modbus_t *ctx = modbus_new_rtu(s->pty_path, 19200, 'E', 8, 1);
    int capture[2];
    if (!ctx || pipe(capture) != 0)
        die("rtu server setup");
    uint8_t buf[512];
    int len = 0;
    for (;;) {
        struct pollfd p[2] = {{s->stop[0], POLLIN, 0}, {s->pty_master, POLLIN, 0}};
        if (poll(p, 2, -1) < 0)
            continue;
        if (p[0].revents)
            break;
        if (!(p[1].revents & POLLIN))
            continue;
        ssize_t n = read(s->pty_master, buf + len, sizeof buf - (size_t)len);
        if (n <= 0)
            continue;
        len += (int)n;
        /* Framing by length is enough for a test bus with one master. */
        for (;;) {
            int fl = rtu_frame_len(buf, len);
            if (fl < 0) {
                len = 0;
                break;
            }
            if (fl == 0 || len < fl)
                break;
            serve(s, ctx, buf, fl, capture);
            memmove(buf, buf + fl, (size_t)(len - fl));
            len -= fl;
        }
    }
    close(capture[0]);
    close(capture[1]);
    modbus_set_socket(ctx, -1);
    modbus_free(ctx);
    return NULL;
}

static void open_pty(lr_test_mb_server *s)
{
    s->pty_master = posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (s->pty_master < 0 || grantpt(s->pty_master) != 0 || unlockpt(s->pty_master) != 0 ||
        ptsname_r(s->pty_master, s->pty_path, sizeof s->pty_path) != 0)
        die("posix_openpt");
    s->pty_keep = open(s->pty_path, O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (s->pty_keep < 0)
        die("open pty slave");
    if (s->link) {
        unlink(s->link);
        if (symlink(s->pty_path, s->link) != 0)
            die("symlink");
    }
}

static void start(lr_test_mb_server *s)
{
    if (pipe(s->stop) != 0)
        die("pipe");
    if (s->rtu) {
        open_pty(s);
    } else {
        s->listen_fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
        if (s->listen_fd < 0)
            die("socket");
        int one = 1;
        setsockopt(s->listen_fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
        struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)s->port)};
        a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        if (bind(s->listen_fd, (struct sockaddr *)&a, sizeof a) != 0)
            die("bind");
        socklen_t al = sizeof a;
        if (getsockname(s->listen_fd, (struct sockaddr *)&a, &al) != 0)
            die("getsockname");
        s->port = ntohs(a.sin_port); /* 0 at first start: the kernel picked a free port */
        if (listen(s->listen_fd, 8) != 0)
            die("listen");
    }
    if (pthread_create(&s->th, NULL, s->rtu ? rtu_thread : tcp_thread, s) != 0)
        die("pthread_create");
    s->running = true;
}

static lr_test_mb_server *create(bool rtu, const char *link)
{
    lr_test_mb_server *s = calloc(1, sizeof *s);
    if (!s)
        die("calloc");
    s->rtu = rtu;
    s->listen_fd = s->pty_master = s->pty_keep = -1;
    if (link && !(s->link = strdup(link)))
        die("strdup");
    pthread_mutex_init(&s->mu, NULL);
    s->panel = modbus_mapping_new(0, 0, 10, 0);
    s->driver = modbus_mapping_new(0, 0, 10, 0);
    if (!s->panel || !s->driver)
        die("modbus_mapping_new");
    start(s);
    return s;
}

lr_test_mb_server *lr_test_mb_server_start(void) { return create(false, NULL); }

lr_test_mb_server *lr_test_mb_server_start_rtu(const char *link) { return create(true, link); }

int lr_test_mb_server_port(const lr_test_mb_server *s) { return s->port; }

const char *lr_test_mb_server_device(const lr_test_mb_server *s)
{
    return s->link ? s->link : s->pty_path;
}

int lr_test_mb_server_reg(lr_test_mb_server *s, int unit, int reg)
{
    pthread_mutex_lock(&s->mu);
    int v = (unit == 1 ? s->panel : s->driver)->tab_registers[reg];
    pthread_mutex_unlock(&s->mu);
    return v;
}

void lr_test_mb_server_set_reg(lr_test_mb_server *s, int unit, int reg, int value)
{
    pthread_mutex_lock(&s->mu);
    (unit == 1 ? s->panel : s->driver)->tab_registers[reg] = (uint16_t)value;
    pthread_mutex_unlock(&s->mu);
}

int lr_test_mb_server_answered(lr_test_mb_server *s)
{
    pthread_mutex_lock(&s->mu);
    int n = s->answered;
    pthread_mutex_unlock(&s->mu);
    return n;
}

void lr_test_mb_server_set_silent(lr_test_mb_server *s, bool silent)
{
    pthread_mutex_lock(&s->mu);
    s->silent = silent;
    pthread_mutex_unlock(&s->mu);
}

void lr_test_mb_server_corrupt(lr_test_mb_server *s, int n)
{
    pthread_mutex_lock(&s->mu);
    s->corrupt = n;
    pthread_mutex_unlock(&s->mu);
}

void lr_test_mb_server_stop(lr_test_mb_server *s)
{
    if (!s->running)
        return;
    if (write(s->stop[1], "x", 1) != 1)
        die("write");
    pthread_join(s->th, NULL);
    close(s->stop[0]);
    close(s->stop[1]);
    if (s->listen_fd >= 0)
        close(s->listen_fd);
    s->listen_fd = -1;
    if (s->rtu) {
        /* The bus goes away: the master's slave fd hangs up and /dev/pts/N disappears. */
        close(s->pty_keep);
        close(s->pty_master);
        s->pty_keep = s->pty_master = -1;
        if (s->link)
            unlink(s->link);
    }
    s->running = false;
}

void lr_test_mb_server_restart(lr_test_mb_server *s)
{
    if (!s->running)
        start(s);
}

bool lr_test_mb_server_running(const lr_test_mb_server *s) { return s->running; }

void lr_test_mb_server_free(lr_test_mb_server *s)
{
    if (!s)
        return;
    lr_test_mb_server_stop(s);
    modbus_mapping_free(s->panel);
    modbus_mapping_free(s->driver);
    pthread_mutex_destroy(&s->mu);
    free(s->link);
    free(s);
}
