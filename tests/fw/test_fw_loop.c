/* The rig's loop: a sim script drives it headless (in-process under ASan, and as
 * build/bin/lamprig with --duration); SIGTERM mid-run → exit 0, the lamp driver at its safe
 * level (a libmodbus server on loopback), stats flushed; SIGHUP with a broken config keeps the
 * old one and names file/line/field, with a good one applies it. Latency stats: one entry per
 * event that changed something, each non-negative. The soak: 30 s (three loops of its script)
 * of the shipped sim demo as `lamprig run` in a sanitized child, ended by SIGTERM
 * (LAMPRIG_SOAK_S sets the length: `make soak` runs 120 s);
 * a fast one (19000 events/s, beside four misbehaving Modbus peers) whose resident memory and
 * descriptors stay flat and whose frames keep coming. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "firmware/cli.h"
#include "firmware/rig/rig.h"
#include "hal/dev.h"
#include "render/base/json.h"
#include "render/scene/scene.h"
#include "tests/support/fs.h"
#include "tests/support/gl.h"
#include "tests/support/hal_test.h"
#include "tests/support/modbus_rogue.h"
#include "tests/support/modbus_server.h"
#include "tests/support/near.h"
#include "tests/support/proc.h"

#define MS 1000000LL
#define LAMPRIG LR_SOURCE_CONFIGS "/../build/bin/lamprig"

static double scene_num(lr_rig *r, const char *key)
{
    char buf[128];
    lr_err e = {0};
    if (lr_scene_get(lr_rig_scene(r), key, buf, sizeof buf, &e))
        fail_msg("%s", e.msg);
    return strtod(buf, NULL);
}

/* Checks a stats file: counts, and every event's latency >= 0 with a frame index, under
 * MAX_LATENCY_MS; returns the number of events logged. The bound catches an event never shown
 * (a loop stuck behind work), not the work's cost, which `make bench` measures: the sim
 * script's first preset (wax to marble) re-plans and re-solves the candle's light on the CPU
 * inside the loop, measured from the event to its frame at 2.1 s without sanitizers and
 * 5.1-5.4 s under ASan on an idle 2-core machine; tests/run.sh runs another binary beside this
 * one, which gives the rig about half the CPUs and doubles that, and a loaded CI machine more. */
#define MAX_LATENCY_MS 30000.0
static int check_stats(const char *path, int min_frames, int min_events)
{
    lr_json *j;
    lr_err e = {0};
    if (lr_json_load(path, &j, &e))
        fail_msg("%s", e.msg);
    lr_jnode root = lr_json_root(j);
    long frames = 0, events = 0;
    assert_int_equal(lr_json_get_int(j, root, "frames", true, &frames, &e), LR_OK);
    assert_int_equal(lr_json_get_int(j, root, "events", true, &events, &e), LR_OK);
    assert_true(frames >= min_frames);
    assert_true(events >= min_events);
    lr_jnode log = lr_json_get(j, root, "event_log");
    assert_int_equal(lr_json_count(j, log), (int)events);
    for (int i = 0; i < lr_json_count(j, log); i++) {
        lr_jnode ev = lr_json_at(j, log, i);
        double lat = -1, frame = -1;
        assert_int_equal(lr_json_get_number(j, ev, "latency_ms", true, &lat, &e), LR_OK);
        assert_int_equal(lr_json_get_number(j, ev, "frame", true, &frame, &e), LR_OK);
        if (!(lat >= 0 && lat < MAX_LATENCY_MS)) {
            char ctl[64] = "?";
            double t = -1;
            lr_json_get_string(j, ev, "control", false, ctl, sizeof ctl, &e);
            lr_json_get_number(j, ev, "t_s", false, &t, &e);
            fail_msg("%s: event %d (%s at %.2f s, frame %.0f): latency %.0f ms, not in [0, %.0f)",
                     path, i, ctl, t, frame, lat, MAX_LATENCY_MS);
        }
        assert_true(frame >= 0 && frame < (double)frames);
    }
    if (events > 0) {
        lr_jnode lat = lr_json_get(j, root, "latency_ms");
        double med = -1, p99 = -1;
        assert_int_equal(lr_json_get_number(j, lat, "median", true, &med, &e), LR_OK);
        assert_int_equal(lr_json_get_number(j, lat, "p99", true, &p99, &e), LR_OK);
        assert_true(med >= 0 && p99 >= med);
    }
    lr_json_destroy(j);
    return (int)events;
}

/* In-process: a scripted dimmer with a fade, a material cycle and a flicker knob; the scene
 * ends where the script says, and the stats have one non-negative latency per event. */
