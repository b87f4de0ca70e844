/* Section "console": a console fader -> frame latency, the same figures as the rig's other
 * controls (rig_controls.c). The shipped console rig (configs/rig/console.json) runs as a user
 * runs it (`lamprig run`, headless); this process plays the console: every STEP_S it moves the
 * dimmer between two levels, by turns through sACN (unicast), Art-Net and OSC, each packet laid
 * out here from the standards' tables. From the rig's --stats file, per input: event -> the
 * first frame that shows the change (any stage) and -> the first converged frame, and the
 * presented frame interval. Ports: free UDP ports on 127.0.0.1 (the shipped 5568, 6454 and 9000
 * may be in use by a console on this machine); the lamp driver is left unreachable (its retries
 * do not touch the loop's timing). */
#include "tools/bench/bench.h"
#include "tools/bench/proc.h"

#include <arpa/inet.h>
#include <limits.h>
#include <math.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include "render/base/json.h"
#include "render/base/paths.h"

#define READY_S 60.0 /* at most, for the rig to open its inputs (start-up, plan, first view) */
#define STEP_S 0.5
#define TAIL_S 1.0 /* after the last move, for its frames */
#define STEPS 36    /* 12 per input */
#define MAX_EVENTS 256

static const char *const INPUTS[3] = {"sacn", "artnet", "osc"};

static void put16(uint8_t *p, unsigned v)
{
    p[0] = (uint8_t)(v >> 8);
    p[1] = (uint8_t)v;
}

/* E1.31-2018 Table 4-1: a data packet with one slot, universe 1, priority 100. */
static size_t sacn_packet(uint8_t *b, int seq, uint8_t v)
{
    size_t len = 127;
    memset(b, 0, len);
    put16(b, 0x0010);
    memcpy(b + 4, "ASC-E1.17\0\0\0", 12);
    put16(b + 16, 0x7000 | (unsigned)(len - 16));
    b[21] = 0x04;
    memcpy(b + 22, "lamprig-bench-00", 16);
    put16(b + 38, 0x7000 | (unsigned)(len - 38));
    b[43] = 0x02;
    memcpy(b + 44, "lamprig-bench", 13);
    b[108] = 100;
    b[111] = (uint8_t)seq;
    put16(b + 113, 1);
    put16(b + 115, 0x7000 | (unsigned)(len - 115));
    b[117] = 0x02;
    b[118] = 0xa1;
    put16(b + 121, 0x0001);
    put16(b + 123, 2);
    b[126] = v;
    return len;
}

/* Art-Net 4 ArtDmx: port-address 1, two slots (the length must be even). */
static size_t artdmx_packet(uint8_t *b, uint8_t v)
{
    memcpy(b, "Art-Net\0\x00\x50\x00\x0e\x01\x00\x01\x00\x00\x02", 18);
    b[18] = v;
    b[19] = 0;
    return 20;
}

/* OSC 1.0: "/lamprig/dimmer" padded to 4 bytes, ",f" padded, a big-endian float. */
static size_t osc_packet(uint8_t *b, float v)
{
    memset(b, 0, 28);
    memcpy(b, "/lamprig/dimmer", 15); /* 15 + NUL = 16 */
    memcpy(b + 16, ",f", 2);         /* 2 + NUL, padded to 4 */
    uint32_t u;
    memcpy(&u, &v, 4);
    u = htonl(u);
    memcpy(b + 20, &u, 4);
    return 24;
}

