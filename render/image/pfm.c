/* lamprig — Portable Float Map: "PF\n<w> <h>\n<scale>\n" then raw 32-bit floats, rows bottom
 * to top; a negative scale means little-endian (the PFM convention, e.g. Paul Debevec's HDR
 * Shop and pfstools). */
#include "render/image/image.h"

#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/atomic_file.h"
#include "render/base/file.h"

int lr_image_write_pfm(const char *path, const lr_image *img, lr_err *e)
{
    if (!img->rgb || img->width < 1 || img->height < 1)
        return lr_err_set(e, LR_EINVAL, "%s: empty image", path);
    size_t row = (size_t)img->width * 3;
    unsigned char *buf = malloc(row * 4);
    if (!buf)
        return lr_err_set(e, LR_ENOMEM, "%s: row buffer", path);
    lr_atomic_file *af;
    int rc = lr_atomic_file_open(path, &af, e);
    if (rc) {
        free(buf);
        return rc;
    }
    FILE *f = lr_atomic_file_stream(af);
    fprintf(f, "PF\n%d %d\n-1.0\n", img->width, img->height);
    for (int y = img->height - 1; y >= 0; y--) {
        const float *src = img->rgb + (size_t)y * row;
        /* Explicit little-endian bytes: the file is the same whatever the host. */
        for (size_t i = 0; i < row; i++) {
            uint32_t u;
            memcpy(&u, &src[i], 4);
            for (int b = 0; b < 4; b++)
                buf[4 * i + (size_t)b] = (unsigned char)(u >> (8 * b));
        }
        fwrite(buf, 4, row, f);
    }
    free(buf);
    return lr_atomic_file_commit(af, e); /* reports any write error of the above */
}

/* Reads one whitespace-delimited header token into tok; returns the position after it. */
static size_t token(const unsigned char *d, size_t n, size_t pos, char *tok, size_t cap)
{
    while (pos < n && (d[pos] == ' ' || d[pos] == '\t' || d[pos] == '\n' || d[pos] == '\r'))
        pos++;
    size_t k = 0;
    while (pos < n && k + 1 < cap && !(d[pos] == ' ' || d[pos] == '\t' || d[pos] == '\n' || d[pos] == '\r'))
        tok[k++] = (char)d[pos++];
    tok[k] = '\0';
    return pos;
}

static int parse_int(const char *s, int *v)
{
    char *end;
    errno = 0;
    long x = strtol(s, &end, 10);
    if (errno || end == s || *end || x < 1 || x > LR_IMAGE_MAX_SIDE)
        return -1;
    *v = (int)x;
    return 0;
}

int lr_image_read_pfm(const char *path, lr_image *out, lr_err *e)
{
    out->width = out->height = 0;
    out->rgb = NULL;
    char *text = NULL;
    size_t n = 0;
    int rc = lr_file_read(path, LR_FILE_MAX_DATA, &text, &n, e);
    const unsigned char *d = (const unsigned char *)text;
    if (rc)
        return rc;
    char magic[8], ws[16], hs[16], ss[32];
    size_t pos = token(d, n, 0, magic, sizeof magic);
    int channels = strcmp(magic, "PF") == 0 ? 3 : strcmp(magic, "Pf") == 0 ? 1 : 0;
    int w = 0, h = 0;
    if (!channels) {
        rc = lr_err_set(e, LR_EPARSE, "%s: not a PFM file (no PF/Pf signature)", path);
        goto done;
    }
    pos = token(d, n, pos, ws, sizeof ws);
    pos = token(d, n, pos, hs, sizeof hs);
    if (pos >= n) {
        rc = lr_err_set(e, LR_EPARSE, "%s: truncated PFM header", path);
        goto done;
    }
    if (parse_int(ws, &w) || parse_int(hs, &h)) {
        rc = lr_err_set(e, LR_EPARSE, "%s: bad PFM size \"%s %s\" (1..%d)", path, ws, hs,
                        LR_IMAGE_MAX_SIDE);
        goto done;
    }
    pos = token(d, n, pos, ss, sizeof ss);
    /* Exactly one whitespace character separates the header from the data. */
    if (pos >= n) {
        rc = lr_err_set(e, LR_EPARSE, "%s: truncated PFM header", path);
        goto done;
    }
    char *end;
    double scale = strtod(ss, &end);
    if (end == ss || *end || !isfinite(scale) || scale == 0.0) {
        rc = lr_err_set(e, LR_EPARSE, "%s: bad PFM scale \"%s\"", path, ss);
        goto done;
    }
    pos++; /* the token stopped at a whitespace character, which ends the header */
    size_t want = (size_t)w * (size_t)h * (size_t)channels * 4, have = n - pos;
    if (have < want) {
        rc = lr_err_set(e, LR_EPARSE, "%s: truncated: %zu of %zu pixel bytes", path, have, want);
        goto done;
    }
    if (have > want) {
        rc = lr_err_set(e, LR_EPARSE, "%s: %zu unexpected bytes after the pixel data", path,
                        have - want);
        goto done;
    }
    if ((rc = lr_image_alloc(out, w, h, e))) {
        lr_err_prefix(e, "%s", path);
        goto done;
    }
    bool little = scale < 0.0;
    const unsigned char *p = d + pos;
    for (int y = h - 1; y >= 0; y--) {
        float *dst = out->rgb + (size_t)y * (size_t)w * 3;
        for (int x = 0; x < w; x++) {
            for (int c = 0; c < channels; c++, p += 4) {
                uint32_t u = little ? (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 |
                                          (uint32_t)p[3] << 24
                                    : (uint32_t)p[3] | (uint32_t)p[2] << 8 | (uint32_t)p[1] << 16 |
                                          (uint32_t)p[0] << 24;
                memcpy(&dst[3 * x + c], &u, 4);
            }
            if (channels == 1)
                dst[3 * x + 1] = dst[3 * x + 2] = dst[3 * x];
        }
    }
done:
    free(text);
    return rc;
}