static void test_sim_in_process(void **state)
{
    (void)state;
    char *dir = lr_test_tmpdir();
    char text[2048];
    snprintf(text, sizeof text,
             "{\"scene\": \"%s/scenes/candle.json\",\n"
             " \"devices\": [{\"type\": \"sim\", \"text\": \"0.05 dimmer absolute 0.5\\n"
             "0.10 button1 press\\n0.15 button1 release\\n0.20 knob1 delta 2\\n"
             "0.30 dimmer absolute 1.0\\n0.35 nothing press\\n\"}],\n"
             " \"controls\": [\n"
             "  {\"control\": \"dimmer\", \"param\": \"light.intensity\", \"range\": [0, 0.01],\n"
             "   \"curve\": \"square\", \"fade_s\": 0.1},\n"
             "  {\"control\": \"button1\", \"param\": \"objects[0].material\",\n"
             "   \"values\": [\"candle_wax\", \"marble\"]},\n"
             "  {\"control\": \"knob1\", \"param\": \"lights[0].flicker.amplitude\",\n"
             "   \"range\": [0, 1], \"step\": 0.1, \"initial\": 0}],\n"
             " \"output\": {\"width\": 32, \"height\": 24, \"fps\": 100, \"renderer\": "
             "\"preview\"}}\n",
             LR_SOURCE_CONFIGS);
    char *cfg = lr_test_write(dir, "rig.json", text, (size_t)-1);
    char *stats = lr_test_path(dir, "stats.json");
    lr_test_log log = {0};
    lr_rig_opts o = {.config = cfg, .stats_path = stats, .duration_s = 0.8, .no_signals = true,
                     .log = {lr_test_log_fn, &log}};
    lr_rig *r;
    lr_err e = {0};
    int64_t t0 = lr_now_ns();
    if (lr_rig_create(&o, &r, &e))
        fail_msg("%s", e.msg);
    assert_int_equal(lr_rig_run(r, &e), LR_OK); /* returns at --duration (from the end of create) */
    double took = (double)(lr_now_ns() - t0) * 1e-9;
    /* At least the duration; the upper bound only catches a loop that never reaches it
     * (start-up under ASan is 1-2 s idle, several times that beside other binaries). */
    assert_true(took >= 0.8 && took < 20.0);
    assert_near(scene_num(r, "light.intensity"), 0.01, 1e-12);
    assert_near(scene_num(r, "lights[0].flicker.amplitude"), 0.2, 1e-9);
    char buf[64];
    lr_scene_get(lr_rig_scene(r), "objects[0].material.base", buf, sizeof buf, NULL);
    assert_string_equal(buf, "marble");
    lr_rig_info info;
    lr_rig_get_info(r, &info);
    assert_int_equal(info.events, 4); /* the release and the unbound control change nothing */
    assert_true(info.frames >= 4);
    lr_rig_destroy(r); /* writes the stats */
    assert_int_equal(check_stats(stats, 4, 4), 4);
    assert_int_equal(lr_test_log_count(&log, "duration reached"), 1);
    free(cfg);
    free(stats);
    lr_test_rmtree(dir);
}

/* A scene switch (button2) loads the next scene file (in a job, off the loop) and writes
 * every control's value into it again: the dimmer's intensity, the material picked by button1 and the translucency
 * scale survive the switch (the votive's file says 0.004 W/sr and scale 1.5); --out-dir keeps
 * one file per frame across the switch. */
static void test_scene_switch_keeps_controls(void **state)
{
    (void)state;
    char *dir = lr_test_tmpdir();
    char text[2048];
    snprintf(text, sizeof text,
             "{\"scene\": \"%s/scenes/candle.json\",\n"
             " \"devices\": [{\"type\": \"sim\", \"text\": \"0.05 dimmer absolute 0.3\\n"
             "0.10 button1 press\\n0.15 knob2 absolute 1\\n0.25 button2 press\\n\"}],\n"
             " \"controls\": [\n"
             "  {\"control\": \"dimmer\", \"param\": \"light.intensity\", \"range\": [0, 0.01]},\n"
             "  {\"control\": \"button1\", \"param\": \"objects[0].material\",\n"
             "   \"values\": [\"candle_wax\", \"marble\"]},\n"
             "  {\"control\": \"knob2\", \"param\": \"objects[0].material.scale\", \"range\": [0.5, 3]},\n"
             "  {\"control\": \"button2\", \"param\": \"scene\",\n"
             "   \"values\": [\"%s/scenes/candle.json\", \"%s/scenes/votive.json\"]}],\n"
             " \"output\": {\"width\": 16, \"height\": 16, \"renderer\": \"preview\"}}\n",
             LR_SOURCE_CONFIGS, LR_SOURCE_CONFIGS, LR_SOURCE_CONFIGS);
    char *cfg = lr_test_write(dir, "rig.json", text, (size_t)-1);
    char *frames = lr_test_path(dir, "frames");
    assert_int_equal(mkdir(frames, 0755), 0);
    lr_test_log log = {0};
    lr_rig_opts o = {.config = cfg, .duration_s = 120, .no_signals = true, .out_dir = frames,
                     .log = {lr_test_log_fn, &log}};
    lr_rig *r;
    lr_err e = {0};
    if (lr_rig_create(&o, &r, &e))
        fail_msg("%s", e.msg);
    /* The script's 0.25 s, then the switch: its scene loads and plans in a job (firmware/rig/
     * job.h), a few turns later; a minute's guard. */
    int64_t t0 = lr_now_ns();
    assert_int_equal(lr_rig_run_until(r, t0 + 600 * 1000000LL, &e), LR_OK);
    while (strcmp(lr_scene_name(lr_rig_scene(r)), "votive") && lr_now_ns() < t0 + 60 * 1000000000LL)
        assert_int_equal(lr_rig_run_until(r, lr_now_ns() + 20 * 1000000LL, &e), LR_OK);
    
    assert_string_equal(lr_scene_name(lr_rig_scene(r)), "votive");
    assert_near(scene_num(r, "light.intensity"), 0.003, 1e-12);
    assert_near(scene_num(r, "objects[0].material.scale"), 3.0, 1e-9);
    char buf[64];
    lr_scene_get(lr_rig_scene(r), "objects[0].material.base", buf, sizeof buf, NULL);
    assert_string_equal(buf, "marble");
    assert_int_equal(lr_test_log_count(&log, "scene: "), 1);
    /* --out-dir numbers frames by the rig's own count: one file per frame drawn, none written
     * over when the switch restarts the new scene's accumulation at its frame 0. */
    lr_rig_info info;
    lr_rig_get_info(r, &info);
    assert_true(info.frames >= 2);
    DIR *d = opendir(frames);
    assert_non_null(d);
    unsigned long long pngs = 0;
    struct dirent *de;
    while ((de = readdir(d)))
        pngs += strstr(de->d_name, ".png") != NULL;
    closedir(d);
    assert_int_equal(pngs, (unsigned long long)info.frames);
    char last[4096];
    snprintf(last, sizeof last, "%s/frame_%06llu.png", frames,
             (unsigned long long)info.frames - 1);
    assert_int_equal(access(last, F_OK), 0);
    lr_rig_destroy(r);
    free(frames);
    free(cfg);
    lr_test_rmtree(dir);
}