/* console.json with absolute paths, the given ports, unicast only, no Art-Net broadcast. */
static int write_cfg(const char *configs, const char *path, const int port[3])
{
    char *text = lrb_read_rig_file(configs, "console.json");
    if (!text)
        return 1;
    char out[16384];
    size_t o = 0;
    for (const char *p = text; *p && o < sizeof out - PATH_MAX - 128; p++) {
        if (!strncmp(p, "\"../", 4)) {
            o += (size_t)snprintf(out + o, sizeof out - o, "\"%s/rig/", configs);
            continue;
        }
        static const char *const dev[3] = {"\"name\": \"sacn\",", "\"name\": \"artnet\",",
                                           "\"name\": \"osc\","};
        bool done = false;
        for (int k = 0; k < 3 && !done; k++)
            if (!strncmp(p, dev[k], strlen(dev[k]))) {
                o += (size_t)snprintf(out + o, sizeof out - o, "%s \"port\": %d,%s", dev[k],
                                      port[k], k == 0   ? " \"unicast_only\": true,"
                                               : k == 1 ? " \"announce\": \"none\","
                                                        : "");
                p += strlen(dev[k]) - 1;
                done = true;
            }
        if (done)
            continue;
        if (!strncmp(p, "\"port\": 9000,", 13)) { /* the osc device's own port: replaced */
            p += 12;
            continue;
        }
        if (!strncmp(p, "tcp://127.0.0.1:1502", 20)) { /* nobody listens on port 9 */
            o += (size_t)snprintf(out + o, sizeof out - o, "tcp://127.0.0.1:9");
            p += 19;
            continue;
        }
        out[o++] = *p;
    }
    out[o] = '\0';
    free(text);
    return lrb_write_file(path, out);
}

/* Whether the rig's log has the line it writes once every device is open ("config PATH: scene
 * .., N devices, .."): before it the inputs' sockets are not bound, and a packet sent then is
 * lost without a trace. The start-up (plan, first view) takes 4-5 s idle and half a minute
 * beside two busy loops; a fixed 4 s wait lost the first moves of every input, and all of
 * them when the start-up ran past the 24 s run. */
static bool rig_ready(const char *log)
{
    FILE *f = fopen(log, "r");
    if (!f)
        return false;
    char line[4096];
    bool ready = false;
    while (!ready && fgets(line, sizeof line, f))
        ready = strstr(line, "lamprig: info: config ") && strstr(line, " devices, ");
    fclose(f);
    return ready;
}

typedef struct row {
    double first[MAX_EVENTS], conv[MAX_EVENTS];
    int n_first, n_conv;
} row;

static int read_stats(const char *stats, row rows[3], double *fi_med, double *fi_p99)
{
    lr_json *j;
    lr_err e = {0};
    if (lr_json_load(stats, &j, &e)) {
        fprintf(stderr, "bench console: %s\n", e.msg);
        return 1;
    }
    lr_jnode root = lr_json_root(j), evs = lr_json_get(j, root, "event_log"),
             frs = lr_json_get(j, root, "frame_log");
    int rc = 0;
    for (int i = 0; !rc && i < lr_json_count(j, evs); i++) {
        lr_jnode ev = lr_json_at(j, evs, i);
        char src[32] = "", ctl[32] = "";
        rc = lr_json_get_string(j, ev, "source", true, src, sizeof src, &e) ||
             lr_json_get_string(j, ev, "control", true, ctl, sizeof ctl, &e);
        int k = -1;
        for (int q = 0; q < 3; q++)
            if (!strcmp(src, INPUTS[q]))
                k = q;
        if (rc || k < 0 || strcmp(ctl, "dimmer"))
            continue;
        double first = NAN, conv = NAN;
        if (lr_json_type(j, lr_json_get(j, ev, "latency_ms")) == LR_JSON_NUMBER)
            rc = lr_json_get_number(j, ev, "latency_ms", true, &first, &e);
        lr_jnode c = lr_json_get(j, ev, "converge_ms");
        if (!rc && c != LR_JNONE && lr_json_type(j, c) == LR_JSON_NUMBER)
            rc = lr_json_get_number(j, ev, "converge_ms", true, &conv, &e);
        if (isfinite(first) && rows[k].n_first < MAX_EVENTS)
            rows[k].first[rows[k].n_first++] = first;
        if (isfinite(conv) && rows[k].n_conv < MAX_EVENTS)
            rows[k].conv[rows[k].n_conv++] = conv;
    }
    int nf = lr_json_count(j, frs);
    double *iv = nf > 1 ? calloc((size_t)nf, sizeof *iv) : NULL;
    double prev = NAN;
    int n_iv = 0;
    for (int i = 0; !rc && i < nf; i++) {
        double t = NAN;
        rc = lr_json_get_number(j, lr_json_at(j, frs, i), "t_s", true, &t, &e);
        if (!rc && iv && isfinite(prev))
            iv[n_iv++] = (t - prev) * 1e3;
        prev = t;
    }
    *fi_med = iv ? lrb_quantile(iv, n_iv, 0.5) : NAN;
    *fi_p99 = iv ? lrb_quantile(iv, n_iv, 0.99) : NAN;
    free(iv);
    if (rc)
        fprintf(stderr, "bench console: %s\n", e.msg);
    lr_json_destroy(j);
    return rc;
}

