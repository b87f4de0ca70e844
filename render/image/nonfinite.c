/* lamprig — non-finite pixels of an image (see image.h). */
#include <math.h>

#include "render/image/image.h"

size_t lr_image_count_nonfinite(const lr_image *img)
{
    size_t n = 0, np = (size_t)img->width * (size_t)img->height;
    for (size_t i = 0; i < np; i++) {
        const float *p = img->rgb + 3 * i;
        n += !isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]);
    }
    return n;
}
