/* lamprig — linear RGB images and their files: tone-mapped 8-bit sRGB PNG, linear float PFM.
 *
 * An lr_image is plain data: width x height texels of three linear floats, rows top to bottom
 * (PNG order; PFM is stored bottom to top and flipped on the way in and out; GL readbacks are
 * bottom to top and go through lr_image_from_gl_rgba).
 *
 * Files are written atomically (temporary file beside the destination, then rename): a
 * reader never sees half an image. Read errors name the file and what is wrong with it
 * ("x.pfm: truncated: 1200 of 4800 pixel bytes").
 */
#ifndef LR_IMAGE_H
#define LR_IMAGE_H

#include "render/base/err.h"

typedef struct lr_image {
    int width, height;
    float *rgb; /* width * height * 3, owned; rows top to bottom */
} lr_image;

/* Largest side the readers accept; anything bigger in a header is taken as corruption. */
#define LR_IMAGE_MAX_SIDE 16384

/* Allocates a zeroed image; frees nothing first. LR_EINVAL for sides outside
 * 1..LR_IMAGE_MAX_SIDE. */
int lr_image_alloc(lr_image *img, int width, int height, lr_err *e);
/* Frees the pixels and zeroes the struct; safe on a zeroed or freed image. */
void lr_image_free(lr_image *img);
/* Allocates img from w x h RGBA floats in GL order (rows bottom up), dropping alpha. */
int lr_image_from_gl_rgba(lr_image *img, const float *rgba, int width, int height, lr_err *e);

/* Box filter by an integer factor: out is (src width / factor) x (src height / factor), each
 * pixel the mean of the factor x factor source pixels it covers. A pinhole image rendered at
 * factor times the size has its subpixel centres at (i + 1/2) / factor of each output pixel,
 * so the mean is the midpoint rule for the pixel's box integral: the footprint of the
 * physical reference (render/reference: a uniform random point in each pixel). LR_EINVAL
 * when a side is not a positive multiple of the factor; out is allocated (lr_image_free). */
int lr_image_downsample_box(const lr_image *src, int factor, lr_image *out, lr_err *e);

/* ---- tone mapping (the CPU twin of the composition pass's last step) --------------------- */

typedef enum lr_tonemap_op {
    LR_TONEMAP_CLAMP = 0, /* default: exposure, then clip to [0, 1] */
    LR_TONEMAP_REINHARD,  /* x / (1 + x) per channel */
    LR_TONEMAP_ACES,      /* Narkowicz 2015 fit of the ACES filmic curve */
} lr_tonemap_op;

typedef struct lr_tonemap {
    lr_tonemap_op op;
    float exposure; /* linear multiplier applied first; 0 means 1 */
} lr_tonemap;

/* Display-linear value in [0, 1] for one linear channel value (NaN and negatives give 0,
 * +Inf gives 1). tm may be NULL for the defaults. */
float lr_tonemap_apply(const lr_tonemap *tm, float linear);
/* The sRGB transfer function (IEC 61966-2-1) and its inverse, on [0, 1]. */
float lr_srgb_encode(float linear);
float lr_srgb_decode(float encoded);
/* The blend pass's encode (render/shaders/blend.frag), its CPU twin: the linear segment below
 * 0.0031308, else I. Taylor's fit 0.662002687 l^(1/2) + 0.684122060 l^(1/4)
 * - 0.323583601 l^(1/8) - 0.0225411470 l ("sRGB approximations for HLSL", 2012): three
 * square roots instead of pow, within 0.25 / 255 of lr_srgb_encode on [0, 1] (bounded in
 * tests/base/test_image.c), so an 8-bit code is the exact one or one step off. */
float lr_srgb_encode_fast(float linear);

/* Pixels with a NaN or an infinite channel (a writer's caller refuses to write them: a PNG
 * would show them as black or white, silently). */
size_t lr_image_count_nonfinite(const lr_image *img);

/* ---- files ---------------------------------------------------------------------------- */

/* Tone-maps, sRGB-encodes and rounds to 8-bit RGB. tm NULL: defaults. */
int lr_image_write_png(const char *path, const lr_image *img, const lr_tonemap *tm, lr_err *e);
/* Reads any PNG libpng can convert to 8-bit sRGB RGB (grey, palette, alpha, 16-bit are
 * converted; alpha is composited on black) and decodes it to linear. */
int lr_image_read_png(const char *path, lr_image *out, lr_err *e);

/* "PF" (colour), little-endian (scale -1.0), rows bottom to top; values written bit-exact,
 * NaN and Inf included (tests scan HDR output for them). */
int lr_image_write_pfm(const char *path, const lr_image *img, lr_err *e);
/* Reads "PF" and greyscale "Pf" (replicated to RGB), either byte order; the scale's magnitude
 * is ignored (it carries no agreed meaning). Rejects truncated files and trailing bytes. */
int lr_image_read_pfm(const char *path, lr_image *out, lr_err *e);

#endif
