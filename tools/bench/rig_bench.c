/* Section "rig": the firmware, `lamprig run`, measured from outside as a child process (the
 * release build/bin/lamprig next to this binary).
 * (1) Control-to-frame latency of a dimmer turn, headless: the shipped sim rig's budget and
 *     control map (configs/rig/sim.json: the settings its planner picks for the budget, 320×240,
 *     30 fps cap, the candle's dimmer with its square curve and 0.25 s fade), driven by a sim script of
 *     60 dimmer turns over 30 s; median and p99 of the per-event latencies in its --stats file.
 * (2) Idle CPU when nothing changes: utime + stime from /proc/PID/stat over 10 s, once the
 *     scene has converged (one scripted dimmer move, then no events) with the flame steady;
 *     the same rig as shipped, whose flickering flame composes a frame every frame interval
 *     and so is never idle (its steady-state cost); and the Modbus demo rig against
 *     lamprig-modbus-sim, whose panel is polled every 50 ms. */
#include "tools/bench/bench.h"
#include "tools/bench/proc.h"

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <netinet/in.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "render/base/atomic_file.h"
#include "render/base/json.h"
#include "render/base/paths.h"

#define TURNS 60
#define TURN_SPACING_S 0.5
#define IDLE_WINDOW_S 10.0
#define STABLE_WINDOW_S 2.0
#define STABLE_MAX_S 40.0

static char bindir[PATH_MAX];
static char configs[PATH_MAX]; /* absolute: the rig configs are written to a scratch dir */

/* utime + stime of pid in clock ticks, or -1. */
static long cpu_ticks(pid_t pid)
{
    char path[64], buf[1024];
    snprintf(path, sizeof path, "/proc/%d/stat", (int)pid);
    FILE *f = fopen(path, "r");
    if (!f)
        return -1;
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = '\0';
    char *p = strrchr(buf, ')'); /* the command name may contain spaces */
    if (!p)
        return -1;
    unsigned long ut = 0, st = 0;
    /* after ')': state(3) ... utime is field 14, stime 15 */
    if (sscanf(p + 2, "%*c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %lu %lu", &ut, &st) != 2)
        return -1;
    return (long)(ut + st);
}

/* A rig config with the shipped sim rig's budget (its "budget" object, copied from
 * configs/rig/sim.json), output and control map, driven by script; extra_set: scene_set
 * entries (", \"key\": value"), or "". */
static int write_rig_set(const char *path, const char *script, const char *extra_set)
{
    char *shipped = lrb_read_rig_file(configs, "sim.json");
    const char *b = shipped ? strstr(shipped, "\"budget\"") : NULL;
    const char *end = b ? strchr(b, '}') : NULL;
    if (!end) {
        fprintf(stderr, "bench rig: configs/rig/sim.json has no \"budget\" object\n");
        free(shipped);
        return 1;
    }
    char text[3 * PATH_MAX + 1024];
    snprintf(text, sizeof text,
             "{\"scene\": \"%s/scenes/candle.json\",\n"
             " %.*s,\n"
             " \"scene_set\": {%s},\n"
             " \"devices\": [{\"type\": \"sim\", \"name\": \"sim\", \"script\": \"%s\"}],\n"
             " \"controls\": \"%s/controls/candle.json\",\n"
             " \"output\": {\"mode\": \"headless\", \"width\": 320, \"height\": 240, \"fps\": 30},\n"
             " \"safe_level\": 0, \"stats\": {\"period_s\": 60}}\n",
             configs, (int)(end + 1 - b), b, extra_set[0] ? extra_set + 2 : "", script,
             configs);
    free(shipped);
    return lrb_write_file(path, text);
}

/* steady: the flame's flicker off (the candle flickers by default, and a flickering light
 * wants a frame every frame interval, so the rig is never idle). */
static int write_rig(const char *path, const char *script, bool steady)
{
    return write_rig_set(path, script, steady ? ", \"lights[0].flicker.amplitude\": 0" : "");
}

typedef struct latency {
    long n, pending, frames;
    double median, p99, max, duration;
} latency;

