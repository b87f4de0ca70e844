/* lamprig-modbus-sim — a Modbus TCP simulator of the modbus-demo rig's hardware: the dimmer
 * panel (unit 1, holding register 0, 0-1000) and the lamp driver (unit 2, holding register 0,
 * 0-255), answered by libmodbus's own modbus_reply, so `lamprig run --config
 * configs/rig/modbus-demo.json --modbus tcp://127.0.0.1:PORT` can be tried without hardware.
 *
 *   lamprig-modbus-sim [--port 1502] [--panel 500] [--sweep SECONDS] [--trace]
 *
 * Type a number 0..1000 and Enter to move the panel; every change of the driver register is
 * printed ("driver 128 (50.2 %)"). --sweep turns the panel 0 → 1000 → 0 over SECONDS, again
 * and again. One thread, one poll loop; SIGINT (Ctrl-C) or SIGTERM ends it (exit 0).
 *
 * --trace also prints a timestamped line per request and per change, for a benchmark to
 * measure the rig's poll cadence and its panel-to-lamp delay from the peer's side:
 * "@T request unit U function F", "@T panel V", "@T driver V", T in seconds of
 * CLOCK_MONOTONIC (the same clock as the rig's, so the lines compare across processes).
 *
 * Runs like a daemon when stdin is not a terminal: at end of input (stdin /dev/null, a closed
 * pipe) it stops reading stdin and goes on serving; poll() then waits on the sockets (and
 * the signals) alone, so a hung-up stdin never makes the loop spin. */
#include <arpa/inet.h>
#include <errno.h>
#include <math.h>
#include <modbus.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/signalfd.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "firmware/tool.h"

#define MAX_CLIENTS 8

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

#define PROGRAM "lamprig-modbus-sim"

static const lr_argspec opts[] = {
    {.name = "--port", .type = LR_ARG_INT, .metavar = "PORT", .min = 1, .max = 65535,
     .help = "TCP port on 127.0.0.1, 1..65535 (default 1502)"},
    {.name = "--panel", .type = LR_ARG_INT, .metavar = "0..1000", .min = 0, .max = 1000,
     .help = "the dimmer panel's register at start (default 500)"},
    {.name = "--sweep", .type = LR_ARG_NUMBER, .metavar = "SECONDS", .flags = LR_ARG_FLOOR,
     .help = "turn the panel 0 -> 1000 -> 0 over SECONDS (>= 0), again and\n"
             "again (default 0: it moves only when a number is typed)"},
    {.name = "--trace",
     .help = "also a timestamped line per request and per change\n"
             "(\"@T request unit U function F\", \"@T panel V\", \"@T driver V\")"},
    {0},
};

static const lr_command tool = {
    .name = PROGRAM,
    .about = "A Modbus TCP simulator of the modbus-demo rig: the dimmer panel (unit 1, holding\n"
             "register 0, 0-1000) and the lamp driver (unit 2, holding register 0, 0-255).\n"
             "Type a number 0..1000 and Enter to move the panel; every change of the driver\n"
             "register is printed. With stdin at its end (/dev/null, a closed pipe) it goes on\n"
             "serving.",
    .opts = opts,
    .notes = "SIGINT or SIGTERM ends it (exit 0). Exit status 1 when it cannot listen, 2 on\n"
             "bad arguments.",
};

