/* Child processes for the bench's rig rows (tools/bench/proc.h). */
#include "tools/bench/proc.h"

#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

void lrb_sleep_s(double s)
{
    struct timespec ts = {(time_t)s, (long)((s - (double)(time_t)s) * 1e9)};
    while (nanosleep(&ts, &ts) != 0)
        ;
}

void lrb_print_log(const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return;
    char line[1024];
    while (fgets(line, sizeof line, f))
        fprintf(stderr, "  | %s", line);
    fclose(f);
}

/* The child: stdin from in_fd (-1: inherited), stdout and stderr to log_path, argv[0]. */
static pid_t spawn(char *const argv[], const char *log_path, int in_fd)
{
    pid_t pid = fork();
    if (pid == 0) {
        if (in_fd >= 0)
            dup2(in_fd, 0);
        int fd = open(log_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fd >= 0) {
            dup2(fd, 1);
            dup2(fd, 2);
        }
        execv(argv[0], argv);
        _exit(127);
    }
    return pid;
}

pid_t lrb_spawn(char *const argv[], const char *log_path)
{
    return spawn(argv, log_path, -1);
}

pid_t lrb_spawn_piped(char *const argv[], const char *log_path, int *stdin_fd)
{
    int p[2];
    *stdin_fd = -1;
    if (pipe2(p, O_CLOEXEC) != 0)
        return -1;
    pid_t pid = spawn(argv, log_path, p[0]);
    close(p[0]);
    if (pid < 0)
        close(p[1]);
    else
        *stdin_fd = p[1];
    return pid;
}

int lrb_reap(pid_t pid, double guard_s)
{
    int st = 0;
    for (int i = 0; i < (int)(guard_s * 20); i++) {
        if (waitpid(pid, &st, WNOHANG) == pid)
            return st;
        lrb_sleep_s(0.05);
    }
    kill(pid, SIGKILL);
    waitpid(pid, &st, 0);
    return -1;
}

int lrb_busy_start(int n, pid_t *pids)
{
    for (int i = 0; i < n; i++) {
        pids[i] = fork();
        if (pids[i] == 0) {
            volatile unsigned long x = 0;
            for (;;)
                x++;
        }
        if (pids[i] < 0) {
            lrb_busy_stop(i, pids);
            return 1;
        }
    }
    return 0;
}

void lrb_busy_stop(int n, const pid_t *pids)
{
    for (int i = 0; i < n; i++) {
        kill(pids[i], SIGKILL);
        waitpid(pids[i], NULL, 0);
    }
}
