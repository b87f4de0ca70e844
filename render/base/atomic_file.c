/* lamprig — write-to-temp-then-rename files. */
#include "render/base/atomic_file.h"

#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

struct lr_atomic_file {
    FILE *f;
    char *path;
    char *tmp;
};

int lr_atomic_open(const char *path, lr_atomic_file **out, lr_err *e)
{
    *out = NULL;
    lr_atomic_file *af = calloc(1, sizeof *af);
    size_t n = strlen(path);
    if (af) {
        af->path = strdup(path);
        af->tmp = malloc(n + sizeof ".tmp-XXXXXX");
    }
    if (!af || !af->path || !af->tmp) {
        if (af) {
            free(af->path);
            free(af->tmp);
        }
        free(af);
        return lr_err_set(e, LR_ENOMEM, "%s", path);
    }
    memcpy(af->tmp, path, n);
    memcpy(af->tmp + n, ".tmp-XXXXXX", sizeof ".tmp-XXXXXX");
    int fd = mkstemp(af->tmp);
    if (fd < 0) {
        int err = errno;
        free(af->path);
        free(af->tmp);
        free(af);
        return lr_err_set(e, LR_EIO, "%s: cannot create a temporary file beside it: %s", path,
                          strerror(err));
    }
    /* mkstemp makes 0600; an image or calibration file should be readable like any other.
     * (Fixed 0644 rather than 0666 & ~umask: reading the umask means setting it, which races
     * with other threads creating files.) */
    fchmod(fd, 0644);
    af->f = fdopen(fd, "wb");
    if (!af->f) {
        int err = errno;
        close(fd);
        unlink(af->tmp);
        free(af->path);
        free(af->tmp);
        free(af);
        return lr_err_set(e, LR_EIO, "%s: %s", path, strerror(err));
    }
    *out = af;
    return LR_OK;
}

FILE *lr_atomic_stream(lr_atomic_file *af) { return af->f; }

static void release(lr_atomic_file *af)
{
    free(af->path);
    free(af->tmp);
    free(af);
}

void lr_atomic_abort(lr_atomic_file *af)
{
    if (!af)
        return;
    if (af->f)
        fclose(af->f);
    unlink(af->tmp);
    release(af);
}

/* Makes the rename itself durable (POSIX leaves directory entries to the directory's fsync). */
static void sync_dir(const char *path)
{
    const char *slash = strrchr(path, '/');
    char dir[4096];
    if (!slash)
        snprintf(dir, sizeof dir, ".");
    else if (slash == path)
        snprintf(dir, sizeof dir, "/");
    else
        snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    int fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd >= 0) {
        fsync(fd);
        close(fd);
    }
}

int lr_atomic_commit(lr_atomic_file *af, lr_err *e)
{
    int err = 0;
    if (fflush(af->f) != 0 || ferror(af->f))
        err = errno ? errno : EIO;
    else if (fsync(fileno(af->f)) != 0)
        err = errno;
    if (fclose(af->f) != 0 && !err)
        err = errno;
    af->f = NULL;
    if (!err && rename(af->tmp, af->path) != 0)
        err = errno;
    if (err) {
        int rc = lr_err_set(e, LR_EIO, "%s: write failed: %s", af->path, strerror(err));
        lr_atomic_abort(af);
        return rc;
    }
    sync_dir(af->path);
    release(af);
    return LR_OK;
}