int main(int argc, char **argv)
{
    int port = 1502, panel = 500;
    double sweep = 0;
    lr_args args;
    lr_err e = {0};
    int st = lr_tool_args(&tool, argc, argv, &args);
    if (st >= 0)
        return st;
    if (lr_args_int(&args, "--port", &port, &e) || lr_args_int(&args, "--panel", &panel, &e) ||
        lr_args_double(&args, "--sweep", &sweep, &e))
        return lr_tool_usage(PROGRAM, "%s", e.msg);
    bool trace = lr_args_has(&args, "--trace");
    signal(SIGPIPE, SIG_IGN);
    /* SIGINT/SIGTERM arrive as a readable fd in the poll set: no handler, no race with
     * poll(), and the loop ends through the same cleanup as at any other exit. */
    sigset_t stop;
    sigemptyset(&stop);
    sigaddset(&stop, SIGINT);
    sigaddset(&stop, SIGTERM);
    int sfd = -1;
    if (sigprocmask(SIG_BLOCK, &stop, NULL) == 0)
        sfd = signalfd(-1, &stop, SFD_CLOEXEC);
    if (sfd < 0) {
        fprintf(stderr, "lamprig-modbus-sim: signalfd: %s\n", strerror(errno));
        return 1;
    }
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
    /* stdin while it can still give lines; -1 (ignored by poll) after end of input. */
    int in_fd = 0;
    double t0 = now_s();
    for (;;) {
        enum { IN, LISTEN, SIG, FIRST_CLIENT };
        struct pollfd p[FIRST_CLIENT + MAX_CLIENTS] = {
            [IN] = {in_fd, POLLIN, 0}, [LISTEN] = {lfd, POLLIN, 0}, [SIG] = {sfd, POLLIN, 0}};
        for (int i = 0; i < nc; i++)
            p[FIRST_CLIENT + i] = (struct pollfd){clients[i], POLLIN, 0};
        if (poll(p, (nfds_t)(FIRST_CLIENT + nc), sweep ? 20 : -1) < 0) {
            if (errno == EINTR)
                continue;
            fprintf(stderr, "lamprig-modbus-sim: poll: %s\n", strerror(errno));
            break;
        }
        if (p[SIG].revents & POLLIN) {
            struct signalfd_siginfo si;
            if (read(sfd, &si, sizeof si) == (ssize_t)sizeof si)
                printf("signal %u: stopping\n", si.ssi_signo);
            break;
        }
        if (sweep) {
            double ph = fmod((now_s() - t0) / sweep, 1.0);
            units[1]->tab_registers[0] = (uint16_t)lround(1000 * (ph < 0.5 ? 2 * ph : 2 - 2 * ph));
        }
        /* A closed pipe reports POLLHUP without POLLIN; /dev/null POLLIN and then EOF. */
        if (p[IN].revents & (POLLIN | POLLHUP | POLLERR | POLLNVAL)) {
            char line[64];
            if ((p[IN].revents & POLLNVAL) || !fgets(line, sizeof line, stdin)) {
                in_fd = -1;
                printf("stdin closed: panel stays at %d, serving until SIGTERM\n",
                       units[1]->tab_registers[0]);
            } else {
                int v = atoi(line);
                if (v >= 0 && v <= 1000)
                    units[1]->tab_registers[0] = (uint16_t)v;
                printf("panel %d\n", units[1]->tab_registers[0]);
                if (trace)
                    printf("@%.6f panel %d\n", now_s(), units[1]->tab_registers[0]);
            }
            fflush(stdout);
        }
        if (p[LISTEN].revents & POLLIN) {
            int c = accept(lfd, NULL, NULL);
            if (c >= 0 && nc < MAX_CLIENTS)
                clients[nc++] = c;
            else if (c >= 0)
                close(c);
        }
        for (int i = 0; i < nc; i++) {
            if (!p[FIRST_CLIENT + i].revents)
                continue;
            uint8_t q[MODBUS_TCP_MAX_ADU_LENGTH];
            modbus_set_socket(ctx, clients[i]);
            int rc = modbus_receive(ctx, q);
            if (rc > 0) {
                int hl = modbus_get_header_length(ctx);
                int unit = q[hl - 1];
                /* Flushed: a reader of the trace (lamprig-bench's wait for the first poll) must
                 * see a request when it comes, not when 4 KB of them have filled the buffer
                 * (about 5 s of polls: the bench's last two panel steps fell after the run). */
                if (trace) {
                    printf("@%.6f request unit %d function %d\n", now_s(), unit, q[hl]);
                    fflush(stdout);
                }
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
            if (trace)
                printf("@%.6f driver %d\n", now_s(), d);
            fflush(stdout);
            last_driver = d;
        }
    }
    for (int i = 0; i < nc; i++)
        close(clients[i]);
    close(lfd);
    close(sfd);
    modbus_set_socket(ctx, -1);
    modbus_free(ctx);
    modbus_mapping_free(units[1]);
    modbus_mapping_free(units[2]);
    return 0;
}
