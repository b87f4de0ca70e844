/* Portable float maps for references and their variance: "PF\n<w> <h>\n-1.0\n", then
 * little-endian 32-bit floats, rows bottom to top (the PFM convention; a negative scale means
 * little-endian). render/image on the gl branch reads and writes the same format; once it is
 * on main these two functions can defer to it. */
#include "render/reference/ref_priv.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/atomic_file.h"

int lr_ref_pfm_write(const char *path, const lr_ref_image *img, lr_err *e)
{
    if (!img->rgb || img->width < 1 || img->height < 1)
        return lr_err_set(e, LR_EINVAL, "%s: empty image", path);
    lr_atomic_file *af;
    int rc = lr_atomic_file_open(path, &af, e);
    if (rc)
        return rc;
    FILE *f = lr_atomic_file_stream(af);
    fprintf(f, "PF\n%d %d\n-1.0\n", img->width, img->height);
    size_t row = (size_t)img->width * 3;
    for (int y = img->height - 1; y >= 0; y--) {
        const float *src = img->rgb + (size_t)y * row;
        for (size_t i = 0; i < row; i++) {
            uint32_t u;
            memcpy(&u, &src[i], 4);
            unsigned char b[4] = {(unsigned char)u, (unsigned char)(u >> 8),
                                  (unsigned char)(u >> 16), (unsigned char)(u >> 24)};
            fwrite(b, 1, 4, f);
        }
    }
    return lr_atomic_file_commit(af, e); /* reports any write error above */
}

int lr_ref_pfm_read(const char *path, lr_ref_image *out, lr_err *e)
{
    *out = (lr_ref_image){0};
    FILE *f = fopen(path, "rb");
    if (!f)
        return lr_err_set(e, LR_EIO, "%s: %s", path, strerror(errno));
    char magic[3] = {0};
    int w = 0, h = 0;
    double scale = 0.0;
    int rc = LR_OK;
    /* Header: three whitespace-separated tokens after the magic, then exactly one
     * whitespace byte before the data. */
    if (fscanf(f, "%2s %d %d %lf", magic, &w, &h, &scale) != 4 || strcmp(magic, "PF") != 0 ||
        w < 1 || h < 1 || w > 16384 || h > 16384 || scale == 0.0 || fgetc(f) == EOF)
        rc = lr_err_set(e, LR_EPARSE, "%s: not a colour PFM (PF, width, height, scale)", path);
    size_t n = (size_t)w * (size_t)h * 3;
    unsigned char *raw = NULL;
    if (!rc && (!(raw = malloc(n * 4)) || !(out->rgb = malloc(n * sizeof *out->rgb))))
        rc = lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
    if (!rc && fread(raw, 4, n, f) != n)
        rc = lr_err_set(e, LR_EPARSE, "%s: truncated pixel data", path);
    if (!rc && fgetc(f) != EOF)
        rc = lr_err_set(e, LR_EPARSE, "%s: trailing bytes after the pixels", path);
    if (!rc) {
        bool little = scale < 0.0;
        size_t row = (size_t)w * 3;
        for (int y = 0; y < h; y++) {
            const unsigned char *src = raw + (size_t)(h - 1 - y) * row * 4;
            for (size_t i = 0; i < row; i++) {
                const unsigned char *b = src + 4 * i;
                uint32_t u = little ? (uint32_t)b[0] | (uint32_t)b[1] << 8 |
                                          (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24
                                    : (uint32_t)b[3] | (uint32_t)b[2] << 8 |
                                          (uint32_t)b[1] << 16 | (uint32_t)b[0] << 24;
                memcpy(&out->rgb[(size_t)y * row + i], &u, 4);
            }
        }
        out->width = w;
        out->height = h;
    }
    free(raw);
    fclose(f);
    if (rc)
        lr_ref_image_free(out);
    return rc;
}