/* Devices missing at start (no GPIO chip, no HID knob, no USB device here): each is logged
 * once (not once per retry) and retried, and the rig runs on the sim script meanwhile. */
static void test_missing_devices_keep_running(void **state)
{
    (void)state;
    char *dir = lr_test_tmpdir();
    char text[2048];
    snprintf(text, sizeof text,
             "{\"scene\": \"%s/scenes/candle.json\",\n"
             " \"devices\": [\n"
             "  {\"type\": \"gpio\", \"chip\": \"gpiochip7\", \"retry_min_ms\": 20,\n"
             "   \"encoders\": [{\"name\": \"knob1\", \"line_a\": \"17\", \"line_b\": \"27\"}]},\n"
             "  {\"type\": \"hid\", \"name\": \"powermate\", \"vid\": \"077d\", \"pid\": \"0410\",\n"
             "   \"retry_min_ms\": 20},\n"
             "  {\"type\": \"usb\", \"retry_min_ms\": 20, \"rescan_ms\": 20,\n"
             "   \"watch\": [{\"name\": \"shuttle\", \"vid\": \"0b33\", \"pid\": \"0020\"}]},\n"
             "  {\"type\": \"sim\", \"text\": \"0.1 dimmer absolute 1\\n0.3 dimmer absolute 0.25\\n\"}],\n"
             " \"controls\": [{\"control\": \"dimmer\", \"param\": \"light.intensity\",\n"
             "   \"range\": [0, 0.01]},\n"
             "  {\"control\": \"gpio/knob1\", \"param\": \"render.exposure\", \"range\": [1e5, 1e7]}],\n"
             " \"output\": {\"width\": 16, \"height\": 16, \"renderer\": \"preview\"}}\n",
             LR_SOURCE_CONFIGS);
    char *cfg = lr_test_write(dir, "rig.json", text, (size_t)-1);
    lr_test_log log = {0};
    lr_rig_opts o = {.config = cfg, .duration_s = 1.0, .no_signals = true,
                     .log = {lr_test_log_fn, &log}};
    lr_rig *r;
    lr_err e = {0};
    if (lr_rig_create(&o, &r, &e))
        fail_msg("%s", e.msg);
    assert_int_equal(lr_rig_run(r, &e), LR_OK);
    assert_near(scene_num(r, "light.intensity"), 0.0025, 1e-12);
    lr_rig_info info;
    lr_rig_get_info(r, &info);
    assert_int_equal(info.events, 2);
    lr_rig_destroy(r);
    /* One line each, although each was retried many times in that second. */
    assert_int_equal(lr_test_log_count(&log, "gpiochip7"), 1);
    assert_int_equal(lr_test_log_count(&log, "powermate"), 1);
    assert_true(lr_test_log_count(&log, "shuttle") <= 1);
    free(cfg);
    lr_test_rmtree(dir);
}

/* ---- child processes ---- */

static pid_t spawn(char *const argv[], const char *err_path)
{
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        int fd = open(err_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fd >= 0) {
            dup2(fd, 2);
            dup2(fd, 1);
        }
        execv(argv[0], argv);
        _exit(127);
    }
    return pid;
}

/* Waits for the child to exit (guard 180 s: a `--duration 3` run under ASan takes 5-12 s
 * beside other binaries, and at exit the rig waits for the worker's frame under way, a grid
 * solve of tens of seconds under ASan on a loaded machine; the guard only ends a child that
 * never exits); returns its wait status. */
static int reap(pid_t pid)
{
    int st = 0;
    for (int i = 0; i < 18000; i++) {
        pid_t w = waitpid(pid, &st, WNOHANG);
        if (w == pid)
            return st;
        usleep(10000);
    }
    kill(pid, SIGKILL);
    waitpid(pid, &st, 0);
    fail_msg("lamprig did not exit");
    return st;
}

static bool file_has(const char *path, const char *needle)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return false;
    char line[2048];
    bool found = false;
    while (!found && fgets(line, sizeof line, f))
        found = strstr(line, needle) != NULL;
    fclose(f);
    return found;
}

static bool wait_file_has(const char *path, const char *needle, int guard_ms)
{
    for (int i = 0; i < guard_ms / 10; i++) {
        if (file_has(path, needle))
            return true;
        usleep(10000);
    }
    return false;
}

/* ---- the soak: `lamprig run` in a re-executed copy of this ASan/UBSan test binary ---- */

#define CHILD_FLAG "--as-lamprig"      /* argv[1] of the child: the rest goes to lr_cli_main */
#define LEAK_FLAG "--as-leaker"        /* argv[1] of the control child that leaks on purpose */
#define LEAK_EXIT 86                   /* exitcode given to LSan/ASan in the child */

/* The child's sanitizer settings: tests/run.sh's own, inherited (the same suppressions: the
 * driver's own leaks suppressed, ours never), with a leak or an ASan error
 * making the exit status LEAK_EXIT; a UBSan error aborts. Outside run.sh, its defaults. */
static void append_env(const char *name, const char *fallback, const char *extra)
{
    char buf[2048];
    const char *v = getenv(name);
    snprintf(buf, sizeof buf, "%s:%s", v && *v ? v : fallback, extra);
    setenv(name, buf, 1);
}

static void child_env(void)
{
    append_env("ASAN_OPTIONS", "detect_leaks=1:abort_on_error=0:intercept_tls_get_addr=0",
               "exitcode=86");
    append_env("LSAN_OPTIONS",
               "suppressions=" LR_SOURCE_CONFIGS
               "/../tests/lsan.supp:print_suppressions=0:intercept_tls_get_addr=0",
               "exitcode=86");
    setenv("UBSAN_OPTIONS", "print_stacktrace=1:halt_on_error=1", 1);
}

/* fork + exec of /proc/self/exe (a fresh process: no threads or GL state inherited from the
 * tests that ran before), output to out_path. */
static pid_t spawn_self(char *const args[], const char *out_path)
{
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        int fd = open(out_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fd >= 0) {
            dup2(fd, 2);
            dup2(fd, 1);
        }
        child_env();
        execv("/proc/self/exe", args);
        _exit(127);
    }
    return pid;
}