/* One run of the console rig with `busy` busy loops beside it: the dimmer moved STEPS times
 * by turns through the three inputs; the stats read into rows. Nonzero when the run failed. */
static int measure(const char *lamprig, const char *cfg, const char *stats, const char *log,
                   const int port[3], int busy, row rows[3], double *fi_med, double *fi_p99)
{
    /* The rig stops on SIGTERM after the last move; the duration is only a guard. */
    char dur[32];
    snprintf(dur, sizeof dur, "%.1f", READY_S + STEPS * STEP_S + TAIL_S + 30);
    int tx = socket(AF_INET, SOCK_DGRAM, 0);
    if (tx < 0)
        return 1;
    pid_t loops[2];
    if (busy && lrb_busy_start(busy, loops)) {
        close(tx);
        return 1;
    }
    fprintf(stderr, "bench console: the shipped console rig, %d moves, %d busy loops...\n", STEPS,
            busy);
    char *argv[] = {(char *)lamprig, "run", "--config", (char *)cfg, "--headless",
                    "--duration", dur, "--stats", (char *)stats, NULL};
    /* The log of the run before would read as ready at once. */
    unlink(log);
    unlink(stats);
    pid_t pid = lrb_spawn(argv, log);
    double waited = 0;
    for (; pid > 0 && waited < READY_S && !rig_ready(log); waited += 0.05)
        lrb_sleep_s(0.05);
    if (pid <= 0 || waited >= READY_S) {
        fprintf(stderr, "bench console: the rig did not open its inputs within %.0f s\n", READY_S);
        if (pid > 0) {
            kill(pid, SIGTERM);
            lrb_reap(pid, 30);
        }
        close(tx);
        if (busy)
            lrb_busy_stop(busy, loops);
        lrb_print_log(log);
        return 1;
    }
    for (int i = 0; i < STEPS; i++) {
        int k = i % 3;
        /* The level alternates 60 and 200 of 255 from step to step, whichever input sends
         * it: every packet is a change (the three inputs feed one binding, and a repeated
         * level would change nothing and not be an event of the stats). */
        uint8_t v = i % 2 ? 200 : 60;
        uint8_t b[700];
        size_t len = k == 0   ? sacn_packet(b, i / 3, v)
                     : k == 1 ? artdmx_packet(b, v)
                              : osc_packet(b, v / 255.0f);
        struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port[k]),
                                .sin_addr.s_addr = htonl(INADDR_LOOPBACK)};
        if (sendto(tx, b, len, 0, (struct sockaddr *)&a, sizeof a) != (ssize_t)len)
            fprintf(stderr, "bench console: send to %s failed\n", INPUTS[k]);
        lrb_sleep_s(STEP_S);
    }
    close(tx);
    lrb_sleep_s(TAIL_S);
    kill(pid, SIGTERM);
    int st = lrb_reap(pid, 300);
    if (busy)
        lrb_busy_stop(busy, loops);
    if (st < 0 || !WIFEXITED(st) || WEXITSTATUS(st) != 0) {
        fprintf(stderr, "bench console: lamprig run failed (status %#x):\n", st);
        lrb_print_log(log);
        return 1;
    }
    return read_stats(stats, rows, fi_med, fi_p99);
}

