#include "render/base/atomic_file.h"

#include <errno.h>
#include <fcntl.h>
#include <libgen.h>
#include <sys/stat.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "render/base/umask.h"

struct lr_atomic_file {
    FILE *stream;
    char *path;
    char *tmp;
};

int lr_atomic_file_open(const char *path, lr_atomic_file **out, lr_err *e)
{
    return lr_atomic_file_open_mode(path, LR_FILE_MODE_DATA, out, e);
}

int lr_atomic_file_open_mode(const char *path, mode_t mode, lr_atomic_file **out, lr_err *e)
{
    *out = NULL;
    lr_atomic_file *f = calloc(1, sizeof *f);
    size_t n = strlen(path) + 16;
    if (!f || !(f->path = strdup(path)) || !(f->tmp = malloc(n))) {
        if (f)
            free(f->path);
        free(f);
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
    }
    snprintf(f->tmp, n, "%s.tmpXXXXXX", path);
    int fd = mkstemp(f->tmp);
    if (fd < 0) {
        int err = errno;
        free(f->tmp);
        free(f->path);
        free(f);
        return lr_err_set(e, LR_EIO, "%s: cannot create a temporary file beside it: %s", path, strerror(err));
    }
    /* mkstemp makes 0600 whatever the umask; the file gets the mode open(2) would have given
     * it (a service's UMask= and a user's umask decide who may read its output). */
    if (fchmod(fd, mode & ~lr_umask_get() & 0777) != 0) {
        int err = errno;
        close(fd);
        unlink(f->tmp);
        free(f->tmp);
        free(f->path);
        free(f);
        return lr_err_set(e, LR_EIO, "%s: cannot set the mode of its temporary file: %s", path,
                          strerror(err));
    }
    f->stream = fdopen(fd, "wb");
    if (!f->stream) {
        close(fd);
        unlink(f->tmp);
        free(f->tmp);
        free(f->path);
        free(f);
        return lr_err_set(e, LR_EIO, "%s: fdopen failed", path);
    }
    *out = f;
    return LR_OK;
}

FILE *lr_atomic_file_stream(lr_atomic_file *f) { return f->stream; }

static void release(lr_atomic_file *f)
{
    free(f->tmp);
    free(f->path);
    free(f);
}

int lr_atomic_file_commit(lr_atomic_file *f, lr_err *e)
{
    int rc = LR_OK;
    int bad = ferror(f->stream) || fflush(f->stream) != 0 || fsync(fileno(f->stream)) != 0;
    int err = errno;
    if (fclose(f->stream) != 0 && !bad) {
        bad = 1;
        err = errno;
    }
    if (bad) {
        rc = lr_err_set(e, LR_EIO, "%s: write failed: %s", f->path, strerror(err));
        unlink(f->tmp);
    } else if (rename(f->tmp, f->path) != 0) {
        rc = lr_err_set(e, LR_EIO, "%s: rename failed: %s", f->path, strerror(errno));
        unlink(f->tmp);
    } else {
        /* Make the rename itself durable. */
        char *dup = strdup(f->path);
        if (dup) {
            int dfd = open(dirname(dup), O_RDONLY | O_DIRECTORY);
            if (dfd >= 0) {
                (void)fsync(dfd);
                close(dfd);
            }
            free(dup);
        }
    }
    release(f);
    return rc;
}

void lr_atomic_file_abort(lr_atomic_file *f)
{
    if (!f)
        return;
    fclose(f->stream);
    unlink(f->tmp);
    release(f);
}

int lr_atomic_file_check(const char *path, lr_err *e)
{
    struct stat st;
    if (!path || !path[0])
        return lr_err_set(e, LR_EINVAL, "empty output path");
    if (stat(path, &st) == 0 && S_ISDIR(st.st_mode))
        return lr_err_set(e, LR_EINVAL, "%s: is a directory (expected a file name)", path);
    /* The same temp file the write will make: proves the directory exists and is writable. */
    lr_atomic_file *f;
    int rc = lr_atomic_file_open(path, &f, e);
    if (rc)
        return rc;
    lr_atomic_file_abort(f);
    return LR_OK;
}

int lr_atomic_write(const char *path, const void *data, size_t len, lr_err *e)
{
    return lr_atomic_write_mode(path, data, len, LR_FILE_MODE_DATA, e);
}

int lr_atomic_write_mode(const char *path, const void *data, size_t len, mode_t mode, lr_err *e)
{
    lr_atomic_file *f;
    int rc = lr_atomic_file_open_mode(path, mode, &f, e);
    if (rc)
        return rc;
    if (len && fwrite(data, 1, len, f->stream) != len) {
        int err = errno;
        lr_atomic_file_abort(f);
        return lr_err_set(e, LR_EIO, "%s: write failed: %s", path, strerror(err));
    }
    return lr_atomic_file_commit(f, e);
}