/* What the child runs instead of the tests; its return from main() is where LSan checks. */
static int child_main(int argc, char **argv)
{
    if (strcmp(argv[1], LEAK_FLAG) == 0) {
        void *volatile lost = malloc(4096); /* never freed: LSan must fail the exit */
        memset(lost, 1, 4096);
        lost = NULL;
        return 0;
    }
    /* Pin the GL driver (its own leaks are suppressed by library name), then run as
     * build/bin/lamprig would: argv[1] stands in for argv[0]. */
    lr_gl *gl;
    if (lr_test_gl_create(&gl) != LR_OK)
        return 1;
    lr_gl_destroy(gl);
    return lr_cli_main(argc - 1, argv + 1);
}

static int count_in_file(const char *path, const char *needle)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return 0;
    char line[4096];
    int n = 0;
    while (fgets(line, sizeof line, f))
        n += strstr(line, needle) != NULL;
    fclose(f);
    return n;
}

static void print_file(const char *path)
{
    size_t len = 0;
    unsigned char *text = lr_test_read(path, &len);
    if (text)
        fprintf(stderr, "---- %s ----\n%.*s\n----\n", path, (int)(len > 20000 ? 20000 : len),
                (const char *)text);
    free(text);
}

/* Sanitizers are live in the child: a deliberate leak gives LEAK_EXIT and a LeakSanitizer
 * report, so a clean exit status from the soak does mean "no leak". */
static void test_child_leak_is_caught(void **state)
{
    (void)state;
    char *dir = lr_test_tmpdir();
    char *out = lr_test_path(dir, "out.txt");
    char *args[] = {"lamprig-test", LEAK_FLAG, NULL};
    int st = reap(spawn_self(args, out));
    assert_true(WIFEXITED(st));
    assert_int_equal(WEXITSTATUS(st), LEAK_EXIT);
    assert_true(count_in_file(out, "ERROR: LeakSanitizer") == 1);
    free(out);
    lr_test_rmtree(dir);
}

/* The "frames" of a stats file, -1 while there is none (it is written atomically). */
static long soak_frames(const char *path)
{
    if (access(path, F_OK) != 0)
        return -1;
    lr_json *j;
    lr_err e = {0};
    if (lr_json_load(path, &j, &e))
        return -1;
    long n = -1;
    lr_json_get_int(j, lr_json_root(j), "frames", true, &n, &e);
    lr_json_destroy(j);
    return n;
}

/* The soak: the shipped sim demo (configs/rig/sim.json, its script looping, the real
 * `passes` renderer at the rig's budget, 320x240) run as `lamprig run --headless --stats F`
 * in an ASan/UBSan/LSan child for LAMPRIG_SOAK_S seconds, then SIGTERM. The default, 30 s, is
 * three loops of the 10 s script: every event kind recurs and the script wraps twice, which
 * is what a leak or a stuck loop needs to show in the checks below; `make soak` runs the
 * issue's 120 s (the same checks: they scale with the length), both counted from the rig's
 * first frame. Exit status 0 (LSan at exit would make it LEAK_EXIT), no sanitizer report, the stats file
 * valid: frames plausible for the time (at least 1 per second of the 30 fps cap, at most the
 * cap), events with per-event latencies (the 10 s script has 24 events that change
 * something). */
static void test_soak_shipped_sim(void **state)
{
    (void)state;
    const char *env = getenv("LAMPRIG_SOAK_S");
    double secs = env ? atof(env) : 30.0;
    if (!(secs > 0))
        secs = 30.0;
    char *dir = lr_test_tmpdir();
    char *stats = lr_test_path(dir, "stats.json");
    char *out = lr_test_path(dir, "out.txt");
    char *args[] = {"lamprig-test", CHILD_FLAG, "run", "--config",
                    LR_SOURCE_CONFIGS "/rig/sim.json", "--headless", "--stats", stats, NULL};
    int64_t t0 = lr_now_ns();
    pid_t pid = spawn_self(args, out);
    /* The soak's clock starts at the first stats write after the first frame (stats.period_s
     * 5): that frame solves the candle's light on the CPU, 5 s under ASan idle and 21-25 s
     * measured beside another sanitized GL binary on a loaded 2-core machine, which would
     * otherwise eat most of a short soak. Guard: 120 s. */
    for (int i = 0; soak_frames(stats) < 1; i++) {
        if (waitpid(pid, NULL, WNOHANG) != 0) {
            print_file(out);
            fail_msg("lamprig exited before its first frame");
        }
        if (i >= 1200) {
            kill(pid, SIGKILL);
            waitpid(pid, NULL, 0);
            fail_msg("lamprig drew no frame in 120 s");
        }
        usleep(100000);
    }
    int64_t end = lr_now_ns() + (int64_t)(secs * 1e9);
    while (lr_now_ns() < end) {
        if (waitpid(pid, NULL, WNOHANG) != 0) {
            print_file(out);
            fail_msg("lamprig exited before SIGTERM");
        }
        usleep(100000);
    }
    assert_int_equal(kill(pid, SIGTERM), 0);
    int st = reap(pid);
    double ran = (double)(lr_now_ns() - t0) * 1e-9;
    bool clean = WIFEXITED(st) && WEXITSTATUS(st) == 0;
    if (!clean || count_in_file(out, "Sanitizer") || count_in_file(out, "runtime error"))
        print_file(out);
    assert_true(WIFEXITED(st));
    assert_int_equal(WEXITSTATUS(st), 0);
    assert_int_equal(count_in_file(out, "Sanitizer"), 0);
    assert_int_equal(count_in_file(out, "runtime error"), 0);
    assert_int_equal(count_in_file(out, "SIGTERM: shutting down"), 1);

    /* At least half the script's events (24 per 10 s loop) over the soak, less one loop: the
     * first preset's CPU re-solve (MAX_LATENCY_MS above) holds the loop for 5 s under ASan
     * idle and longer beside another binary, and a SIGTERM that ends the soak inside it
     * leaves that time's events undelivered. */
    int events = check_stats(stats, 1, (int)((secs - 10.0) / 10 * 24 * 0.5));
    lr_json *j;
    lr_err e = {0};
    assert_int_equal(lr_json_load(stats, &j, &e), LR_OK);
    lr_jnode root = lr_json_root(j);
    long frames = 0;
    double dur = 0;
    assert_int_equal(lr_json_get_int(j, root, "frames", true, &frames, &e), LR_OK);
    assert_int_equal(lr_json_get_number(j, root, "duration_s", true, &dur, &e), LR_OK);
    lr_json_destroy(j);
    /* The rig's clock starts after process and GL start-up (about 2 s under ASan); the soak's
     * after the first frame. */
    assert_true(dur >= secs && dur <= ran);
    assert_true(frames >= (long)dur && frames <= (long)(30 * dur) + 2);
    print_message("soak: %.1f s in the rig, %ld frames, %d events with latencies\n", dur, frames,
                  events);
    free(stats);
    free(out);
    lr_test_rmtree(dir);
}

