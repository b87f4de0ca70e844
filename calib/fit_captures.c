#include "calib/fit_captures.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "calib/camresp.h"
#include "calib/compare.h"
#include "calib/image.h"

int lr_image_resample_box(const lr_image *src, int w, int h, lr_image *out, lr_err *e)
{
    int rc = lr_image_alloc(out, w, h, e);
    if (rc)
        return rc;
    double sx = (double)src->width / w, sy = (double)src->height / h;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            /* the output pixel's footprint [x0, x1) x [y0, y1) in source pixels */
            double x0 = x * sx, x1 = (x + 1) * sx, y0 = y * sy, y1 = (y + 1) * sy;
            double acc[3] = {0, 0, 0}, wsum = 0;
            for (int j = (int)floor(y0); j < (int)ceil(y1) && j < src->height; j++) {
                double wy = fmin(y1, j + 1) - fmax(y0, j);
                for (int i = (int)floor(x0); i < (int)ceil(x1) && i < src->width; i++) {
                    double wgt = wy * (fmin(x1, i + 1) - fmax(x0, i));
                    if (wgt <= 0)
                        continue;
                    const float *s = src->rgb + 3 * ((size_t)j * src->width + i);
                    for (int c = 0; c < 3; c++)
                        acc[c] += wgt * s[c];
                    wsum += wgt;
                }
            }
            for (int c = 0; c < 3; c++)
                out->rgb[3 * ((size_t)y * w + x) + c] = (float)(wsum > 0 ? acc[c] / wsum : 0);
        }
    return LR_OK;
}

int lr_fit_load_captures(const char *const *paths, const double *times, int n,
                         const lr_rig_calib *calib, int width, int height, double scale,
                         lr_image *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    if (n < 1)
        return lr_err_set(e, LR_EINVAL, "fit: no captures");
    if (n > 1 && !times)
        return lr_err_set(e, LR_EINVAL, "fit: %d captures need their exposure times", n);
    if (!(scale > 0 && isfinite(scale)))
        return lr_err_set(e, LR_EINVAL, "fit: capture scale %g must be > 0", scale);
    for (int i = 0; i < n && times; i++)
        if (!(times[i] > 0 && isfinite(times[i])))
            return lr_err_set(e, LR_EINVAL, "fit: exposure time %g of %s must be > 0", times[i],
                              paths[i]);
    lr_img *imgs = calloc((size_t)n, sizeof *imgs);
    if (!imgs)
        return lr_err_set(e, LR_ENOMEM, "fit: out of memory");
    lr_image lin = {0};
    int rc = LR_OK;
    for (int i = 0; i < n && !rc; i++) {
        rc = lr_img_read(paths[i], LR_IMG_RGB8, &imgs[i], e);
        if (!rc && i > 0 && (imgs[i].w != imgs[0].w || imgs[i].h != imgs[0].h))
            rc = lr_err_set(e, LR_EINVAL, "%s is %d x %d, %s is %d x %d", paths[i], imgs[i].w,
                            imgs[i].h, paths[0], imgs[0].w, imgs[0].h);
    }
    if (rc)
        goto done;
    int cw = imgs[0].w, ch = imgs[0].h;
    double a_cap = (double)cw / ch, a_fit = (double)width / height;
    if (fabs(a_cap / a_fit - 1) > 0.01) {
        rc = lr_err_set(e, LR_EINVAL,
                        "fit: captures are %d x %d (aspect %.3f) but the fit renders %d x %d "
                        "(%.3f): the scene's camera must be the rig's camera",
                        cw, ch, a_cap, width, height, a_fit);
        goto done;
    }
    if ((rc = lr_image_alloc(&lin, cw, ch, e)))
        goto done;
    if (n == 1) {
        const uint8_t *p = imgs[0].px;
        double t = times ? times[0] : 1;
        for (size_t k = 0; k < (size_t)cw * ch; k++) {
            double v[3];
            lr_rig_camera_to_linear(calib, p + 3 * k, v);
            for (int c = 0; c < 3; c++)
                lin.rgb[3 * k + c] = (float)(v[c] / t);
        }
    } else {
        lr_img hdr;
        lr_camresp *resp = malloc(sizeof *resp);
        if (!resp) {
            rc = lr_err_set(e, LR_ENOMEM, "fit: out of memory");
            goto done;
        }
        lr_rig_camera_response(calib, resp);
        rc = lr_camresp_merge(resp, imgs, times, n, &hdr, e);
        free(resp);
        if (rc)
            goto done;
        const float *p = hdr.px;
        for (size_t k = 0; k < (size_t)cw * ch; k++) {
            double v[3] = {p[3 * k], p[3 * k + 1], p[3 * k + 2]}, o[3];
            if (calib->has_color)
                lr_colormatrix_apply(&calib->color, v, o);
            else
                memcpy(o, v, sizeof o);
            for (int c = 0; c < 3; c++)
                lin.rgb[3 * k + c] = (float)o[c];
        }
        lr_img_free(&hdr);
    }
    /* A clipped value bounds the radiance from below only (and 0 from above): the pixels
     * saturated (some channel >= 250) or black in every capture are NaN here, the box filter
     * carries NaN into every fit pixel they touch, and lr_fit_run leaves those out, as
     * compare leaves them out of its metrics (lr_compare_capture_mask, same threshold). */
    uint8_t *clipped = malloc((size_t)cw * ch);
    if (!clipped) {
        rc = lr_err_set(e, LR_ENOMEM, "fit: out of memory");
        goto done;
    }
    if (!(rc = lr_compare_capture_mask(imgs, n, 0, 0.5 / 255.0, clipped, e)))
        for (size_t k = 0; k < (size_t)cw * ch; k++)
            if (clipped[k])
                lin.rgb[3 * k] = lin.rgb[3 * k + 1] = lin.rgb[3 * k + 2] = NAN;
    free(clipped);
    if (rc || (rc = lr_image_resample_box(&lin, width, height, out, e)))
        goto done;
    for (size_t k = 0; k < (size_t)width * height * 3; k++)
        out->rgb[k] = (float)(out->rgb[k] / scale);
done:
    for (int i = 0; i < n; i++)
        lr_img_free(&imgs[i]);
    free(imgs);
    lr_image_free(&lin);
    return rc;
}
