/* lamprig — sweeping stale temps and capping a cache folder's size (cache_dir.h). */
#include "render/base/cache_dir.h"

#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

int lr_cache_dir_ours(const char *name, int *temp)
{
    const char *p = name;
    *temp = 0;
    if (!islower((unsigned char)*p))
        return 0;
    while (islower((unsigned char)*p))
        p++;
    if (*p++ != '-')
        return 0;
    for (int i = 0; i < 16; i++, p++)
        if (!isxdigit((unsigned char)*p) || isupper((unsigned char)*p))
            return 0;
    if (strncmp(p, ".bin", 4) != 0)
        return 0;
    p += 4;
    if (!*p)
        return 1;
    if (strncmp(p, ".tmp", 4) != 0)
        return 0;
    p += 4;
    for (int i = 0; i < 6; i++, p++)
        if (!isalnum((unsigned char)*p))
            return 0;
    if (*p)
        return 0;
    *temp = 1;
    return 1;
}

typedef struct entry {
    char *name;
    uint64_t bytes;
    time_t used;
} entry;

static int by_use(const void *a, const void *b)
{
    const entry *x = a, *y = b;
    return (x->used > y->used) - (x->used < y->used);
}

int lr_cache_dir_tidy(const char *dir, uint64_t max_bytes, time_t now, lr_cache_tidy *out,
                      lr_err *e)
{
    memset(out, 0, sizeof *out);
    int dfd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd < 0)
        return errno == ENOENT ? LR_OK : lr_err_set(e, LR_EIO, "%s: %s", dir, strerror(errno));
    DIR *d = fdopendir(dfd);
    if (!d) {
        int err = errno;
        close(dfd);
        return lr_err_set(e, LR_EIO, "%s: %s", dir, strerror(err));
    }
    entry *v = NULL;
    size_t n = 0, cap = 0;
    int rc = LR_OK;
    for (struct dirent *de; (de = readdir(d));) {
        int temp;
        struct stat st;
        if (!lr_cache_dir_ours(de->d_name, &temp) ||
            fstatat(dfd, de->d_name, &st, AT_SYMLINK_NOFOLLOW) != 0 || !S_ISREG(st.st_mode))
            continue;
        if (temp) {
            if (now - st.st_mtime > LR_CACHE_TEMP_AGE_S && unlinkat(dfd, de->d_name, 0) == 0)
                out->temps_removed++;
            continue;
        }
        if (n == cap) {
            size_t nc = cap ? 2 * cap : 64;
            entry *t = realloc(v, nc * sizeof *v);
            if (!t) {
                rc = lr_err_set(e, LR_ENOMEM, "%s: out of memory", dir);
                break;
            }
            v = t;
            cap = nc;
        }
        v[n].name = strdup(de->d_name);
        if (!v[n].name) {
            rc = lr_err_set(e, LR_ENOMEM, "%s: out of memory", dir);
            break;
        }
        v[n].bytes = (uint64_t)st.st_size;
        v[n].used = st.st_atime > st.st_mtime ? st.st_atime : st.st_mtime;
        out->bytes_before += v[n].bytes;
        n++;
    }
    out->bytes_after = out->bytes_before;
    if (!rc && out->bytes_before > max_bytes) {
        qsort(v, n, sizeof *v, by_use);
        for (size_t i = 0; i < n && out->bytes_after > max_bytes; i++)
            if (unlinkat(dfd, v[i].name, 0) == 0) {
                out->bytes_after -= v[i].bytes;
                out->files_removed++;
            }
    }
    for (size_t i = 0; i < n; i++)
        free(v[i].name);
    free(v);
    closedir(d);
    return rc;
}

int lr_cache_max_bytes(uint64_t *out, lr_err *e)
{
    *out = LR_CACHE_MAX_BYTES_DEFAULT;
    const char *s = getenv("LAMPRIG_CACHE_MAX_MB");
    if (!s)
        return LR_OK;
    char *end;
    errno = 0;
    unsigned long long mb = strtoull(s, &end, 10);
    if (!isdigit((unsigned char)s[0]) || *end || errno || mb == 0 || mb > ((uint64_t)1 << 40))
        return lr_err_set(e, LR_EINVAL, "LAMPRIG_CACHE_MAX_MB: '%s' is not a positive number of "
                          "MiB", s);
    *out = (uint64_t)mb << 20;
    return LR_OK;
}
