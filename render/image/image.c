/* lamprig — image buffers and tone mapping. */
#include "render/image/image.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

int lr_image_alloc(lr_image *img, int width, int height, lr_err *e)
{
    img->width = img->height = 0;
    img->rgb = NULL;
    if (width < 1 || height < 1 || width > LR_IMAGE_MAX_SIDE || height > LR_IMAGE_MAX_SIDE)
        return lr_err_set(e, LR_EINVAL, "image size %dx%d outside 1..%d", width, height,
                          LR_IMAGE_MAX_SIDE);
    img->rgb = calloc((size_t)width * (size_t)height * 3, sizeof *img->rgb);
    if (!img->rgb)
        return lr_err_set(e, LR_ENOMEM, "image %dx%d", width, height);
    img->width = width;
    img->height = height;
    return LR_OK;
}

void lr_image_free(lr_image *img)
{
    if (!img)
        return;
    free(img->rgb);
    img->rgb = NULL;
    img->width = img->height = 0;
}

int lr_image_from_gl_rgba(lr_image *img, const float *rgba, int width, int height, lr_err *e)
{
    int rc = lr_image_alloc(img, width, height, e);
    if (rc)
        return rc;
    for (int y = 0; y < height; y++) {
        const float *src = rgba + (size_t)(height - 1 - y) * (size_t)width * 4;
        float *dst = img->rgb + (size_t)y * (size_t)width * 3;
        for (int x = 0; x < width; x++)
            memcpy(dst + 3 * x, src + 4 * x, 3 * sizeof *dst);
    }
    return LR_OK;
}

float lr_tonemap_apply(const lr_tonemap *tm, float v)
{
    float exposure = tm && tm->exposure != 0.0f ? tm->exposure : 1.0f;
    lr_tonemap_op op = tm ? tm->op : LR_TONEMAP_CLAMP;
    v *= exposure;
    if (!(v > 0.0f)) /* also NaN */
        return 0.0f;
    switch (op) {
    case LR_TONEMAP_REINHARD:
        v = isinf(v) ? 1.0f : v / (1.0f + v);
        break;
    case LR_TONEMAP_ACES:
        /* K. Narkowicz, "ACES Filmic Tone Mapping Curve" (2015). */
        v = isinf(v) ? 1.0f : (v * (2.51f * v + 0.03f)) / (v * (2.43f * v + 0.59f) + 0.14f);
        break;
    case LR_TONEMAP_CLAMP:
    default:
        break;
    }
    return v < 1.0f ? v : 1.0f;
}

/* IEC 61966-2-1. */
float lr_srgb_encode(float l)
{
    if (!(l > 0.0f))
        return 0.0f;
    if (l >= 1.0f)
        return 1.0f;
    return l <= 0.0031308f ? 12.92f * l : 1.055f * powf(l, 1.0f / 2.4f) - 0.055f;
}

float lr_srgb_encode_fast(float l)
{
    if (!(l > 0.0f))
        return 0.0f;
    if (l > 1.0f)
        l = 1.0f;
    if (l <= 0.0031308f)
        return 12.92f * l;
    float s1 = sqrtf(l), s2 = sqrtf(s1), s3 = sqrtf(s2);
    float v = 0.662002687f * s1 + 0.684122060f * s2 - 0.323583601f * s3 - 0.0225411470f * l;
    return v < 1.0f ? v : 1.0f;
}

float lr_srgb_decode(float s)
{
    if (!(s > 0.0f))
        return 0.0f;
    if (s >= 1.0f)
        return 1.0f;
    return s <= 0.04045f ? s / 12.92f : powf((s + 0.055f) / 1.055f, 2.4f);
}
