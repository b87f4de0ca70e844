/* lamprig — PNG through libpng's simplified API (png_image), which keeps libpng's longjmp
 * error handling inside libpng and reports failures as a message in the png_image. */
#include "render/image/image.h"

#include <errno.h>
#include <math.h>
#include <png.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "render/base/atomic_file.h"
#include "render/base/file.h"

int lr_image_write_png(const char *path, const lr_image *img, const lr_tonemap *tm, lr_err *e)
{
    if (!img->rgb || img->width < 1 || img->height < 1)
        return lr_err_set(e, LR_EINVAL, "%s: empty image", path);
    size_t n = (size_t)img->width * (size_t)img->height * 3;
    unsigned char *px = malloc(n);
    if (!px)
        return lr_err_set(e, LR_ENOMEM, "%s: %dx%d pixels", path, img->width, img->height);
    for (size_t i = 0; i < n; i++)
        px[i] = (unsigned char)lrintf(lr_srgb_encode(lr_tonemap_apply(tm, img->rgb[i])) * 255.0f);

    lr_atomic_file *af;
    int rc = lr_atomic_file_open(path, &af, e);
    if (rc) {
        free(px);
        return rc;
    }
    png_image pi;
    memset(&pi, 0, sizeof pi);
    pi.version = PNG_IMAGE_VERSION;
    pi.width = (png_uint_32)img->width;
    pi.height = (png_uint_32)img->height;
    /* 8-bit, not PNG_FORMAT_FLAG_LINEAR: libpng tags it as sRGB. */
    pi.format = PNG_FORMAT_RGB;
    int ok = png_image_write_to_stdio(&pi, lr_atomic_file_stream(af), 0, px, 0, NULL);
    free(px);
    if (!ok) {
        rc = lr_err_set(e, LR_EIO, "%s: PNG encoding failed: %s", path, pi.message);
        png_image_free(&pi);
        lr_atomic_file_abort(af);
        return rc;
    }
    return lr_atomic_file_commit(af, e);
}

/* Decodes an open PNG into out; pi is released by the caller. */
static int decode(const char *path, FILE *f, png_image *pi, lr_image *out, lr_err *e)
{
    if (!png_image_begin_read_from_stdio(pi, f))
        /* libpng says "Not a PNG file", "Read Error", "IHDR: CRC error" ... */
        return lr_err_set(e, LR_EPARSE, "%s: not a readable PNG: %s", path, pi->message);
    if (pi->width < 1 || pi->height < 1 || pi->width > LR_IMAGE_MAX_SIDE ||
        pi->height > LR_IMAGE_MAX_SIDE)
        return lr_err_set(e, LR_EPARSE, "%s: PNG size %ux%u outside 1..%d", path,
                          (unsigned)pi->width, (unsigned)pi->height, LR_IMAGE_MAX_SIDE);
    pi->format = PNG_FORMAT_RGB;
    size_t n = PNG_IMAGE_SIZE(*pi);
    unsigned char *px = malloc(n);
    if (!px)
        return lr_err_set(e, LR_ENOMEM, "%s: %ux%u pixels", path, (unsigned)pi->width,
                          (unsigned)pi->height);
    png_color black = {0, 0, 0};
    int rc = LR_OK;
    if (!png_image_finish_read(pi, &black, px, 0, NULL))
        rc = lr_err_set(e, LR_EPARSE, "%s: corrupt or truncated PNG: %s", path, pi->message);
    else if ((rc = lr_image_alloc(out, (int)pi->width, (int)pi->height, e)) != LR_OK)
        lr_err_prefix(e, "%s", path);
    if (rc == LR_OK) {
        /* 256-entry table: the same decode for every pixel, and no powf per channel. */
        float lut[256];
        for (int i = 0; i < 256; i++)
            lut[i] = lr_srgb_decode((float)i / 255.0f);
        for (size_t i = 0; i < n; i++)
            out->rgb[i] = lut[px[i]];
    }
    free(px);
    return rc;
}

int lr_image_read_png(const char *path, lr_image *out, lr_err *e)
{
    out->width = out->height = 0;
    out->rgb = NULL;
    /* Opened here so a missing file is an I/O error in errno's words, not a PNG error. */
    /* A regular file only: a FIFO would block the open for ever, a device read for ever. */
    FILE *f;
    int rc = lr_file_fopen_regular(path, &f, e);
    if (rc)
        return rc;
    png_image pi;
    memset(&pi, 0, sizeof pi);
    pi.version = PNG_IMAGE_VERSION;
    rc = decode(path, f, &pi, out, e);
    png_image_free(&pi);
    fclose(f);
    return rc;
}
