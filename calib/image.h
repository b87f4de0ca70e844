/* lamprig calib — camera frames, projected patterns and HDR results as plain pixel buffers.
 *
 * An lr_img is data, not an object: width, height, channels (1 = grey, 3 = RGB in that order,
 * never OpenCV's BGR), bytes per sample (1 = 8-bit, 2 = 16-bit, 4 = float32) and a malloc'ed,
 * tightly packed, row-major buffer that the image owns. Reading and PNG/HDR encoding go
 * through the OpenCV shim (calib/cv_shim.h); writing is atomic (temp file + rename).
 */
#ifndef LR_CALIB_IMAGE_H
#define LR_CALIB_IMAGE_H

#include <stddef.h>
#include <stdint.h>

#include "render/base/err.h"

typedef struct lr_img {
    int w, h;
    int channels; /* 1 or 3 */
    int depth;    /* bytes per sample: 1 (uint8), 2 (uint16) or 4 (float) */
    void *px;
} lr_img;

enum lr_img_read_mode {
    LR_IMG_AS_IS = 0, /* keep depth; grey stays grey, colour becomes RGB, alpha is dropped */
    LR_IMG_GRAY8,     /* convert to one 8-bit channel (Gray-code decoding, board detection) */
    LR_IMG_RGB8,      /* convert to three 8-bit channels (exposure stacks, ColorChecker) */
};

/* Allocates a zeroed image. */
int lr_img_alloc(lr_img *img, int w, int h, int channels, int depth, lr_err *e);
void lr_img_free(lr_img *img);

/* Reads any format OpenCV decodes (PNG, JPEG, TIFF, PNM, ...). Errors name the path. */
int lr_img_read(const char *path, enum lr_img_read_mode mode, lr_img *out, lr_err *e);
/* Writes atomically and durably (temp + fsync + rename); the format follows the extension
 * (.png for 8/16-bit, .hdr for float). For results worth keeping (maps, HDR images). */
int lr_img_write(const char *path, const lr_img *img, lr_err *e);
/* Plain write without fsync, for bulk frames that can be regenerated or recaptured
 * (pattern sequences, captures: 40+ files a pose, where an fsync each costs seconds on an
 * SD card). A crash can leave a truncated file, which decoding then reports by name. */
int lr_img_write_frame(const char *path, const lr_img *img, lr_err *e);

/* Sample (x, y, c) scaled to [0, 1] for integer depths (v / 255 or v / 65535), as is for
 * float. No bounds check. */
double lr_img_get(const lr_img *img, int x, int y, int c);

#endif
