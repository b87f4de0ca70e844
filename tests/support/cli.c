/* lamprig tests — running the built command line as a child. */
#include "tests/support/cli.h"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <sys/wait.h>

#include "render/base/file.h"

int lr_test_run_cli(const char *dir, const char *fmt, ...)
{
    char cmd[2048], full[2400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(cmd, sizeof cmd, fmt, ap);
    va_end(ap);
    /* stdin closed off: no command under test reads it, and none may wait on a terminal. */
    snprintf(full, sizeof full, "%s >%s/out 2>%s/err </dev/null", cmd, dir, dir);
    int st = system(full);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

char *lr_test_slurp(const char *dir, const char *name)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    char *t = NULL;
    size_t n;
    lr_err e = {0};
    if (lr_file_read(path, LR_FILE_MAX_TEXT, &t, &n, &e))
        fail_msg("%s", e.msg);
    return t;
}