static int read_stats(const char *path, latency *l)
{
    lr_json *j;
    lr_err e = {0};
    if (lr_json_load(path, &j, &e)) {
        fprintf(stderr, "bench rig: %s\n", e.msg);
        return 1;
    }
    lr_jnode root = lr_json_root(j), lat = lr_json_get(j, root, "latency_ms");
    int rc = lr_json_get_int(j, root, "frames", true, &l->frames, &e) ||
             lr_json_get_int(j, root, "events_pending", true, &l->pending, &e) ||
             lr_json_get_number(j, root, "duration_s", true, &l->duration, &e) ||
             lr_json_get_int(j, lat, "n", true, &l->n, &e) ||
             lr_json_get_number(j, lat, "median", true, &l->median, &e) ||
             lr_json_get_number(j, lat, "p99", true, &l->p99, &e) ||
             lr_json_get_number(j, lat, "max", true, &l->max, &e);
    if (rc)
        fprintf(stderr, "bench rig: %s\n", e.msg);
    lr_json_destroy(j);
    return rc;
}

static int dimmer_latency(const char *dir, latency *l)
{
    char script[PATH_MAX], cfg[PATH_MAX], stats[PATH_MAX], log[PATH_MAX];
    snprintf(script, sizeof script, "%s/turns.sim", dir);
    snprintf(cfg, sizeof cfg, "%s/turns.json", dir);
    snprintf(stats, sizeof stats, "%s/turns-stats.json", dir);
    snprintf(log, sizeof log, "%s/turns.log", dir);
    /* Turns every 0.5 s, starting after 1 s (the first full frame is done), between 20 % and
     * 100 %, each to a new position. */
    char text[8192];
    size_t len = 0;
    for (int i = 0; i < TURNS; i++)
        len += (size_t)snprintf(text + len, sizeof text - len, "%.2f dimmer absolute %.3f\n",
                                1.0 + TURN_SPACING_S * i, 0.2 + 0.8 * ((i * 5) % 9) / 8.0);
    snprintf(text + len, sizeof text - len, "%.2f end\n", 1.0 + TURN_SPACING_S * TURNS);
    if (lrb_write_file(script, text) || write_rig(cfg, script, false))
        return 1;
    char duration[32];
    snprintf(duration, sizeof duration, "%.1f", 1.0 + TURN_SPACING_S * TURNS + 1.0);
    char lamprig[PATH_MAX + 16];
    snprintf(lamprig, sizeof lamprig, "%s/lamprig", bindir);
    char *argv[] = {lamprig, "run", "--config", cfg, "--headless", "--duration", duration,
                    "--stats", stats, NULL};
    int st = lrb_reap(lrb_spawn(argv, log), 120);
    if (st < 0 || !WIFEXITED(st) || WEXITSTATUS(st) != 0) {
        fprintf(stderr, "bench rig: lamprig run failed (status %#x):\n", st);
        lrb_print_log(log);
        return 1;
    }
    return read_stats(stats, l);
}

/* One idle-CPU row: the figure, or why there is none. */
typedef struct idle_row {
    double pct;     /* % of one core over IDLE_WINDOW_S, -1 when not measured */
    bool quiet;     /* the process went quiet (no tick in 0.5 s) before the window */
    bool stable;    /* its CPU % was steady (or quiet) before the window */
    char why[192];  /* when not measured, or a note on the figure */
} idle_row;

/* Starts argv and measures its CPU % over IDLE_WINDOW_S. wait_quiet: first wait (30 s at most)
 * until it uses no tick in 0.5 s (the scene converged, the fades done); when it never does,
 * the window is measured anyway and the row says so. Otherwise after a fixed 3 s warm-up (a
 * flickering flame composes every frame and is never quiet). Returns 1 on a real error (it
 * could not start, exited on its own, or did not exit cleanly on SIGTERM; the log goes to
 * stderr), else 0 with the figure or the reason in *row. */
static int idle_cpu_after(char *const argv[], const char *log, bool wait_quiet, double warm_s,
                          idle_row *row);
static int idle_cpu(char *const argv[], const char *log, bool wait_quiet, idle_row *row)
{
    return idle_cpu_after(argv, log, wait_quiet, wait_quiet ? 30.0 : 3.0, row);
}

#define AHEAD_MAX_S 150.0

/* 0 when the log file holds `what`, else 1 (not yet, or unreadable). */
static int log_has(const char *log, const char *what)
{
    FILE *f = fopen(log, "r");
    if (!f)
        return 1;
    char line[1024];
    int found = 1;
    while (found && fgets(line, sizeof line, f))
        if (strstr(line, what))
            found = 0;
    fclose(f);
    return found;
}