/* The fewest descriptors of pid over 5 readings 20 ms apart: a stats write in flight holds
 * one more for a moment, a leak holds it for good. */
static int fd_floor(pid_t pid)
{
    int lo = -1;
    for (int i = 0; i < 5; i++) {
        int n = lr_test_fd_count(pid);
        if (n >= 0 && (lo < 0 || n < lo))
            lo = n;
        usleep(20000);
    }
    return lo;
}

/* What a stats file says at one moment: events, frames, and of the modbus device `dev` (NULL:
 * none) its timeouts, stale and bad answers and exceptions. -1 when the file is not there or
 * not complete yet. */
typedef struct soak_snap {
    long events, frames;
    long timeouts, stale, bad, exceptions;
} soak_snap;

static soak_snap stats_snap(const char *path, const char *dev)
{
    soak_snap n = {-1, -1, -1, -1, -1, -1};
    lr_json *j;
    lr_err e = {0};
    if (lr_json_load(path, &j, &e))
        return n;
    lr_jnode root = lr_json_root(j), devs = lr_json_get(j, root, "devices");
    lr_json_get_int(j, root, "events", true, &n.events, &e);
    lr_json_get_int(j, root, "frames", true, &n.frames, &e);
    for (int i = 0; dev && i < lr_json_count(j, devs); i++) {
        lr_jnode d = lr_json_at(j, devs, i);
        if (!lr_json_str_eq(j, lr_json_get(j, d, "name"), dev))
            continue;
        lr_jnode mb = lr_json_get(j, d, "modbus");
        lr_json_get_int(j, mb, "timeouts", true, &n.timeouts, &e);
        lr_json_get_int(j, mb, "stale", true, &n.stale, &e);
        lr_json_get_int(j, mb, "bad_responses", true, &n.bad, &e);
        lr_json_get_int(j, mb, "exceptions", true, &n.exceptions, &e);
    }
    lr_json_destroy(j);
    return n;
}

static long stats_events(const char *path) { return stats_snap(path, NULL).events; }

/* The misbehaving Modbus peers of the fast soak (tests/support/modbus_rogue.h), one device
 * each: the rig polls and writes all of them the whole time. */
static const struct {
    lr_test_rogue_mode mode;
    const char *name;
    bool lamp;
} rogue_peers[] = {
    /* An answer to a read a byte per 45 ms: each poll ends at timeout_ms. No lamp: a level
     * pending is sent before any poll, and the knob keeps one pending, so a lamp here would
     * keep the reads (the only requests this peer drips on) from being sent. */
    {LR_ROGUE_DRIP, "drip", false},
    {LR_ROGUE_LATE, "late", true},     /* every answer after the previous request's: stale */
    {LR_ROGUE_RANDOM, "random", true}, /* wrong unit, wrong function, exceptions, good ones */
    {LR_ROGUE_CLOSE, "close", true},   /* accepts and closes: a reconnect every retry */
};
#define N_ROGUES ((int)(sizeof rogue_peers / sizeof rogue_peers[0]))

/* A knob spun fast for long, beside misbehaving Modbus peers: build/bin/lamprig (no sanitizer:
 * its own allocator's footprint) with a sim script of 20 absolute moves per millisecond,
 * looping (about 19000 events/s at 70 frames/s on the 2-core machine), four modbus devices
 * on loopback, each a peer of tests/support/modbus_rogue.c (DRIP, LATE, RANDOM, CLOSE; polls
 * every 20 ms, answers bounded at 200 ms, reconnects after 50..200 ms), the knob's binding
 * written to the lamp driver of the last three, the preview view at 32x24 and a stats
 * write every 0.2 s. After a 5 s warm-up (the event log of 4096 full, the heap at its size,
 * every peer connected to), over a window of 15 s (LAMPRIG_SOAK_S, if shorter):
 * - at least 1000 events/s;
 * - frames keep coming: at least 5 a second, a twentieth of the 100 fps cap (and of the
 *   measured ~70, a fourteenth: room for a loaded CI machine); a loop held by the drip (the
 *   defect this guards against: 2 frames in 15 s) gives a fraction of one;
 * - VmRSS grows by at most 576 KiB: what may still grow is the frame log filling (4096
 *   records of about 80 bytes, 320 KiB) and 256 KiB of heap and page slack; the latencies
 *   kept (8 bytes an event, 2.3 MB in the window) and their sorted copy at each write grew it
 *   before, and so would anything kept per Modbus answer, timeout or reconnect;
 * - descriptors: the floor at the end within 2 of the floor at the start. Two devices (drip,
 *   close) drop and reopen their socket all the time, so each may hold one more or one fewer
 *   at a reading; the close peer is reconnected at least 10 times in the window (measured:
 *   one every 200 ms, the retry bound), so a descriptor lost per reconnect shows as 10 or
 *   more;
 * and every peer was asked during the window, and at exit the link counters show each one's
 * fault (timeouts, stale answers, bad answers or exceptions). */
