/* lamprig bench — child processes for the rig rows: `lamprig run`, the Modbus simulator and
 * busy loops, started and reaped from outside as a user would run them. */
#ifndef LRB_PROC_H
#define LRB_PROC_H

#include <sys/types.h>

void lrb_sleep_s(double s);
/* Copies a child's log to stderr, each line indented. */
void lrb_print_log(const char *path);
/* Starts argv[0] with stdout and stderr to log_path. */
pid_t lrb_spawn(char *const argv[], const char *log_path);
/* The same with its stdin a pipe: *stdin_fd is the writing end (the caller closes it). */
pid_t lrb_spawn_piped(char *const argv[], const char *log_path, int *stdin_fd);
/* Waits up to guard_s for pid, then kills it: its wait status, or -1 when it had to be killed. */
int lrb_reap(pid_t pid, double guard_s);
/* n processes spinning on a core each (a loaded board), and their end. */
int lrb_busy_start(int n, pid_t *pids);
void lrb_busy_stop(int n, const pid_t *pids);

#endif