/* As idle_cpu, with the longest wait for quiet (wait_quiet) or the fixed warm-up given. */
static int idle_cpu_after(char *const argv[], const char *log, bool wait_quiet, double warm_s,
                          idle_row *row)
{
    *row = (idle_row){.pct = -1};
    /* The child truncates the log once started: an earlier run's lines must not be read as
     * this one's before that (the wait for the states ahead below reads it). */
    unlink(log);
    pid_t pid = lrb_spawn(argv, log);
    if (pid < 0) {
        snprintf(row->why, sizeof row->why, "could not start %s", argv[0]);
        return 1;
    }
    long prev = -1;
    bool alive = true;
    /* Idle means after the states ahead are built (firmware/rig/ahead.h: the rig's background
     * work once its controls rest, 40 s on the proxy): wait for its log line, AHEAD_MAX_S at
     * most (a rig without a cache never writes it). */
    for (double w = 0; w < AHEAD_MAX_S && log_has(log, "cache: states built ahead"); w += 0.5)
        lrb_sleep_s(0.5);
    for (int i = 0; i < (int)(warm_s / 0.5 + 0.5); i++) {
        lrb_sleep_s(0.5);
        long t = cpu_ticks(pid);
        if (t < 0) {
            alive = false;
            break;
        }
        if (wait_quiet && prev >= 0 && t - prev == 0 && i >= 6) {
            row->quiet = true;
            break;
        }
        prev = t;
    }
    /* Without quiet to wait for (a flickering flame), the warm-up alone can end before the
     * scene converged on a loaded machine: accumulation frames cost a core, the blend alone a
     * few %. So also wait, STABLE_MAX_S at most, for two successive STABLE_WINDOW_S windows
     * whose CPU % agree within 25 % (or both under 1 %). */
    row->stable = wait_quiet;
    double prev_pct = -1.0;
    for (double waited = 0.0; alive && !wait_quiet && waited < STABLE_MAX_S;
         waited += STABLE_WINDOW_S) {
        long a = cpu_ticks(pid);
        double wa = lrb_now();
        lrb_sleep_s(STABLE_WINDOW_S);
        long b = cpu_ticks(pid);
        if (a < 0 || b < a) {
            alive = false;
            break;
        }
        double pct = 100.0 * (double)(b - a) / (double)sysconf(_SC_CLK_TCK) / (lrb_now() - wa);
        if (prev_pct >= 0.0 && ((pct < 1.0 && prev_pct < 1.0) ||
                                (pct <= 1.25 * prev_pct && prev_pct <= 1.25 * pct))) {
            row->stable = true;
            break;
        }
        prev_pct = pct;
    }
    if (alive) {
        long t0 = cpu_ticks(pid);
        double w0 = lrb_now();
        lrb_sleep_s(IDLE_WINDOW_S);
        long t1 = cpu_ticks(pid);
        double w1 = lrb_now();
        if (t0 >= 0 && t1 >= t0)
            row->pct = 100.0 * (double)(t1 - t0) / (double)sysconf(_SC_CLK_TCK) / (w1 - w0);
        else
            alive = false;
    }
    if (wait_quiet && !row->quiet && row->pct >= 0)
        snprintf(row->why, sizeof row->why,
                 "never idle: no 0.5 s without CPU in 30 s (the scene kept rendering)");
    else if (!row->stable && row->pct >= 0)
        snprintf(row->why, sizeof row->why,
                 "never steady: no two %.0f s windows within 25 %% in %.0f s", STABLE_WINDOW_S,
                 STABLE_MAX_S);
    /* A zombie still has its /proc entry; whether it exited on its own shows in its status. */
    int st = 0;
    bool exited = waitpid(pid, &st, WNOHANG) == pid;
    if (!exited && !alive) { /* its /proc entry unreadable: make sure it is gone */
        st = lrb_reap(pid, 10);
        exited = true;
    }
    if (exited) {
        snprintf(row->why, sizeof row->why, "lamprig run exited on its own (status %#x)", st);
        fprintf(stderr, "bench rig: %s:\n", row->why);
        lrb_print_log(log);
        row->pct = -1;
        return 1;
    }
    kill(pid, SIGTERM);
    st = lrb_reap(pid, 10);
    if (st < 0 || !WIFEXITED(st) || WEXITSTATUS(st) != 0) {
        snprintf(row->why, sizeof row->why,
                 "lamprig run did not exit cleanly on SIGTERM (status %#x)", st);
        fprintf(stderr, "bench rig: %s:\n", row->why);
        lrb_print_log(log);
        row->pct = -1;
        return 1;
    }
    return 0;
}

