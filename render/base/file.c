/* lamprig — whole-file reads. */
#include "render/base/file.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

int lr_file_read(const char *path, char **data, size_t *len, lr_err *e)
{
    *data = NULL;
    *len = 0;
    FILE *f = fopen(path, "rb");
    if (!f)
        return lr_err_set(e, LR_EIO, "%s: cannot open: %s", path, strerror(errno));
    /* Grow as we go rather than trusting a size from fstat: pipes and /proc report 0. */
    char *buf = NULL;
    size_t n = 0, cap = 0;
    int err = 0;
    for (;;) {
        if (cap - n < 2) {
            size_t ncap = cap ? 2 * cap : 1 << 14;
            char *t = realloc(buf, ncap);
            if (!t) {
                err = ENOMEM;
                break;
            }
            buf = t;
            cap = ncap;
        }
        size_t k = fread(buf + n, 1, cap - n - 1, f);
        n += k;
        if (k == 0) {
            if (ferror(f))
                err = errno ? errno : EIO;
            break;
        }
    }
    fclose(f);
    if (err) {
        free(buf);
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
