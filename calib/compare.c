#include "calib/compare.h"

#include <lcms2.h>
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "calib/camview.h"

const char *lr_compare_region_name(int region)
{
    static const char *const names[LR_REGION_COUNT] = {"object", "receivers", "all"};
    return region >= 0 && region < LR_REGION_COUNT ? names[region] : "?";
}

/* ---- CIEDE2000 through lcms2 ---------------------------------------------------------------- */

double lr_ciede2000(const double lab1[3], const double lab2[3])
{
    cmsCIELab a = {lab1[0], lab1[1], lab1[2]}, b = {lab2[0], lab2[1], lab2[2]};
    return cmsCIE2000DeltaE(&a, &b, 1.0, 1.0, 1.0);
}

struct lr_lab_xform {
    cmsHTRANSFORM t;
};

int lr_lab_xform_create(lr_lab_xform **out, lr_err *e)
{
    *out = NULL;
    /* Linear sRGB: Rec. 709 primaries, D65 white, identity tone curves. */
    cmsCIExyY d65 = {0.3127, 0.3290, 1.0};
    cmsCIExyYTRIPLE prim = {{0.64, 0.33, 1.0}, {0.30, 0.60, 1.0}, {0.15, 0.06, 1.0}};
    cmsToneCurve *lin = cmsBuildGamma(NULL, 1.0);
    cmsToneCurve *curves[3] = {lin, lin, lin};
    cmsHPROFILE rgb = lin ? cmsCreateRGBProfile(&d65, &prim, curves) : NULL;
    cmsHPROFILE lab = cmsCreateLab4Profile(NULL); /* D50 */
    cmsHTRANSFORM t = NULL;
    if (rgb && lab)
        /* No optimisation: the unoptimised pipeline stays in floating point (an optimised
         * one may bake the matrix-shaper into 16-bit tables). */
        t = cmsCreateTransform(rgb, TYPE_RGB_DBL, lab, TYPE_Lab_DBL,
                               INTENT_RELATIVE_COLORIMETRIC, cmsFLAGS_NOOPTIMIZE | cmsFLAGS_NOCACHE);
    if (lin)
        cmsFreeToneCurve(lin);
    if (rgb)
        cmsCloseProfile(rgb);
    if (lab)
        cmsCloseProfile(lab);
    lr_lab_xform *x = t ? malloc(sizeof *x) : NULL;
    if (!x) {
        if (t)
            cmsDeleteTransform(t);
        return lr_err_set(e, LR_ENOMEM, "lcms2: cannot create the linear sRGB -> Lab transform");
    }
    x->t = t;
    *out = x;
    return LR_OK;
}

void lr_lab_xform_destroy(lr_lab_xform *x)
{
    if (!x)
        return;
    cmsDeleteTransform(x->t);
    free(x);
}

void lr_lab_xform_apply(const lr_lab_xform *x, const double *rgb, double *lab, int n)
{
    cmsDoTransform(x->t, rgb, lab, (cmsUInt32Number)n);
}

/* ---- SSIM ------------------------------------------------------------------------------------ */

/* Separable Gaussian blur, 11 taps sigma 1.5, weights renormalised where the window leaves
 * the image. */
static void blur(const float *in, float *tmp, float *out, int w, int h)
{
    double g[11];
    for (int i = 0; i < 11; i++)
        g[i] = exp(-(i - 5) * (i - 5) / (2 * 1.5 * 1.5));
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double s = 0, ws = 0;
            for (int k = -5; k <= 5; k++) {
                int xx = x + k;
                if (xx < 0 || xx >= w)
                    continue;
                s += g[k + 5] * in[(size_t)y * w + xx];
                ws += g[k + 5];
            }
            tmp[(size_t)y * w + x] = (float)(s / ws);
        }
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double s = 0, ws = 0;
            for (int k = -5; k <= 5; k++) {
                int yy = y + k;
                if (yy < 0 || yy >= h)
                    continue;
                s += g[k + 5] * tmp[(size_t)yy * w + x];
                ws += g[k + 5];
            }
            out[(size_t)y * w + x] = (float)(s / ws);
        }
}

