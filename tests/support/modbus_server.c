/* lamprig tests — libmodbus TCP server in a thread (see modbus_server.h); the same server as
 * tests/test_hal_modbus.c, TCP only. */
#include "tests/support/modbus_server.h"

#include <arpa/inet.h>
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
    int port;
    int listen_fd;
    int stop[2];
    pthread_t th;
    bool running;
    pthread_mutex_t mu;
    modbus_mapping_t *panel, *driver;
    int answered;
};

static void die(const char *what)
{
    fprintf(stderr, "modbus test server: %s failed\n", what);
    abort();
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
                int unit = q[modbus_get_header_length(ctx) - 1];
                pthread_mutex_lock(&s->mu);
                modbus_mapping_t *map = unit == 1 ? s->panel : unit == 2 ? s->driver : NULL;
                if (map) {
                    modbus_reply(ctx, q, rc, map);
                    s->answered++;
                }
                pthread_mutex_unlock(&s->mu);
            } else if (rc < 0) {
                close(clients[i]);
                clients[i] = clients[--nc];
                break;
            }
        }
    }
    for (int i = 0; i < nc; i++)
        close(clients[i]);
    modbus_set_socket(ctx, -1);
    modbus_free(ctx);
    return NULL;
}

static void start(lr_test_mb_server *s)
{
    if (pipe(s->stop) != 0)
        die("pipe");
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
    s->port = ntohs(a.sin_port);
    if (listen(s->listen_fd, 8) != 0)
        die("listen");
    if (pthread_create(&s->th, NULL, tcp_thread, s) != 0)
        die("pthread_create");
    s->running = true;
}

lr_test_mb_server *lr_test_mb_server_start(void)
{
    lr_test_mb_server *s = calloc(1, sizeof *s);
    if (!s)
        die("calloc");
    s->listen_fd = -1;
    pthread_mutex_init(&s->mu, NULL);
    s->panel = modbus_mapping_new(0, 0, 10, 0);
    s->driver = modbus_mapping_new(0, 0, 10, 0);
    if (!s->panel || !s->driver)
        die("modbus_mapping_new");
    start(s);
    return s;
}

int lr_test_mb_server_port(const lr_test_mb_server *s) { return s->port; }

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

void lr_test_mb_server_stop(lr_test_mb_server *s)
{
    if (!s->running)
        return;
    if (write(s->stop[1], "x", 1) != 1)
        die("write");
    pthread_join(s->th, NULL);
    close(s->stop[0]);
    close(s->stop[1]);
    close(s->listen_fd);
    s->listen_fd = -1;
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
    free(s);
}
