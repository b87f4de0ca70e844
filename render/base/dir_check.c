/* lamprig — whether a folder can take a cache's files (see dir_check.h). */
#include "render/base/dir_check.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#define PROBE_BYTES 4096

/* dir, or its nearest existing ancestor, into buf. -1 when a component that exists is not a
 * folder (a file where the folder should be) or the path does not fit. */
static int existing_folder(const char *dir, char *buf, size_t cap, int *not_dir)
{
    *not_dir = 0;
    int n = snprintf(buf, cap, "%s", dir[0] ? dir : ".");
    if (n < 0 || (size_t)n >= cap)
        return -1;
    for (;;) {
        struct stat st;
        if (stat(buf, &st) == 0) {
            if (S_ISDIR(st.st_mode))
                return 0;
            *not_dir = 1;
            return -1;
        }
        /* ENOTDIR: a component above is a file; walking up finds it, so the message names
         * it. */
        if (errno != ENOENT && errno != ENOTDIR)
            return -1;
        char *slash = strrchr(buf, '/');
        if (!slash)
            return snprintf(buf, cap, ".") > 0 ? 0 : -1;
        if (slash == buf) {
            buf[1] = '\0';
            return 0;
        }
        *slash = '\0';
    }
}

static int probe(const char *folder, lr_err *e)
{
    char path[PATH_MAX];
    int n = snprintf(path, sizeof path, "%s/.lamprig-probe-XXXXXX", folder);
    if (n < 0 || (size_t)n >= sizeof path)
        return lr_err_set(e, LR_EIO, "%s: path too long", folder);
    int fd = mkstemp(path);
    if (fd < 0)
        return lr_err_set(e, LR_EIO, "%s: cannot create a file: %s", folder, strerror(errno));
    static const char zeros[PROBE_BYTES];
    ssize_t w = write(fd, zeros, sizeof zeros);
    int err = w < 0 ? errno : ENOSPC;
    close(fd);
    unlink(path);
    if (w != (ssize_t)sizeof zeros)
        return lr_err_set(e, LR_EIO, "%s: cannot write a file: %s", folder, strerror(err));
    return LR_OK;
}

int lr_dir_check_writable(const char *dir, uint64_t min_free, lr_err *e)
{
    char folder[PATH_MAX];
    int not_dir;
    if (!dir)
        return lr_err_set(e, LR_EINVAL, "no folder given");
    if (existing_folder(dir, folder, sizeof folder, &not_dir))
        return lr_err_set(e, LR_EIO, "%s: %s", not_dir ? folder : dir,
                          not_dir ? "not a folder" : strerror(errno));
    struct statvfs vs;
    if (statvfs(folder, &vs) != 0)
        return lr_err_set(e, LR_EIO, "%s: %s", folder, strerror(errno));
    if (vs.f_flag & ST_RDONLY)
        return lr_err_set(e, LR_EIO, "%s: read-only file system", folder);
    uint64_t avail = (uint64_t)vs.f_bavail * (uint64_t)vs.f_frsize;
    if (avail < min_free)
        return lr_err_set(e, LR_EIO, "%s: %llu kB free, under %llu kB", folder,
                          (unsigned long long)(avail / 1024), (unsigned long long)(min_free / 1024));
    return probe(folder, e);
}
