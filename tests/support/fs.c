/* lamprig tests — scratch directories and files. */
#include "tests/support/fs.h"

#include <ftw.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <unistd.h>

static void die(const char *what, const char *path)
{
    perror(path);
    fprintf(stderr, "test support: %s failed\n", what);
    abort();
}

char *lr_test_tmpdir(void)
{
    const char *base = getenv("TMPDIR");
    char *dir = lr_test_path(base && *base ? base : "/tmp", "lamprig-test-XXXXXX");
    if (!mkdtemp(dir))
        die("mkdtemp", dir);
    return dir;
}

static int rm_one(const char *path, const struct stat *st, int flag, struct FTW *ftw)
{
    return remove(path);
}

void lr_test_rmtree(char *dir)
{
    if (dir)
        nftw(dir, rm_one, 16, FTW_DEPTH | FTW_PHYS);
    free(dir);
}

char *lr_test_path(const char *dir, const char *name)
{
    size_t n = strlen(dir) + strlen(name) + 2;
    char *p = malloc(n);
    if (!p)
        die("malloc", name);
    snprintf(p, n, "%s/%s", dir, name);
    return p;
}

char *lr_test_write(const char *dir, const char *name, const void *data, size_t len)
{
    char *path = lr_test_path(dir, name);
    for (char *s = strchr(path + strlen(dir) + 1, '/'); s; s = strchr(s + 1, '/')) {
        *s = '\0';
        mkdir(path, 0755);
        *s = '/';
    }
    lr_test_put(path, data, len);
    return path;
}

void lr_test_put(const char *path, const void *data, size_t len)
{
    if (len == (size_t)-1)
        len = strlen(data);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(data, 1, len, f) != len || fclose(f) != 0)
        die("write", path);
}

unsigned char *lr_test_read(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        die("open", path);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *buf = malloc((size_t)n + 1);
    if (!buf || fread(buf, 1, (size_t)n, f) != (size_t)n)
        die("read", path);
    fclose(f);
    buf[n] = '\0';
    *len = (size_t)n;
    return buf;
}

int lr_test_mount_tmpfs(const char *dir, unsigned kib, int read_only)
{
    char opts[64];
    snprintf(opts, sizeof opts, "size=%uk", kib);
    return mount("tmpfs", dir, "tmpfs", read_only ? MS_RDONLY : 0, opts);
}

void lr_test_umount(const char *dir) { (void)umount2(dir, MNT_DETACH); }