static void test_soak_fast_events(void **state)
{
    (void)state;
    const char *env = getenv("LAMPRIG_SOAK_S");
    double window = env && atof(env) > 0 && atof(env) < 15 ? atof(env) : 15;
    lr_test_rogue *peer[N_ROGUES];
    char devices[4096];
    size_t dlen = 0;
    for (int i = 0; i < N_ROGUES; i++) {
        peer[i] = lr_test_rogue_start(rogue_peers[i].mode, 0);
        lr_test_rogue_set_reg(peer[i], 0, 500);
        dlen += (size_t)snprintf(
            devices + dlen, sizeof devices - dlen,
            ",\n  {\"type\": \"modbus\", \"name\": \"%s\", \"url\": \"tcp://127.0.0.1:%d\",\n"
            "   \"poll_ms\": 20, \"timeout_ms\": 200, \"retry_min_ms\": 50, "
            "\"retry_max_ms\": 200,\n"
            "   \"inputs\": [{\"control\": \"panel\", \"unit\": 1, \"reg\": 0}]%s}",
            rogue_peers[i].name, lr_test_rogue_port(peer[i]),
            rogue_peers[i].lamp ? ",\n   \"lamp\": {\"unit\": 2, \"reg\": 0}" : "");
    }
    char *dir = lr_test_tmpdir();
    char script[8192] = "";
    size_t len = 0;
    for (int ms = 0; ms < 10; ms++)
        for (int k = 0; k < 20; k++)
            len += (size_t)snprintf(script + len, sizeof script - len,
                                    "0.%03d knob1 absolute %.2f\\n", ms,
                                    ((ms * 20 + k) % 101) / 100.0);
    char text[16384];
    snprintf(text, sizeof text,
             "{\"scene\": \"%s/scenes/candle.json\",\n"
             " \"devices\": [{\"type\": \"sim\", \"loop\": true, \"text\": \"%s0.010 end\\n\"}%s],\n"
             " \"controls\": [{\"control\": \"knob1\", \"param\": "
             "\"lights[0].flicker.amplitude\", \"range\": [0, 1], \"lamp\": true}],\n"
             " \"output\": {\"width\": 32, \"height\": 24, \"fps\": 100, \"renderer\": "
             "\"preview\"},\n"
             " \"stats\": {\"period_s\": 0.2}}\n",
             LR_SOURCE_CONFIGS, script, devices);
    char *cfg = lr_test_write(dir, "rig.json", text, (size_t)-1);
    char *stats = lr_test_path(dir, "stats.json");
    char *err = lr_test_path(dir, "stderr.txt");
    char *argv[] = {LAMPRIG, "run", "--config", cfg, "--headless", "--stats", stats, NULL};
    pid_t pid = spawn(argv, err);
    int64_t t0 = lr_now_ns();
    bool all_asked = false;
    while (lr_now_ns() - t0 < 5000 * MS || stats_events(stats) < 8192 || !all_asked) {
        if (waitpid(pid, NULL, WNOHANG) != 0 || lr_now_ns() - t0 > 60000 * MS) {
            print_file(err);
            fail_msg("lamprig exited, or logged under 8192 events or left a peer unasked in "
                     "60 s");
        }
        usleep(100000);
        all_asked = true;
        for (int i = 0; i < N_ROGUES; i++)
            all_asked &= lr_test_rogue_accepted(peer[i]) > 0;
    }
    soak_snap s0 = stats_snap(stats, NULL);
    long rss0 = lr_test_rss_kib(pid);
    int fd0 = fd_floor(pid), req0[N_ROGUES], acc0 = lr_test_rogue_accepted(peer[3]);
    for (int i = 0; i < N_ROGUES; i++)
        req0[i] = lr_test_rogue_requests(peer[i]);
    int64_t t1 = lr_now_ns();
    while (lr_now_ns() - t1 < (int64_t)(window * 1e9)) {
        assert_int_equal(waitpid(pid, NULL, WNOHANG), 0);
        usleep(100000);
    }
    long rss1 = lr_test_rss_kib(pid);
    soak_snap s1 = stats_snap(stats, NULL);
    int fd1 = fd_floor(pid), reconnects = lr_test_rogue_accepted(peer[3]) - acc0;
    double secs = (double)(lr_now_ns() - t1) * 1e-9;
    int asked[N_ROGUES];
    for (int i = 0; i < N_ROGUES; i++)
        asked[i] = lr_test_rogue_requests(peer[i]) - req0[i];
    assert_int_equal(kill(pid, SIGTERM), 0);
    int st = reap(pid);
    print_message("fast soak beside %d rogue Modbus peers: %.0f events/s, %.1f frames/s over "
                  "%.1f s, VmRSS %ld -> %ld KiB (%+ld), fds %d -> %d, %d reconnects of the "
                  "closing peer, requests drip %d late %d random %d\n",
                  N_ROGUES, (double)(s1.events - s0.events) / secs,
                  (double)(s1.frames - s0.frames) / secs, secs, rss0, rss1, rss1 - rss0, fd0,
                  fd1, reconnects, asked[0], asked[1], asked[2]);
    assert_true(WIFEXITED(st));
    assert_int_equal(WEXITSTATUS(st), 0);
    assert_true(rss0 > 0 && rss1 > 0 && fd0 > 0 && s0.events >= 0 && s1.events >= 0);
    assert_true((double)(s1.events - s0.events) >= 1000 * secs);
    assert_true((double)(s1.frames - s0.frames) >= 5 * secs);
    assert_true(rss1 - rss0 <= 576);
    assert_true(fd1 >= fd0 - 2 && fd1 <= fd0 + 2);
    assert_true(reconnects >= 10);
    for (int i = 0; i < 3; i++) /* the close peer is never asked: it hangs up first */
        assert_true(asked[i] > 0);

    /* The file at exit: every event in the latency count, the log its last 4096; each peer's
     * fault in its device's counters. */
    lr_json *j;
    lr_err e = {0};
    assert_int_equal(lr_json_load(stats, &j, &e), LR_OK);
    lr_jnode root = lr_json_root(j);
    long events = 0, n = 0;
    double med = -1, p99 = -1, max = -1;
    lr_jnode lat = lr_json_get(j, root, "latency_ms");
    assert_int_equal(lr_json_get_int(j, root, "events", true, &events, &e), LR_OK);
    assert_int_equal(lr_json_get_int(j, lat, "n", true, &n, &e), LR_OK);
    assert_int_equal(lr_json_get_number(j, lat, "median", true, &med, &e), LR_OK);
    assert_int_equal(lr_json_get_number(j, lat, "p99", true, &p99, &e), LR_OK);
    assert_int_equal(lr_json_get_number(j, lat, "max", true, &max, &e), LR_OK);
    assert_int_equal(n, events);
    assert_true(events >= s1.events);
    assert_true(med >= 0 && p99 >= med && max >= p99);
    assert_int_equal(lr_json_count(j, lr_json_get(j, root, "event_log")), 4096);
    lr_json_destroy(j);
    soak_snap drip = stats_snap(stats, "drip"), late = stats_snap(stats, "late"),
              rnd = stats_snap(stats, "random");
    print_message("at exit: drip %ld timeouts, late %ld stale, random %ld bad + %ld "
                  "exceptions\n",
                  drip.timeouts, late.stale, rnd.bad, rnd.exceptions);
    assert_true(drip.timeouts > 0);
    assert_true(late.stale > 0);
    assert_true(rnd.bad > 0 && rnd.exceptions > 0);
    for (int i = 0; i < N_ROGUES; i++)
        lr_test_rogue_free(peer[i]);
    free(cfg);
    free(stats);
    free(err);
    lr_test_rmtree(dir);
}

