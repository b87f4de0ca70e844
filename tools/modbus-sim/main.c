/* lamprig-modbus-sim — a Modbus TCP simulator of the modbus-demo rig's hardware: the dimmer
 * panel (unit 1, holding register 0, 0-1000) and the lamp driver (unit 2, holding register 0,
 * 0-255), answered by libmodbus's own modbus_reply, so `lamprig run --config
 * configs/rig/modbus-demo.json --modbus tcp://127.0.0.1:PORT` can be tried without hardware.
 *
 *   lamprig-modbus-sim [--port 1502] [--panel 500] [--sweep SECONDS]
 *
 * Type a number 0..1000 and Enter to move the panel; every change of the driver register is
 * printed ("driver 128 (50.2 %)"). --sweep turns the panel 0 → 1000 → 0 over SECONDS, again
 * and again. One thread, one poll loop; Ctrl-C ends it. */
#include <arpa/inet.h>
#include <errno.h>
#include <math.h>
#include <modbus.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#define MAX_CLIENTS 8

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

static int usage(void)
{
    fprintf(stderr, "usage: lamprig-modbus-sim [--port 1502] [--panel 0..1000] "
                    "[--sweep SECONDS]\n");
    return 2;
}

int main(int argc, char **argv)
{
    int port = 1502, panel = 500;
    double sweep = 0;
    for (int i = 1; i < argc; i++) {
        if (i + 1 >= argc)
            return usage();
        char *end;
        if (strcmp(argv[i], "--port") == 0)
            port = (int)strtol(argv[++i], &end, 10);
        else if (strcmp(argv[i], "--panel") == 0)
            panel = (int)strtol(argv[++i], &end, 10);
        else if (strcmp(argv[i], "--sweep") == 0)
            sweep = strtod(argv[++i], &end);
        else
            return usage();
        if (*end || port < 1 || port > 65535 || panel < 0 || panel > 1000 || sweep < 0)
            return usage();
    }
    signal(SIGPIPE, SIG_IGN);
    modbus_mapping_t *units[3] = {NULL, modbus_mapping_new(0, 0, 10, 0),
                                  modbus_mapping_new(0, 0, 10, 0)};
    modbus_t *ctx = modbus_new_tcp("127.0.0.1", port);
    int lfd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    int one = 1;
    setsockopt(lfd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (!units[1] || !units[2] || !ctx || lfd < 0 ||
        bind(lfd, (struct sockaddr *)&a, sizeof a) != 0 || listen(lfd, 4) != 0) {
        fprintf(stderr, "lamprig-modbus-sim: cannot listen on 127.0.0.1:%d: %s\n", port,
                strerror(errno));
        return 1;
    }
    units[1]->tab_registers[0] = (uint16_t)panel;
    printf("modbus simulator on tcp://127.0.0.1:%d: panel = unit 1 reg 0 (0-1000) at %d, "
           "driver = unit 2 reg 0 (0-255)\n", port, panel);
    if (!sweep)
        printf("type 0..1000 + Enter to move the panel\n");
    fflush(stdout);
    int clients[MAX_CLIENTS], nc = 0, last_driver = -1;
    double t0 = now_s();
    for (;;) {
        struct pollfd p[2 + MAX_CLIENTS] = {{0, POLLIN, 0}, {lfd, POLLIN, 0}};
        for (int i = 0; i < nc; i++)
            p[2 + i] = (struct pollfd){clients[i], POLLIN, 0};
        if (poll(p, (nfds_t)(2 + nc), sweep ? 20 : -1) < 0 && errno != EINTR)
            break;
        if (sweep) {
            double ph = fmod((now_s() - t0) / sweep, 1.0);
            units[1]->tab_registers[0] = (uint16_t)lround(1000 * (ph < 0.5 ? 2 * ph : 2 - 2 * ph));
        }
        if (p[0].revents & POLLIN) {
            char line[64];
            if (!fgets(line, sizeof line, stdin))
                break;
            int v = atoi(line);
            if (v >= 0 && v <= 1000)
                units[1]->tab_registers[0] = (uint16_t)v;
            printf("panel %d\n", units[1]->tab_registers[0]);
        }
        if (p[1].revents & POLLIN) {
            int c = accept(lfd, NULL, NULL);
            if (c >= 0 && nc < MAX_CLIENTS)
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
                if (unit == 1 || unit == 2)
                    modbus_reply(ctx, q, rc, units[unit]);
            } else if (rc < 0) {
                close(clients[i]);
                clients[i] = clients[--nc];
                break;
            }
        }
        int d = units[2]->tab_registers[0];
        if (d != last_driver) {
            printf("driver %d (%.1f %%)\n", d, d / 2.55);
            fflush(stdout);
            last_driver = d;
        }
    }
    for (int i = 0; i < nc; i++)
        close(clients[i]);
    close(lfd);
    modbus_set_socket(ctx, -1);
    modbus_free(ctx);
    modbus_mapping_free(units[1]);
    modbus_mapping_free(units[2]);
    return 0;
}