int lr_ssim_map(const float *a, const float *b, int w, int h, float *out, lr_err *e)
{
    size_t n = (size_t)w * h;
    float *buf = malloc(n * 8 * sizeof *buf);
    if (!buf)
        return lr_err_set(e, LR_ENOMEM, "SSIM: out of memory (%dx%d)", w, h);
    float *prod = buf, *tmp = buf + n, *ma = buf + 2 * n, *mb = buf + 3 * n, *aa = buf + 4 * n,
          *bb = buf + 5 * n, *ab = buf + 6 * n;
    blur(a, tmp, ma, w, h);
    blur(b, tmp, mb, w, h);
    for (size_t i = 0; i < n; i++)
        prod[i] = a[i] * a[i];
    blur(prod, tmp, aa, w, h);
    for (size_t i = 0; i < n; i++)
        prod[i] = b[i] * b[i];
    blur(prod, tmp, bb, w, h);
    for (size_t i = 0; i < n; i++)
        prod[i] = a[i] * b[i];
    blur(prod, tmp, ab, w, h);
    const double C1 = 0.01 * 0.01, C2 = 0.03 * 0.03; /* (K1 L)^2, (K2 L)^2 with L = 1 */
    for (size_t i = 0; i < n; i++) {
        double mx = ma[i], my = mb[i];
        double vx = aa[i] - mx * mx, vy = bb[i] - my * my, cxy = ab[i] - mx * my;
        /* Wang et al. 2004, Eq. 13. */
        out[i] = (float)(((2 * mx * my + C1) * (2 * cxy + C2)) /
                         ((mx * mx + my * my + C1) * (vx + vy + C2)));
    }
    free(buf);
    return LR_OK;
}

/* ---- the comparison -------------------------------------------------------------------------- */

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

/* p-quantile (0..1) of v[0..n) (sorted in place). */
static double quantile(float *v, long n, double p)
{
    if (n <= 0)
        return 0;
    qsort(v, (size_t)n, sizeof *v, cmp_float);
    long i = (long)floor(p * (n - 1) + 0.5);
    return v[i];
}