static void print_idle_row(FILE *out, const char *rig, const idle_row *row)
{
    if (row->pct >= 0)
        fprintf(out, "| %s | %.2f %% of one core%s%s |\n", rig, row->pct, row->why[0] ? "; " : "",
                row->why);
    else
        fprintf(out, "| %s | not measured: %s |\n", rig, row->why[0] ? row->why : "unknown");
}

/* Issue 11: idle CPU with the flame flickering or steady. A flickering flame wants a frame (the
 * blend pass alone once converged) every frame interval, so the process never goes quiet:
 * instead of waiting for quiet, wait SETTLE_S and then until the CPU % is steady
 * (idle_cpu_after), then the CPU % over IDLE_WINDOW_S. A steady flame waits for quiet. */
#define SETTLE_S 10.0

/* configs/rig/modbus-demo.json with its scene path made absolute and the flame's flicker
 * amplitude set to amp (the demo ships it at 0). */
static int write_modbus_flicker(const char *src, const char *path, double amp)
{
    FILE *f = fopen(src, "r");
    if (!f)
        return 1;
    char in[8192], out[8192 + PATH_MAX];
    size_t n = fread(in, 1, sizeof in - 1, f);
    fclose(f);
    in[n] = '\0';
    const char *key = "\"lights[0].flicker.amplitude\": 0", *scn = "\"../scenes/candle.json\"";
    char *k = strstr(in, key), *sc = strstr(in, scn);
    if (!k || !sc || sc > k)
        return 1;
    *sc = '\0';
    *k = '\0';
    int m = snprintf(out, sizeof out,
                     "%s\"%s/scenes/candle.json\"%s\"lights[0].flicker.amplitude\": %g%s", in,
                     configs, sc + strlen(scn), amp, k + strlen(key));
    if (m < 0 || (size_t)m >= sizeof out)
        return 1;
    return lrb_write_file(path, out);
}

