/* lamprig-modbus-sim as a daemon-like process: with stdin /dev/null (started in the background)
 * it keeps serving, and with a stdin pipe that closes it keeps serving without spinning (no
 * CPU while nothing happens); SIGTERM ends it with exit 0. A libmodbus client reads the panel
 * (unit 1) and writes the driver (unit 2) as the rig does. Runs build/bin/lamprig-modbus-sim
 * (built by `make test` before the tests). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <arpa/inet.h>
#include <fcntl.h>
#include <modbus.h>
#include <netinet/in.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "tests/support/fs.h"

#define SIM LR_SOURCE_CONFIGS "/../build/bin/lamprig-modbus-sim"
#define GUARD_POLLS 2000 /* 10 ms each: a hang fails the test instead of blocking it */

static int free_port(void)
{
    int fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a = {.sin_family = AF_INET};
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t al = sizeof a;
    assert_true(fd >= 0);
    assert_int_equal(bind(fd, (struct sockaddr *)&a, sizeof a), 0);
    assert_int_equal(getsockname(fd, (struct sockaddr *)&a, &al), 0);
    close(fd);
    return ntohs(a.sin_port);
}

/* Starts the simulator with stdin from in_fd, stdout+stderr to log (trace: --trace). */
static pid_t spawn_sim_opt(int port, int panel, int in_fd, const char *log, bool trace)
{
    char port_s[16], panel_s[16];
    snprintf(port_s, sizeof port_s, "%d", port);
    snprintf(panel_s, sizeof panel_s, "%d", panel);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        int fd = open(log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fd < 0 || dup2(in_fd, 0) < 0 || dup2(fd, 1) < 0 || dup2(fd, 2) < 0)
            _exit(127);
        char *argv[] = {SIM, "--port", port_s, "--panel", panel_s, trace ? "--trace" : NULL,
                        NULL};
        execv(argv[0], argv);
        _exit(127);
    }
    return pid;
}

static pid_t spawn_sim(int port, int panel, int in_fd, const char *log)
{
    return spawn_sim_opt(port, panel, in_fd, log, false);
}

static bool log_has(const char *log, const char *needle)
{
    FILE *f = fopen(log, "r");
    if (!f)
        return false;
    char line[512];
    bool found = false;
    while (!found && fgets(line, sizeof line, f))
        found = strstr(line, needle) != NULL;
    fclose(f);
    return found;
}

/* Waits (guarded) until the log has needle, failing the test if the sim exits first. */
static void wait_log(pid_t pid, const char *log, const char *needle)
{
    for (int i = 0; i < GUARD_POLLS; i++) {
        if (log_has(log, needle))
            return;
        int st;
        if (waitpid(pid, &st, WNOHANG) == pid)
            fail_msg("lamprig-modbus-sim exited (status %#x) before printing '%s'", st, needle);
        usleep(10000);
    }
    kill(pid, SIGKILL);
    waitpid(pid, NULL, 0);
    fail_msg("lamprig-modbus-sim never printed '%s'", needle);
}

/* SIGTERM: exit status 0, the stop line printed. */
static void stop(pid_t pid, const char *log)
{
    assert_int_equal(kill(pid, SIGTERM), 0);
    int st = -1;
    for (int i = 0; i < GUARD_POLLS && waitpid(pid, &st, WNOHANG) != pid; i++)
        usleep(10000);
    if (!WIFEXITED(st)) {
        kill(pid, SIGKILL);
        waitpid(pid, NULL, 0);
        fail_msg("lamprig-modbus-sim did not exit on SIGTERM (status %#x)", st);
    }
    assert_int_equal(WEXITSTATUS(st), 0);
    assert_true(log_has(log, "signal 15: stopping"));
}

/* The panel through Modbus, and a driver write that the sim reports. */
static void talk(int port, const char *log, pid_t pid, int want_panel, int driver)
{
    modbus_t *c = modbus_new_tcp("127.0.0.1", port);
    assert_non_null(c);
    assert_int_equal(modbus_connect(c), 0);
    uint16_t v = 0;
    assert_int_equal(modbus_set_slave(c, 1), 0);
    assert_int_equal(modbus_read_registers(c, 0, 1, &v), 1);
    assert_int_equal(v, want_panel);
    assert_int_equal(modbus_set_slave(c, 2), 0);
    assert_int_equal(modbus_write_register(c, 0, (uint16_t)driver), 1);
    modbus_close(c);
    modbus_free(c);
    char line[64];
    snprintf(line, sizeof line, "driver %d (", driver);
    wait_log(pid, log, line);
}

/* utime + stime of pid in clock ticks. */
static long cpu_ticks(pid_t pid)
{
    char path[64], buf[1024];
    snprintf(path, sizeof path, "/proc/%d/stat", (int)pid);
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    buf[n] = '\0';
    char *p = strrchr(buf, ')');
    assert_non_null(p);
    unsigned long ut = 0, st = 0;
    assert_int_equal(sscanf(p + 2, "%*c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %lu %lu", &ut,
                            &st), 2);
    return (long)(ut + st);
}

