/* Work off the loop (firmware/rig/job.h): a job whose work blocks until the test lets it go
 * is not done and its descriptor is not readable meanwhile, while the caller goes on; what
 * the work logs is kept, in order, and written to the caller's log only when the job is
 * finished; the log a piece of code gets is the job's on the job's thread and the loop's
 * elsewhere; finishing a job still running waits for it. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <poll.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "firmware/rig/job.h"

typedef struct capture {
    char text[4096];
    int lines;
} capture;

static void capture_line(void *user, lr_log_level level, const char *msg)
{
    capture *c = user;
    size_t n = strlen(c->text);
    snprintf(c->text + n, sizeof c->text - n, "%d:%s\n", (int)level, msg);
    c->lines++;
}

typedef struct work {
    int gate[2];               /* the work reads one byte from gate[0] before it ends */
    const lr_rig_job *self;    /* the job, for lr_rig_job_log_here */
    const lr_log *loop_log;
    bool saw_own_log;          /* lr_rig_job_log_here gave the job's log on its thread */
    int result;
} work;

static void blocked(void *arg, const lr_log *log)
{
    work *w = arg;
    lr_log_write(log, LR_LOG_INFO, "first %d", 1);
    char b;
    ssize_t n = read(w->gate[0], &b, 1);
    w->saw_own_log = lr_rig_job_log_here(w->self, w->loop_log) == log;
    lr_log_write(lr_rig_job_log_here(w->self, w->loop_log), LR_LOG_WARN, "second");
    w->result = n == 1 ? b : -1;
}

static bool readable(int fd, int timeout_ms)
{
    struct pollfd p = {fd, POLLIN, 0};
    return poll(&p, 1, timeout_ms) == 1 && (p.revents & POLLIN);
}

static void test_job_off_the_caller(void **state)
{
    (void)state;
    capture cap = {{0}, 0};
    lr_log loop_log = {capture_line, &cap};
    work w = {.loop_log = &loop_log, .result = 0};
    assert_int_equal(pipe(w.gate), 0);
    lr_rig_job *j = NULL;
    lr_err e = {0};
    assert_int_equal(lr_rig_job_start(blocked, &w, &j, &e), LR_OK);
    w.self = j;
    /* Held at the gate: not done, nothing to read, nothing logged to the caller yet, and the
     * caller's own code gets its own log. */
    for (int i = 0; i < 5; i++) {
        assert_false(lr_rig_job_done(j));
        assert_false(readable(lr_rig_job_fd(j), 20));
    }
    assert_int_equal(cap.lines, 0);
    assert_ptr_equal(lr_rig_job_log_here(j, &loop_log), &loop_log);
    assert_int_equal(write(w.gate[1], "7", 1), 1);
    assert_true(readable(lr_rig_job_fd(j), 60000));
    assert_true(lr_rig_job_done(j));
    assert_int_equal(cap.lines, 0); /* kept until finished */
    lr_rig_job_finish(j, &loop_log);
    assert_int_equal(w.result, '7');
    assert_true(w.saw_own_log);
    assert_int_equal(cap.lines, 2);
    assert_string_equal(cap.text, "2:first 1\n1:second\n");
    close(w.gate[0]);
    close(w.gate[1]);
}

/* Finishing a job that has not returned waits for it (shutdown). */
static void test_finish_waits(void **state)
{
    (void)state;
    capture cap = {{0}, 0};
    lr_log loop_log = {capture_line, &cap};
    work w = {.loop_log = &loop_log};
    assert_int_equal(pipe(w.gate), 0);
    lr_rig_job *j = NULL;
    lr_err e = {0};
    assert_int_equal(lr_rig_job_start(blocked, &w, &j, &e), LR_OK);
    w.self = j;
    assert_int_equal(write(w.gate[1], "x", 1), 1); /* may still be before the read */
    lr_rig_job_finish(j, &loop_log);
    assert_int_equal(w.result, 'x');
    assert_int_equal(cap.lines, 2);
    lr_rig_job_finish(NULL, &loop_log); /* a no-op */
    close(w.gate[0]);
    close(w.gate[1]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_job_off_the_caller),
        cmocka_unit_test(test_finish_waits),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