static double luminance(const float *p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

static double clip01(double v) { return v > 0 ? (v < 1 ? v : 1) : 0; }

int lr_compare_run(const lr_compare_desc *d, lr_compare_result *out, float *demap, lr_err *e)
{
    memset(out, 0, sizeof *out);
    const lr_image *R = d->render, *C = d->capture;
    if (R->width != C->width || R->height != C->height)
        return lr_err_set(e, LR_EINVAL, "compare: render is %dx%d but the capture is %dx%d",
                          R->width, R->height, C->width, C->height);
    int w = R->width, h = R->height, edge = d->edge_px == 0 ? 1 : d->edge_px;
    size_t n = (size_t)w * h;
    /* region per pixel: -1 not compared, else OBJECT / RECEIVERS */
    signed char *reg = malloc(n);
    float *la = malloc(n * sizeof *la), *lb = malloc(n * sizeof *lb), *ss = malloc(n * sizeof *ss);
    float *de = malloc(n * sizeof *de), *sorted = malloc(n * sizeof *sorted);
    double *rgb = malloc(n * 3 * sizeof *rgb), *lab_r = malloc(n * 3 * sizeof *lab_r),
           *lab_c = malloc(n * 3 * sizeof *lab_c);
    lr_lab_xform *xf = NULL;
    int rc = LR_OK;
    if (!reg || !la || !lb || !ss || !de || !sorted || !rgb || !lab_r || !lab_c) {
        rc = lr_err_set(e, LR_ENOMEM, "compare: out of memory (%dx%d)", w, h);
        goto done;
    }
    long ncmp = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            uint8_t l = d->labels[i];
            reg[i] = -1;
            if (l != LR_LABEL_OBJECT && l != LR_LABEL_RECEIVER)
                continue;
            bool interior = true;
            for (int dy = -edge; dy <= edge && interior && edge > 0; dy++)
                for (int dx = -edge; dx <= edge && interior; dx++) {
                    int xx = x + dx, yy = y + dy;
                    if (xx < 0 || yy < 0 || xx >= w || yy >= h ||
                        d->labels[(size_t)yy * w + xx] != l)
                        interior = false;
                }
            if (!interior) {
                out->edge++;
                continue;
            }
            if (d->exclude && d->exclude[i]) {
                out->excluded++;
                continue;
            }
            float lr = (float)luminance(R->rgb + 3 * i);
            float lc = (float)luminance(C->rgb + 3 * i);
            if (!isfinite(lr) || !isfinite(lc)) {
                out->excluded++;
                continue;
            }
            reg[i] = l == LR_LABEL_OBJECT ? LR_REGION_OBJECT : LR_REGION_RECEIVERS;
            sorted[ncmp++] = lr;
        }
    if (ncmp == 0) {
        rc = lr_err_set(e, LR_EINVAL,
                        "compare: no pixel left to compare (no object or receiver in view, or "
                        "all of them saturated, in shadow or on edges)");
        goto done;
    }
    double p99 = quantile(sorted, ncmp, 0.99);
    if (!(p99 > 0)) {
        rc = lr_err_set(e, LR_EINVAL,
                        "compare: the render is black where object and receivers are seen");
        goto done;
    }
    double s = 1.0 / p99;
    out->scale = s;
    for (size_t i = 0; i < n; i++) {
        double r = luminance(R->rgb + 3 * i), c = luminance(C->rgb + 3 * i);
        la[i] = (float)clip01(isfinite(r) ? r * s : 0);
        lb[i] = (float)clip01(isfinite(c) ? c * s : 0);
    }
    if ((rc = lr_ssim_map(la, lb, w, h, ss, e)) || (rc = lr_lab_xform_create(&xf, e)))
        goto done;
    for (size_t i = 0; i < 3 * n; i++)
        rgb[i] = isfinite(R->rgb[i]) ? clip01(R->rgb[i] * s) : 0;
    lr_lab_xform_apply(xf, rgb, lab_r, (int)n);
    for (size_t i = 0; i < 3 * n; i++)
        rgb[i] = isfinite(C->rgb[i]) ? clip01(C->rgb[i] * s) : 0;
    lr_lab_xform_apply(xf, rgb, lab_c, (int)n);

    double num[LR_REGION_COUNT] = {0}, den[LR_REGION_COUNT] = {0};
    double ssim[LR_REGION_COUNT] = {0}, desum[LR_REGION_COUNT] = {0};
    for (size_t i = 0; i < n; i++) {
        de[i] = NAN;
        if (reg[i] < 0)
            continue;
        de[i] = (float)lr_ciede2000(lab_r + 3 * i, lab_c + 3 * i);
        int rs[2] = {reg[i], LR_REGION_ALL};
        for (int k = 0; k < 2; k++) {
            int g = rs[k];
            for (int c = 0; c < 3; c++) {
                double dr = R->rgb[3 * i + c], dc = C->rgb[3 * i + c];
                num[g] += (dc - dr) * (dc - dr);
                den[g] += dr * dr;
            }
            ssim[g] += ss[i];
            desum[g] += de[i];
            out->region[g].pixels++;
        }
    }
    for (int g = 0; g < LR_REGION_COUNT; g++) {
        lr_compare_stats *st = &out->region[g];
        if (st->pixels == 0) {
            st->rmse = st->rel_rmse = st->ssim = st->delta_e = st->delta_e_p95 = NAN;
            continue;
        }
        st->rmse = sqrt(num[g] / (3.0 * st->pixels));
        st->rel_rmse = den[g] > 0 ? sqrt(num[g] / den[g]) : (num[g] > 0 ? INFINITY : 0);
        st->ssim = ssim[g] / st->pixels;
        st->delta_e = desum[g] / st->pixels;
        long m = 0;
        for (size_t i = 0; i < n; i++)
            if (reg[i] >= 0 && (g == LR_REGION_ALL || reg[i] == g))
                sorted[m++] = de[i];
        st->delta_e_p95 = quantile(sorted, m, 0.95);
    }
    if (demap)
        memcpy(demap, de, n * sizeof *de);
done:
    lr_lab_xform_destroy(xf);
    free(reg);
    free(la);
    free(lb);
    free(ss);
    free(de);
    free(sorted);
    free(rgb);
    free(lab_r);
    free(lab_c);
    return rc;
}