/* The shipped sim demo, headless, frames and stats, --duration: exit 0. */
static void test_shipped_sim_demo(void **state)
{
    (void)state;
    char *dir = lr_test_tmpdir();
    char *frames = lr_test_path(dir, "frames");
    char *stats = lr_test_path(dir, "stats.json");
    char *err = lr_test_path(dir, "stderr.txt");
    char *argv[] = {LAMPRIG, "run", "--config", LR_SOURCE_CONFIGS "/rig/sim.json", "--headless",
                    "--duration", "3", "--out-dir", frames, "--stats", stats, NULL};
    int st = reap(spawn(argv, err));
    assert_true(WIFEXITED(st));
    assert_int_equal(WEXITSTATUS(st), 0);
    /* 0..3 s of the script: 6 dimmer moves, 3 knob detents, 1 material press (t = 2.5);
     * with the real renderer on a software GL, the last one may still wait for its frame
     * at exit (counted as pending, not given a latency). */
    int events = check_stats(stats, 2, 1);
    lr_json *j;
    lr_err e = {0};
    assert_int_equal(lr_json_load(stats, &j, &e), LR_OK);
    long pending = -1;
    assert_int_equal(lr_json_get_int(j, lr_json_root(j), "events_pending", true, &pending, &e),
                     LR_OK);
    lr_json_destroy(j);
    assert_int_equal(events + pending, 10);
    assert_true(pending <= 1);
    DIR *d = opendir(frames);
    assert_non_null(d);
    int pngs = 0;
    struct dirent *de;
    while ((de = readdir(d)))
        pngs += strstr(de->d_name, ".png") != NULL;
    closedir(d);
    assert_true(pngs >= 2);
    assert_true(file_has(err, "duration reached: shutting down"));
    free(frames);
    free(stats);
    free(err);
    lr_test_rmtree(dir);
}

static void write_rig(const char *dir, int port, double safe, const char *extra)
{
    char text[2048];
    snprintf(text, sizeof text,
             "{\"scene\": \"%s/scenes/candle.json\",\n"
             " \"devices\": [\n"
             "  {\"type\": \"sim\", \"loop\": true,\n"
             "   \"text\": \"0.0 dimmer absolute 0.2\\n0.2 dimmer absolute 0.9\\n0.4 end\\n\"},\n"
             "  {\"type\": \"modbus\", \"name\": \"driver\", \"url\": \"tcp://127.0.0.1:%d\",\n"
             "   \"lamp\": {\"unit\": 2, \"reg\": 0}}],\n"
             " \"controls\": [{\"control\": \"dimmer\", \"param\": \"light.intensity\",\n"
             "   \"range\": [0, 0.01], \"lamp\": true%s}],\n"
             " \"output\": {\"width\": 32, \"height\": 24, \"renderer\": \"preview\"},\n"
             " \"stats\": {\"period_s\": 0.2},\n"
             " \"safe_level\": %g}\n",
             LR_SOURCE_CONFIGS, port, extra, safe);
    free(lr_test_write(dir, "rig.json", text, (size_t)-1));
}

/* SIGTERM mid-run: exit 0, safe level acknowledged by the driver, stats written. */
static void test_sigterm_clean_exit(void **state)
{
    (void)state;
    lr_test_mb_server *s = lr_test_mb_server_start();
    char *dir = lr_test_tmpdir();
    write_rig(dir, lr_test_mb_server_port(s), 0.1, "");
    char *cfg = lr_test_path(dir, "rig.json");
    char *stats = lr_test_path(dir, "stats.json");
    char *err = lr_test_path(dir, "stderr.txt");
    char *argv[] = {LAMPRIG, "run", "--config", cfg, "--stats", stats, NULL};
    pid_t pid = spawn(argv, err);
    /* Running: the driver follows the scripted dimmer (0.2 → 51 or 0.9 → 230). */
    bool seen = false;
    for (int i = 0; i < 1000 && !seen; i++) {
        int v = lr_test_mb_server_reg(s, 2, 0);
        seen = v == 51 || v == 230;
        usleep(10000);
    }
    assert_true(seen);
    /* The periodic stats write (stats.period_s 0.2) happens while running. */
    for (int i = 0; i < 500 && access(stats, F_OK) != 0; i++)
        usleep(10000);
    assert_int_equal(access(stats, F_OK), 0);
    assert_int_equal(waitpid(pid, NULL, WNOHANG), 0);
    usleep(300000); /* a few more scripted dimmer moves */
    assert_int_equal(kill(pid, SIGTERM), 0);
    int st = reap(pid);
    assert_true(WIFEXITED(st));
    assert_int_equal(WEXITSTATUS(st), 0);
    assert_int_equal(lr_test_mb_server_reg(s, 2, 0), 26); /* 0.1 * 255 = 25.5 → 26 */
    assert_true(file_has(err, "SIGTERM: shutting down"));
    assert_true(file_has(err, "lamp driver at safe level 0.1 (raw 26)"));
    check_stats(stats, 1, 2);
    free(cfg);
    free(stats);
    free(err);
    lr_test_rmtree(dir);
    lr_test_mb_server_free(s);
}

