/* lamprig tests — /proc readings (see proc.h). */
#include "tests/support/proc.h"

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void proc_path(char *buf, size_t len, pid_t pid, const char *leaf)
{
    if (pid)
        snprintf(buf, len, "/proc/%ld/%s", (long)pid, leaf);
    else
        snprintf(buf, len, "/proc/self/%s", leaf);
}

long lr_test_rss_kib(pid_t pid)
{
    char path[64], line[256];
    proc_path(path, sizeof path, pid, "status");
    FILE *f = fopen(path, "r");
    if (!f)
        return -1;
    long kib = -1;
    while (fgets(line, sizeof line, f))
        if (strncmp(line, "VmRSS:", 6) == 0) {
            kib = strtol(line + 6, NULL, 10);
            break;
        }
    fclose(f);
    return kib;
}

int lr_test_fd_count(pid_t pid)
{
    char path[64];
    proc_path(path, sizeof path, pid, "fd");
    DIR *d = opendir(path);
    if (!d)
        return -1;
    int n = 0;
    struct dirent *de;
    while ((de = readdir(d)))
        n += de->d_name[0] != '.';
    closedir(d);
    return pid ? n : n - 1; /* our own listing holds one */
}