/* Per test: the scratch dir and the simulator, both cleaned up by teardown even when the test
 * fails half-way (a spinning simulator must not outlive a failed test). */
typedef struct fixture {
    char *dir;
    pid_t pid;
} fixture;

static int setup(void **state)
{
    fixture *f = calloc(1, sizeof *f);
    if (!f)
        return -1;
    f->dir = lr_test_tmpdir();
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = *state;
    if (f->pid > 0 && waitpid(f->pid, NULL, WNOHANG) == 0) {
        kill(f->pid, SIGKILL);
        waitpid(f->pid, NULL, 0);
    }
    lr_test_rmtree(f->dir);
    free(f);
    return 0;
}

static void test_stdin_dev_null_serves_until_sigterm(void **state)
{
    fixture *f = *state;
    char *dir = f->dir;
    char *log = lr_test_path(dir, "sim.log");
    int null = open("/dev/null", O_RDONLY);
    assert_true(null >= 0);
    int port = free_port();
    pid_t pid = f->pid = spawn_sim(port, 321, null, log);
    close(null);
    wait_log(pid, log, "stdin closed");
    talk(port, log, pid, 321, 128);
    stop(pid, log);
    free(log);
}

/* --trace: a timestamped line per request (unit and function code: 3 reads the panel, 6
 * writes the driver) and per change, on the clock of the caller's CLOCK_MONOTONIC (the bench
 * compares it with its own), in order and within the span of the exchange. */
static void test_trace_lines(void **state)
{
    fixture *f = *state;
    char *log = lr_test_path(f->dir, "sim.log");
    int p[2];
    assert_int_equal(pipe2(p, O_CLOEXEC), 0);
    int port = free_port();
    pid_t pid = f->pid = spawn_sim_opt(port, 400, p[0], log, true);
    close(p[0]);
    wait_log(pid, log, "modbus simulator on");
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    assert_int_equal(write(p[1], "650\n", 4), 4);
    wait_log(pid, log, "panel 650");
    talk(port, log, pid, 650, 77);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    close(p[1]);
    stop(pid, log); /* the trace's request lines are flushed at exit */
    FILE *in = fopen(log, "r");
    assert_non_null(in);
    char line[256];
    double last = 0, a = (double)t0.tv_sec + t0.tv_nsec * 1e-9,
           b = (double)t1.tv_sec + t1.tv_nsec * 1e-9;
    int reads = 0, writes = 0, panels = 0, drivers = 0;
    while (fgets(line, sizeof line, in)) {
        double t;
        int u, fc, v;
        if (line[0] != '@')
            continue;
        assert_int_equal(sscanf(line, "@%lf", &t), 1);
        assert_true(t >= a - 1e-3 && t <= b + 1e-3 && t >= last);
        last = t;
        if (sscanf(line, "@%lf request unit %d function %d", &t, &u, &fc) == 3) {
            reads += u == 1 && fc == 3;
            writes += u == 2 && fc == 6;
        } else if (sscanf(line, "@%lf panel %d", &t, &v) == 2) {
            panels += v == 650;
        } else if (sscanf(line, "@%lf driver %d", &t, &v) == 2) {
            drivers += v == 77;
        } else {
            fail_msg("unexpected trace line: %s", line);
        }
    }
    fclose(in);
    assert_int_equal(reads, 1);
    assert_int_equal(writes, 1);
    assert_int_equal(panels, 1);
    assert_int_equal(drivers, 1);
    free(log);
}

static void test_closed_stdin_pipe_does_not_spin(void **state)
{
    fixture *f = *state;
    char *dir = f->dir;
    char *log = lr_test_path(dir, "sim.log");
    int p[2];
    assert_int_equal(pipe2(p, O_CLOEXEC), 0); /* the child keeps no write end open */
    int port = free_port();
    pid_t pid = f->pid = spawn_sim(port, 500, p[0], log);
    close(p[0]);
    /* A panel move typed on stdin, then the pipe closes. */
    assert_int_equal(write(p[1], "700\n", 4), 4);
    close(p[1]);
    wait_log(pid, log, "panel 700");
    talk(port, log, pid, 700, 64);
    /* Blocked in poll() with nothing to do: no CPU over a second. A spinning loop (poll
     * returning POLLHUP at once, again and again) takes every tick the scheduler gives it,
     * dozens in a second even on a loaded machine. */
    long t0 = cpu_ticks(pid);
    usleep(1000000);
    long used = cpu_ticks(pid) - t0;
    if (used > 2)
        fail_msg("lamprig-modbus-sim used %ld ticks in 1 s with nothing to do (spinning)", used);
    assert_true(log_has(log, "stdin closed"));
    stop(pid, log);
    free(log);
}

int main(void)
{
    signal(SIGPIPE, SIG_IGN);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_stdin_dev_null_serves_until_sigterm, setup,
                                        teardown),
        cmocka_unit_test_setup_teardown(test_closed_stdin_pipe_does_not_spin, setup, teardown),
        cmocka_unit_test_setup_teardown(test_trace_lines, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