/* SIGHUP: a broken config is reported (file, line, field) and the old one runs on; a good one
 * is loaded off the loop and applied (its safe level is the one written at exit). */
static void test_sighup_reload(void **state)
{
    (void)state;
    lr_test_mb_server *s = lr_test_mb_server_start();
    int port = lr_test_mb_server_port(s);
    char *dir = lr_test_tmpdir();
    write_rig(dir, port, 0.1, "");
    char *cfg = lr_test_path(dir, "rig.json");
    char *err = lr_test_path(dir, "stderr.txt");
    char *argv[] = {LAMPRIG, "run", "--config", cfg, "--headless", NULL};
    pid_t pid = spawn(argv, err);
    assert_true(wait_file_has(err, "config ", 10000));

    /* Line 8 of the file carries the bad curve. */
    write_rig(dir, port, 0.3, ", \"curve\": \"cubic\"");
    assert_int_equal(kill(pid, SIGHUP), 0);
    assert_true(wait_file_has(err, "reload: ", 10000));
    char want[700];
    snprintf(want, sizeof want,
             "reload: %s:8: field 'controls[0].curve': unknown curve 'cubic' (linear, square, "
             "s-curve, log, warm-dim); keeping the running config",
             cfg);
    assert_true(file_has(err, want));
    usleep(200000);
    assert_int_equal(waitpid(pid, NULL, WNOHANG), 0); /* still running */

    write_rig(dir, port, 0.5, ", \"curve\": \"s-curve\"");
    assert_int_equal(kill(pid, SIGHUP), 0);
    assert_true(wait_file_has(err, "reloaded ", 10000));
    /* Loaded and planned in a job while the loop went on (firmware/rig/job.h). */
    assert_true(wait_file_has(err, "reload: loaded and planned off the loop in ", 10000));
    /* The new config drives the lamp: s-curve(0.2) = 0.104 → 27; s-curve(0.9) = 0.972 → 248. */
    bool seen = false;
    for (int i = 0; i < 1000 && !seen; i++) {
        int v = lr_test_mb_server_reg(s, 2, 0);
        seen = v == 27 || v == 248;
        usleep(10000);
    }
    assert_true(seen);
    assert_int_equal(kill(pid, SIGTERM), 0);
    int st = reap(pid);
    assert_true(WIFEXITED(st));
    assert_int_equal(WEXITSTATUS(st), 0);
    assert_int_equal(lr_test_mb_server_reg(s, 2, 0), 128); /* the new safe level 0.5 */
    free(cfg);
    free(err);
    lr_test_rmtree(dir);
    lr_test_mb_server_free(s);
}

/* Bad arguments: exit 2 with one line; a broken config: exit 1 naming file:line:field. */
static void test_cli_errors(void **state)
{
    (void)state;
    char *dir = lr_test_tmpdir();
    char *err = lr_test_path(dir, "stderr.txt");
    char *a1[] = {LAMPRIG, "run", "--headless", NULL};
    int st = reap(spawn(a1, err));
    assert_int_equal(WEXITSTATUS(st), 2);
    assert_true(file_has(err, "lamprig run: --config FILE is required"));
    char *a2[] = {LAMPRIG, "run", "--config", "x.json", "--duration", "-1", NULL};
    st = reap(spawn(a2, err));
    assert_int_equal(WEXITSTATUS(st), 2);
    char *bad = lr_test_write(dir, "bad.json", "{\"scene\": 5}\n", (size_t)-1);
    char *a3[] = {LAMPRIG, "run", "--config", bad, NULL};
    st = reap(spawn(a3, err));
    assert_int_equal(WEXITSTATUS(st), 1);
    char want[600];
    snprintf(want, sizeof want, "lamprig run: %s:1: field 'scene': expected a string", bad);
    if (!file_has(err, want))
        fail_msg("stderr lacks '%s'", want);
    free(bad);
    free(err);
    lr_test_rmtree(dir);
}

int main(int argc, char **argv)
{
    if (argc >= 2 && (!strcmp(argv[1], CHILD_FLAG) || !strcmp(argv[1], LEAK_FLAG)))
        return child_main(argc, argv);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sim_in_process),
        cmocka_unit_test(test_scene_switch_keeps_controls),
        cmocka_unit_test(test_missing_devices_keep_running),
        cmocka_unit_test(test_shipped_sim_demo),
        cmocka_unit_test(test_sigterm_clean_exit),
        cmocka_unit_test(test_sighup_reload),
        cmocka_unit_test(test_cli_errors),
        cmocka_unit_test(test_child_leak_is_caught),
        cmocka_unit_test(test_soak_shipped_sim),
        cmocka_unit_test(test_soak_fast_events),
    };
    if (getenv("LR_TEST_FILTER")) /* e.g. LR_TEST_FILTER='test_soak*' to run one test */
        cmocka_set_test_filter(getenv("LR_TEST_FILTER"));
    return cmocka_run_group_tests(tests, NULL, NULL);
}
