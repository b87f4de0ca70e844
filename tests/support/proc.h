/* lamprig tests — a process's resident memory and open descriptors, from /proc (soak tests). */
#ifndef LR_TEST_PROC_H
#define LR_TEST_PROC_H

#include <sys/types.h>

/* VmRSS of pid (0: this process) in KiB; -1 when unreadable (the process gone). */
long lr_test_rss_kib(pid_t pid);
/* Entries of /proc/PID/fd (0: this process, not counting the directory's own descriptor); -1
 * when unreadable. */
int lr_test_fd_count(pid_t pid);

#endif
