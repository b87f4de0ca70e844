/* lamprig — whole-file reads. */
#include "render/base/file.h"

#include <errno.h>
#include <fcntl.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

int lr_file_open_regular(const char *path, lr_err *e)
{
    /* O_NONBLOCK: opening a FIFO for reading would wait for a writer for ever. Cleared below
     * once fstat proved a regular file (where it changes nothing anyway). */
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0)
        return -lr_err_set(e, LR_EIO, "%s: cannot open: %s", path, strerror(errno));
    struct stat st;
    if (fstat(fd, &st) != 0) {
        int err = errno;
        close(fd);
        return -lr_err_set(e, LR_EIO, "%s: %s", path, strerror(err));
    }
    if (!S_ISREG(st.st_mode)) {
        close(fd);
        const char *what = S_ISDIR(st.st_mode)    ? "a directory"
                           : S_ISFIFO(st.st_mode) ? "a FIFO"
                           : S_ISCHR(st.st_mode)  ? "a character device"
                           : S_ISBLK(st.st_mode)  ? "a block device"
                           : S_ISSOCK(st.st_mode) ? "a socket"
                                                  : "not a regular file";
        return -lr_err_set(e, LR_EIO, "%s: %s, not a regular file", path, what);
    }
    int fl = fcntl(fd, F_GETFL);
    if (fl < 0 || fcntl(fd, F_SETFL, fl & ~O_NONBLOCK) != 0) {
        int err = errno;
        close(fd);
        return -lr_err_set(e, LR_EIO, "%s: %s", path, strerror(err));
    }
    return fd;
}

int lr_file_fopen_regular(const char *path, FILE **out, lr_err *e)
{
    *out = NULL;
    int fd = lr_file_open_regular(path, e);
    if (fd < 0)
        return -fd;
    *out = fdopen(fd, "rb");
    if (!*out) {
        close(fd);
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
    }
    return LR_OK;
}

int lr_file_read(const char *path, size_t max, char **data, size_t *len, lr_err *e)
{
    *data = NULL;
    *len = 0;
    int fd = lr_file_open_regular(path, e);
    if (fd < 0)
        return -fd;
    /* Grow as we go rather than trusting st_size: a file may grow while it is read, and /proc
     * reports 0. The cap bounds both. */
    char *buf = NULL;
    size_t n = 0, cap = 0;
    int err = 0;
    bool over = false;
    for (;;) {
        if (cap - n < 2) {
            size_t ncap = cap ? 2 * cap : 1 << 14;
            if (ncap > max + 2)
                ncap = max + 2;
            char *t = realloc(buf, ncap);
            if (!t) {
                err = ENOMEM;
                break;
            }
            buf = t;
            cap = ncap;
        }
        ssize_t k = read(fd, buf + n, cap - n - 1);
        if (k < 0) {
            if (errno == EINTR)
                continue;
            err = errno;
            break;
        }
        n += (size_t)k;
        if (n > max) {
            over = true;
            break;
        }
        if (k == 0)
            break;
    }
    close(fd);
    if (err || over) {
        free(buf);
        if (over)
            return lr_err_set(e, LR_EIO, "%s: larger than %zu bytes, the most this kind of file "
                              "may have", path, max);
        return lr_err_set(e, err == ENOMEM ? LR_ENOMEM : LR_EIO, "%s: %s", path, strerror(err));
    }
    buf[n] = '\0';
    *data = buf;
    *len = n;
    return LR_OK;
}

int lr_dir_make(const char *dir, const char *what, lr_err *e)
{
    char parent[1024];
    snprintf(parent, sizeof parent, "%s", dir);
    char *slash = strrchr(parent, '/');
    if (slash && slash != parent) {
        *slash = 0;
        (void)mkdir(parent, 0777);
    }
    if (mkdir(dir, 0777) != 0 && errno != EEXIST)
        return lr_err_set(e, LR_EIO, "%s: %s: %s", what, dir, strerror(errno));
    return LR_OK;
}