/* ---- captures ---------------------------------------------------------------------------- */

static int check_stack(const lr_img *images, int n, lr_err *e)
{
    if (n < 1)
        return lr_err_set(e, LR_EINVAL, "compare: no capture");
    for (int k = 0; k < n; k++) {
        if (images[k].channels != 3 || (images[k].depth != 1 && images[k].depth != 2))
            return lr_err_set(e, LR_EINVAL,
                              "capture %d: expected an RGB image of 8 or 16 bits (got %d "
                              "channel(s), %d byte(s) per sample)",
                              k + 1, images[k].channels, images[k].depth);
        if (images[k].w != images[0].w || images[k].h != images[0].h)
            return lr_err_set(e, LR_EINVAL, "capture %d is %dx%d but capture 1 is %dx%d", k + 1,
                              images[k].w, images[k].h, images[0].w, images[0].h);
    }
    return LR_OK;
}

int lr_compare_capture_mask(const lr_img *images, int n, double sat, double dark,
                            uint8_t *exclude, lr_err *e)
{
    int rc = check_stack(images, n, e);
    if (rc)
        return rc;
    sat = sat > 0 ? sat : 250.0 / 255.0;
    dark = dark > 0 ? dark : 5.0 / 255.0;
    size_t np = (size_t)images[0].w * images[0].h;
    for (size_t i = 0; i < np; i++) {
        bool all_sat = true, all_dark = true;
        for (int k = 0; k < n; k++) {
            int x = (int)(i % images[k].w), y = (int)(i / images[k].w);
            double hi = 0;
            for (int c = 0; c < 3; c++)
                hi = fmax(hi, lr_img_get(&images[k], x, y, c));
            all_sat = all_sat && hi >= sat;
            all_dark = all_dark && hi <= dark;
        }
        exclude[i] = all_sat || all_dark;
    }
    return LR_OK;
}

int lr_compare_linearise(const lr_rig_calib *rig, const lr_img *images, const double *times,
                         int n, double gain, lr_image *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    int rc = check_stack(images, n, e);
    if (rc)
        return rc;
    if (!(gain > 0 && isfinite(gain)))
        return lr_err_set(e, LR_EINVAL, "compare: gain %g must be > 0", gain);
    for (int k = 0; k < n; k++)
        if (!(times[k] > 0 && isfinite(times[k])))
            return lr_err_set(e, LR_EINVAL, "capture %d: exposure time %g must be > 0", k + 1,
                              times[k]);
    lr_camresp *resp = malloc(sizeof *resp);
    if (!resp)
        return lr_err_set(e, LR_ENOMEM, "out of memory");
    lr_rig_camera_response(rig, resp);
    int w = images[0].w, h = images[0].h;
    if ((rc = lr_image_alloc(out, w, h, e))) {
        free(resp);
        return rc;
    }
    lr_img merged = {0};
    if (n > 1) {
        for (int k = 0; k < n; k++)
            if (images[k].depth != 1) {
                rc = lr_err_set(e, LR_EINVAL,
                                "capture %d: exposure stacks are merged from 8-bit captures", k + 1);
                goto done;
            }
        if ((rc = lr_camresp_merge(resp, images, times, n, &merged, e)))
            goto done;
    }
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double cam[3], lin[3];
            for (int c = 0; c < 3; c++)
                cam[c] = n > 1 ? lr_img_get(&merged, x, y, c)
                               : lr_camresp_linear(resp, c, 255.0 * lr_img_get(&images[0], x, y, c)) /
                                     times[0];
            if (rig->has_color)
                lr_colormatrix_apply(&rig->color, cam, lin);
            else
                memcpy(lin, cam, sizeof lin);
            for (int c = 0; c < 3; c++)
                out->rgb[3 * ((size_t)y * w + x) + c] = (float)(lin[c] / gain);
        }
done:
    lr_img_free(&merged);
    free(resp);
    if (rc)
        lr_image_free(out);
    return rc;
}