static int run(FILE *out)
{
    char bindir[PATH_MAX], configs[PATH_MAX];
    if (lrb_rig_paths("console", bindir, sizeof bindir, configs))
        return 1;
    char dir[] = "/tmp/lamprig-bench-console-XXXXXX";
    if (!mkdtemp(dir))
        return 1;
    int port[3] = {lrb_free_port(SOCK_DGRAM), lrb_free_port(SOCK_DGRAM), lrb_free_port(SOCK_DGRAM)};
    char cfg[PATH_MAX], stats[PATH_MAX], log[PATH_MAX], lamprig[PATH_MAX + 16];
    snprintf(cfg, sizeof cfg, "%s/console.json", dir);
    snprintf(stats, sizeof stats, "%s/stats.json", dir);
    snprintf(log, sizeof log, "%s/rig.log", dir);
    snprintf(lamprig, sizeof lamprig, "%s/lamprig", bindir);
    if (port[0] < 0 || port[1] < 0 || port[2] < 0 || write_cfg(configs, cfg, port)) {
        fprintf(stderr, "bench console: no free UDP ports or cannot write %s\n", cfg);
        return 1;
    }
    /* Idle, then with two busy loops beside the rig (a Pi runs other work too). */
    static row rows[2][3];
    double fi_med[2] = {NAN, NAN}, fi_p99[2] = {NAN, NAN};
    int rc = 0;
    for (int busy = 0; busy < 2 && rc == 0; busy++)
        rc = measure(lamprig, cfg, stats, log, port, busy ? 2 : 0, rows[busy], &fi_med[busy],
                     &fi_p99[busy]);
    fprintf(out, "## Console input: `lamprig run` on `configs/rig/console.json`, headless\n\n"
                 "The dimmer moved %d times, every %.1f s, by turns through sACN (unicast), "
                 "Art-Net and OSC on 127.0.0.1, from the rig's inputs opening. First change: event "
                 "(the packet's arrival) to the end of the first frame showing it; converged: "
                 "to the first converged frame showing it; frame interval over the run. Each run "
                 "idle, then beside two busy loops.\n\n"
                 "| input | beside | control | events | first change median / p99 | converged "
                 "median / p99 (events) | frame interval median / p99 |\n"
                 "|---|---|---|---|---|---|---|\n",
            STEPS, STEP_S);
    int failed = 0;
    for (int q = 0; q < 6 && rc == 0; q++) {
        int busy = q / 3, k = q % 3;
        row *r = &rows[busy][k];
        fprintf(out, "| %s | %s | dimmer | %d | ", INPUTS[k], busy ? "2 busy loops" : "idle",
                r->n_first);
        if (r->n_first)
            fprintf(out, "%.0f / %.0f ms | ", lrb_quantile(r->first, r->n_first, 0.5),
                    lrb_quantile(r->first, r->n_first, 0.99));
        else /* nothing to take a median of: say so, and the section fails */
            fprintf(out, "no event reached a frame in the run | ");
        if (!r->n_first)
            failed = 1;
        if (r->n_conv)
            fprintf(out, "%.0f / %.0f ms (%d) |", lrb_quantile(r->conv, r->n_conv, 0.5),
                    lrb_quantile(r->conv, r->n_conv, 0.99), r->n_conv);
        else
            fprintf(out, "none converged in the run |");
        fprintf(out, " %.1f / %.1f ms |\n", fi_med[busy], fi_p99[busy]);
    }
    double load[3] = {0};
    if (getloadavg(load, 3) < 1)
        load[0] = -1;
    fprintf(out, "\nLoad average %.2f at the end, %ld CPUs.\n\n", load[0],
            sysconf(_SC_NPROCESSORS_ONLN));
    char cmd[PATH_MAX + 16];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "bench console: could not remove %s\n", dir);
    if (failed)
        fprintf(stderr, "bench console: an input's events never reached a frame\n");
    return rc ? rc : failed;
}

const lrb_section lrb_console_section = {
    .name = "console",
    .summary = "lamprig run on the console rig: sACN, Art-Net and OSC dimmer to frame latency",
    .run = run,
};
