/* lamprig — box-filter downsampling (image.h): the model's image filtered like the physical
 * reference's pixels. */
#include "render/image/image.h"

int lr_image_downsample_box(const lr_image *src, int factor, lr_image *out, lr_err *e)
{
    *out = (lr_image){0};
    if (!src || !src->rgb || factor < 1 || src->width < factor || src->height < factor ||
        src->width % factor || src->height % factor)
        return lr_err_set(e, LR_EINVAL, "downsample: %dx%d is not a multiple of the factor %d",
                          src ? src->width : 0, src ? src->height : 0, factor);
    const int w = src->width / factor, h = src->height / factor;
    int rc = lr_image_alloc(out, w, h, e);
    if (rc)
        return rc;
    /* Sums in double in a fixed order: the mean of factor^2 floats, rounded once. */
    const double inv = 1.0 / ((double)factor * factor);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double acc[3] = {0.0, 0.0, 0.0};
            for (int j = 0; j < factor; j++) {
                const float *row = src->rgb + ((size_t)(y * factor + j) * (size_t)src->width +
                                               (size_t)x * (size_t)factor) * 3;
                for (int i = 0; i < factor; i++)
                    for (int c = 0; c < 3; c++)
                        acc[c] += row[3 * i + c];
            }
            float *d = out->rgb + ((size_t)y * (size_t)w + (size_t)x) * 3;
            for (int c = 0; c < 3; c++)
                d[c] = (float)(acc[c] * inv);
        }
    return LR_OK;
}
