#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "render/mesh/mesh_internal.h"
#include "render/base/file.h"

int lr_mesh_read_file(const char *path, char **buf, size_t *len, lr_err *e)
{
    *buf = NULL;
    *len = 0;
    /* A regular file only: a FIFO would block the open for ever, a device read for ever. */
    FILE *f;
    int rc = lr_file_fopen_regular(path, &f, e);
    if (rc)
        return rc;
    char *b = NULL;
    size_t n = 0, cap = 0;
    for (;;) {
        if (n + 1 >= cap) {
            size_t nc = cap ? 2 * cap : 65536;
            if (nc > LR_MESH_FILE_MAX + 2)
                nc = LR_MESH_FILE_MAX + 2;
            char *nb = realloc(b, nc);
            if (!nb) {
                free(b);
                fclose(f);
                return lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
            }
            b = nb;
            cap = nc;
        }
        size_t got = fread(b + n, 1, cap - n - 1, f);
        n += got;
        if (n > LR_MESH_FILE_MAX) {
            free(b);
            fclose(f);
            return lr_err_set(e, LR_EPARSE, "%s: larger than %zu MiB", path,
                              LR_MESH_FILE_MAX >> 20);
        }
        if (got == 0)
            break;
    }
    int err = ferror(f);
    fclose(f);
    if (err) {
        free(b);
        return lr_err_set(e, LR_EIO, "%s: read error", path);
    }
    b[n] = '\0';
    *buf = b;
    *len = n;
    return LR_OK;
}
