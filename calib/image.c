#include "calib/image.h"

#include <errno.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calib/cv_shim.h"
#include "render/base/atomic_file.h"

int lr_img_alloc(lr_img *img, int w, int h, int channels, int depth, lr_err *e)
{
    *img = (lr_img){0};
    if (w <= 0 || h <= 0 || w > 65536 || h > 65536 || (channels != 1 && channels != 3) ||
        (depth != 1 && depth != 2 && depth != 4))
        return lr_err_set(e, LR_EINVAL, "image %dx%d, %d channels, %d bytes: not supported", w,
                          h, channels, depth);
    void *px = calloc((size_t)w * (size_t)h * (size_t)channels, (size_t)depth);
    if (!px)
        return lr_err_set(e, LR_ENOMEM, "image %dx%d: out of memory", w, h);
    *img = (lr_img){w, h, channels, depth, px};
    return LR_OK;
}

void lr_img_free(lr_img *img)
{
    if (!img)
        return;
    free(img->px);
    *img = (lr_img){0};
}

int lr_img_read(const char *path, enum lr_img_read_mode mode, lr_img *out, lr_err *e)
{
    return lr_cv_imread(path, (int)mode, out, e);
}

static int encode(const char *path, const lr_img *img, void **buf, size_t *len, lr_err *e)
{
    const char *dot = strrchr(path, '.');
    const char *slash = strrchr(path, '/');
    if (!dot || (slash && dot < slash))
        return lr_err_set(e, LR_EINVAL, "%s: no file extension to choose the format", path);
    int rc = lr_cv_imencode(dot, img, buf, len, e);
    return rc ? lr_err_prefix(e, "%s", path) : LR_OK;
}

int lr_img_write(const char *path, const lr_img *img, lr_err *e)
{
    void *buf;
    size_t len;
    int rc = encode(path, img, &buf, &len, e);
    if (rc)
        return rc;
    rc = lr_atomic_write(path, buf, len, e);
    free(buf);
    return rc;
}

int lr_img_write_frame(const char *path, const lr_img *img, lr_err *e)
{
    void *buf;
    size_t len;
    int rc = encode(path, img, &buf, &len, e);
    if (rc)
        return rc;
    FILE *f = fopen(path, "wb");
    if (!f) {
        rc = lr_err_set(e, LR_EIO, "%s: cannot write: %s", path, strerror(errno));
    } else {
        bool bad = fwrite(buf, 1, len, f) != len;
        if (fclose(f) != 0 || bad)
            rc = lr_err_set(e, LR_EIO, "%s: write failed: %s", path, strerror(errno));
    }
    free(buf);
    return rc;
}

double lr_img_get(const lr_img *img, int x, int y, int c)
{
    size_t i = ((size_t)y * (size_t)img->w + (size_t)x) * (size_t)img->channels + (size_t)c;
    switch (img->depth) {
    case 1: return ((const uint8_t *)img->px)[i] / 255.0;
    case 2: return ((const uint16_t *)img->px)[i] / 65535.0;
    default: return ((const float *)img->px)[i];
    }
}