static int run(FILE *out)
{
    if (lrb_rig_paths("rig", bindir, sizeof bindir, configs))
        return 1;
    char dir[] = "/tmp/lamprig-bench-rig-XXXXXX";
    if (!mkdtemp(dir))
        return 1;
    fprintf(out, "## Rig firmware: `lamprig run`, headless\n\n");
    fflush(out);
    latency l = {0};
    int rc = dimmer_latency(dir, &l);
    /* The figures README.md's block is made of (tools/bench/figures.c). */
    lr_atomic_file *af = NULL;
    lr_err ce = {0};
    if (((mkdir("build", 0777) && errno != EEXIST) ||
         (mkdir("build/bench", 0777) && errno != EEXIST)) ||
        lr_atomic_file_open("build/bench/rig.csv", &af, &ce)) {
        fprintf(stderr, "bench rig: cannot write build/bench/rig.csv: %s\n",
                ce.msg[0] ? ce.msg : strerror(errno));
        af = NULL;
    }
    FILE *csv = af ? lr_atomic_file_stream(af) : NULL;
    if (csv)
        fprintf(csv, "run,control,figure,value\n");
    rc |= lrb_rig_controls(out, csv, bindir, configs, dir);
    int mb_port = lrb_free_port(SOCK_STREAM);
    if (mb_port > 0)
        rc |= lrb_rig_modbus(out, csv, bindir, configs, dir, mb_port);
    else
        fprintf(out, "The Modbus demo rows: not measured (no free TCP port on 127.0.0.1).\n\n");

    char lamprig[PATH_MAX + 16], cfg[PATH_MAX], script[PATH_MAX], log[PATH_MAX];
    snprintf(lamprig, sizeof lamprig, "%s/lamprig", bindir);
    snprintf(script, sizeof script, "%s/once.sim", dir);
    snprintf(cfg, sizeof cfg, "%s/once.json", dir);
    snprintf(log, sizeof log, "%s/idle.log", dir);
    /* The idle rows: the scene steady (flicker off) and as shipped (the flame flickering). */
    idle_row idle_sim = {.pct = -1}, idle_mb = {.pct = -1};
    int real_error = 0;
    char *argv[] = {lamprig, "run", "--config", cfg, "--headless", NULL};
    if (lrb_write_file(script, "0.0 dimmer absolute 0.6\n0.1 end\n") || write_rig(cfg, script, true)) {
        snprintf(idle_sim.why, sizeof idle_sim.why, "cannot write the scratch rig config");
        real_error = 1;
    } else {
        real_error |= idle_cpu(argv, log, true, &idle_sim);
    }
    /* The Modbus demo rig against the simulator: a converged scene, the panel still polled. */
    int port = lrb_free_port(SOCK_STREAM);
    char sim_bin[PATH_MAX + 32], port_s[16], url[64], mb_cfg[PATH_MAX + 32], sim_log[PATH_MAX + 32];
    snprintf(sim_bin, sizeof sim_bin, "%s/lamprig-modbus-sim", bindir);
    snprintf(port_s, sizeof port_s, "%d", port);
    snprintf(url, sizeof url, "tcp://127.0.0.1:%d", port);
    snprintf(mb_cfg, sizeof mb_cfg, "%s/rig/modbus-demo.json", configs);
    snprintf(sim_log, sizeof sim_log, "%s/modbus-sim.log", dir);
    if (port <= 0) {
        snprintf(idle_mb.why, sizeof idle_mb.why, "no free TCP port on 127.0.0.1");
    } else if (access(sim_bin, X_OK) != 0) {
        snprintf(idle_mb.why, sizeof idle_mb.why, "lamprig-modbus-sim not built next to lamprig-bench");
    } else {
        char *sargv[] = {sim_bin, "--port", port_s, "--panel", "600", NULL};
        pid_t sim = lrb_spawn(sargv, sim_log);
        lrb_sleep_s(0.5);
        char *margv[] = {lamprig, "run", "--config", mb_cfg, "--modbus", url, "--headless", NULL};
        real_error |= idle_cpu(margv, log, true, &idle_mb);
        kill(sim, SIGTERM);
        if (lrb_reap(sim, 5) != 0) {
            fprintf(stderr, "bench rig: lamprig-modbus-sim did not exit cleanly on SIGTERM:\n");
            lrb_print_log(sim_log);
            real_error = 1;
        }
    }
    /* Issue 11: both sim rigs converged, flame flickering (candle.json: amplitude 0.08) and
     * steady. [rig][flicker off, on]. */
    idle_row idle_fl[2][2];
    for (int on = 0; on < 2; on++) {
        idle_fl[0][on] = (idle_row){.pct = -1, .why = "cannot write the scratch rig config"};
        idle_fl[1][on] = idle_mb.pct >= 0 ? (idle_row){.pct = -1, .why = "cannot write the "
                                                       "scratch rig config"}
                                          : idle_mb;
    }
    for (int on = 0; on < 2; on++) {
        char fcfg[PATH_MAX + 32];
        snprintf(fcfg, sizeof fcfg, "%s/flicker%d.json", dir, on);
        if (!write_rig_set(fcfg, script, on ? "" : ", \"lights[0].flicker.amplitude\": 0")) {
            char *fargv[] = {lamprig, "run", "--config", fcfg, "--headless", NULL};
            real_error |= idle_cpu_after(fargv, log, !on, on ? SETTLE_S : 30.0, &idle_fl[0][on]);
        }
        snprintf(fcfg, sizeof fcfg, "%s/modbus-flicker%d.json", dir, on);
        if (port > 0 && access(sim_bin, X_OK) == 0 &&
            !write_modbus_flicker(mb_cfg, fcfg, on ? 0.08 : 0.0)) {
            char *sargv[] = {sim_bin, "--port", port_s, "--panel", "600", NULL};
            pid_t sim = lrb_spawn(sargv, sim_log);
            lrb_sleep_s(0.5);
            char *fargv[] = {lamprig, "run", "--config", fcfg, "--modbus", url, "--headless", NULL};
            real_error |= idle_cpu_after(fargv, log, !on, on ? SETTLE_S : 30.0, &idle_fl[1][on]);
            kill(sim, SIGTERM);
            lrb_reap(sim, 5);
        }
    }

    if (csv) {
        /* How idle "idle" was: the 1-minute load average as the section ends. */
        double la[3] = {0};
        if (getloadavg(la, 3) >= 1)
            fprintf(csv, "host,,load_average,%.2f\n", la[0]);
        for (int on = 0; on < 2; on++) {
            if (idle_fl[0][on].pct >= 0)
                fprintf(csv, "sim,,idle_cpu_%s_pct,%.2f\n", on ? "flickering" : "steady",
                        idle_fl[0][on].pct);
            if (idle_fl[1][on].pct >= 0)
                fprintf(csv, "modbus_idle,,idle_cpu_%s_pct,%.2f\n",
                        on ? "flickering" : "steady", idle_fl[1][on].pct);
        }
        if (lr_atomic_file_commit(af, &ce)) {
            fprintf(stderr, "bench rig: %s\n", ce.msg);
            real_error = 1;
        } else {
            fprintf(out, "Wrote build/bench/rig.csv (README.md's figures block: "
                         "tools/bench/README.md, \"The README's figures\").\n\n");
        }
    }
    if (rc == 0) {
        fprintf(out, "Control-to-frame latency of a dimmer turn: %d absolute dimmer moves, one "
                     "every %.1f s, through the candle's control map (square curve, 0.25 s fade) "
                     "with the shipped sim rig's budget (`budget` in configs/rig/sim.json: "
                     "the settings its planner picks, 320×240, 30 fps cap); per-event "
                     "latency from the stats "
                     "(event timestamp to the end of the first frame after it that runs a "
                     "pass: the fade's first frame, still at the old level, does not "
                     "count).\n\n",
                TURNS, TURN_SPACING_S);
        fprintf(out, "| events | median | p99 | max | frames in %.0f s | pending at exit |\n"
                     "|---|---|---|---|---|---|\n",
                l.duration);
        fprintf(out, "| %ld | %.1f ms | %.1f ms | %.1f ms | %ld | %ld |\n\n", l.n, l.median,
                l.p99, l.max, l.frames, l.pending);
    } else {
        fprintf(out, "Dimmer latency: the run failed.\n\n");
    }
    fprintf(out, "Idle CPU of `lamprig run` once converged, with nothing changing "
                 "(utime + stime from /proc/PID/stat over %.0f s):\n\n"
                 "| rig | idle CPU |\n|---|---|\n",
            IDLE_WINDOW_S);
    print_idle_row(out, "sim rig, flame steady (flicker amplitude 0), script ended", &idle_sim);
    print_idle_row(out, "modbus-demo against lamprig-modbus-sim (panel polled every 50 ms)",
                   &idle_mb);
    fprintf(out, "\nIdle CPU once converged with the flame flickering (candle.json: amplitude "
                 "0.08; one blend pass per frame at the 30 fps cap) and steady (amplitude 0), "
                 "over %.0f s: flickering, once two %.0f s windows agree within 25 %% (at "
                 "least %.0f s after start); steady, once quiet (issue 11 targets: < 10 %% and "
                 "< 2 %% of one core):\n\n| rig | flicker on | flicker off |\n|---|---|---|\n",
            IDLE_WINDOW_S, STABLE_WINDOW_S, SETTLE_S);
    const char *rig_names[2] = {"sim rig (320×240)", "modbus-demo against lamprig-modbus-sim"};
    for (int i = 0; i < 2; i++) {
        char on_s[256], off_s[256];
        for (int on = 0; on < 2; on++) {
            const idle_row *row = &idle_fl[i][on];
            char *dst = on ? on_s : off_s;
            if (row->pct >= 0)
                snprintf(dst, 256, "%.2f %% of one core", row->pct);
            else
                snprintf(dst, 256, "not measured: %s", row->why[0] ? row->why : "unknown");
        }
        fprintf(out, "| %s | %s | %s |\n", rig_names[i], on_s, off_s);
    }
    char cpu[256];
    lrb_cpu_name(cpu, sizeof cpu);
    long ncpu = sysconf(_SC_NPROCESSORS_ONLN);
    double load[3] = {0};
    if (getloadavg(load, 3) < 1)
        load[0] = -1;
    fprintf(out, "\nHost: %s, %ld CPUs, load average %.2f at the end; GL: whatever EGL gives "
                 "headless (Mesa llvmpipe without a GPU).\n\n",
            cpu, ncpu, load[0]);
    char cmd[PATH_MAX + 16];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "bench rig: could not remove %s\n", dir);
    /* A row that could not be measured says why in the table; only a real error (a run that
     * failed, exited on its own or not cleanly on SIGTERM) fails the section. */
    return rc || real_error;
}

const lrb_section lrb_rig_section = {
    .name = "rig",
    .summary = "lamprig run: dimmer control-to-frame latency (median, p99) and idle CPU",
    .run = run,
};
