#include "calib/capture_sim.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/rng.h"

static double gamma_of(const lr_sensor *s)
{
    return s->gamma > 0 ? s->gamma : LR_CAMRESP_DEFAULT_GAMMA;
}
static double gain_of(const lr_sensor *s) { return s->gain > 0 ? s->gain : 1.0; }
static double time_of(const lr_sensor *s) { return s->exposure_s > 0 ? s->exposure_s : 1.0; }

/* Cofactor inverse; returns the determinant (0: singular, inv untouched). */
static double inverse3(const double m[9], double inv[9])
{
    double c00 = m[4] * m[8] - m[5] * m[7], c01 = m[5] * m[6] - m[3] * m[8],
           c02 = m[3] * m[7] - m[4] * m[6];
    double det = m[0] * c00 + m[1] * c01 + m[2] * c02;
    if (!(fabs(det) > 1e-12))
        return 0;
    double r = 1.0 / det;
    inv[0] = c00 * r;
    inv[1] = (m[2] * m[7] - m[1] * m[8]) * r;
    inv[2] = (m[1] * m[5] - m[2] * m[4]) * r;
    inv[3] = c01 * r;
    inv[4] = (m[0] * m[8] - m[2] * m[6]) * r;
    inv[5] = (m[2] * m[3] - m[0] * m[5]) * r;
    inv[6] = c02 * r;
    inv[7] = (m[1] * m[6] - m[0] * m[7]) * r;
    inv[8] = (m[0] * m[4] - m[1] * m[3]) * r;
    return det;
}

int lr_sensor_check(const lr_sensor *s, lr_err *e)
{
    if (!(s->exposure_s >= 0 && isfinite(s->exposure_s)))
        return lr_err_set(e, LR_EINVAL, "sensor.exposure_s: %g is not a time >= 0", s->exposure_s);
    if (!(s->gain >= 0 && isfinite(s->gain)))
        return lr_err_set(e, LR_EINVAL, "sensor.gain: %g is not a number >= 0", s->gain);
    if (!(s->gamma >= 0 && s->gamma <= 10))
        return lr_err_set(e, LR_EINVAL, "sensor.gamma: %g is outside [0, 10]", s->gamma);
    if (!(s->full_well_e >= 0 && isfinite(s->full_well_e)))
        return lr_err_set(e, LR_EINVAL, "sensor.full_well_e: %g is not a count >= 0",
                          s->full_well_e);
    if (!(s->read_noise_e >= 0 && isfinite(s->read_noise_e)))
        return lr_err_set(e, LR_EINVAL, "sensor.read_noise_e: %g is not a number >= 0",
                          s->read_noise_e);
    if (s->read_noise_e > 0 && s->full_well_e <= 0)
        return lr_err_set(e, LR_EINVAL,
                          "sensor.read_noise_e: read noise is in electrons and needs "
                          "sensor.full_well_e > 0");
    if (s->bits != 0 && s->bits != 8 && s->bits != 16)
        return lr_err_set(e, LR_EINVAL, "sensor.bits: %d (expected 8 or 16)", s->bits);
    if (!isfinite(s->cx) || !isfinite(s->cy))
        return lr_err_set(e, LR_EINVAL, "sensor.cx/cy: not finite");
    switch (s->vignette) {
    case LR_VIGNETTE_NONE:
        break;
    case LR_VIGNETTE_COS4:
        if (!(s->focal_px > 0 && isfinite(s->focal_px)))
            return lr_err_set(e, LR_EINVAL,
                              "sensor.focal_px: cos^4 vignetting needs a focal length > 0 "
                              "(pixels), got %g",
                              s->focal_px);
        break;
    case LR_VIGNETTE_POLY:
        for (int i = 0; i < 3; i++)
            if (!isfinite(s->vignette_poly[i]) || fabs(s->vignette_poly[i]) > 100)
                return lr_err_set(e, LR_EINVAL, "sensor.vignette_poly[%d]: %g is outside +-100",
                                  i, s->vignette_poly[i]);
        break;
    default:
        return lr_err_set(e, LR_EINVAL, "sensor.vignette: unknown model %d", (int)s->vignette);
    }
    if (s->color) {
        double inv[9];
        for (int i = 0; i < 9; i++)
            if (!isfinite(s->color->m[i]))
                return lr_err_set(e, LR_EINVAL, "sensor.color: matrix entry %d not finite", i);
        if (inverse3(s->color->m, inv) == 0)
            return lr_err_set(e, LR_EINVAL, "sensor.color: colour matrix is singular");
    }
    return LR_OK;
}

double lr_sensor_saturation(const lr_sensor *s, int c)
{
    if (s->response)
        return s->response->curve[c][255];
    return pow(255.0 / 128.0, gamma_of(s));
}

double lr_sensor_vignette(const lr_sensor *s, int w, int h, double x, double y)
{
    if (s->vignette == LR_VIGNETTE_NONE)
        return 1.0;
    bool centre = s->cx == 0 && s->cy == 0;
    double cx = centre ? (w - 1) * 0.5 : s->cx, cy = centre ? (h - 1) * 0.5 : s->cy;
    double dx = x - cx, dy = y - cy, r2 = dx * dx + dy * dy;
    if (s->vignette == LR_VIGNETTE_COS4) {
        /* cos(theta) = f / sqrt(f^2 + r^2) for the ray to pixel (x, y). */
        double c2 = s->focal_px * s->focal_px / (s->focal_px * s->focal_px + r2);
        return c2 * c2;
    }
    double hd2 = 0.25 * ((double)w * w + (double)h * h), p = r2 / hd2;
    double v = 1 + p * (s->vignette_poly[0] + p * (s->vignette_poly[1] + p * s->vignette_poly[2]));
    return v > 0 ? v : 0;
}

int lr_sensor_exposure(const lr_sensor *s, const lr_image *radiance, double *out, lr_err *e)
{
    int rc = lr_sensor_check(s, e);
    if (rc)
        return rc;
    double minv[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    if (s->color)
        inverse3(s->color->m, minv);
    double k = gain_of(s) * time_of(s);
    int w = radiance->width, h = radiance->height;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const float *L = radiance->rgb + 3 * ((size_t)y * w + x);
            double v = k * lr_sensor_vignette(s, w, h, x, y);
            double *o = out + 3 * ((size_t)y * w + x);
            for (int c = 0; c < 3; c++) {
                double l[3];
                for (int i = 0; i < 3; i++)
                    l[i] = isfinite(L[i]) ? L[i] : 0.0; /* NaN/Inf renders read as black */
                double raw = minv[3 * c] * l[0] + minv[3 * c + 1] * l[1] + minv[3 * c + 2] * l[2];
                o[c] = v * raw;
            }
        }
    return LR_OK;
}

double lr_sensor_encode(const lr_sensor *s, int c, double X)
{
    if (!s->response) {
        double g = gamma_of(s), ref = pow(128.0 / 255.0, g);
        return X > 0 ? 255.0 * pow(X * ref, 1.0 / g) : 0.0;
    }
    const double *cv = s->response->curve[c];
    if (X <= cv[0])
        return 0.0;
    if (X >= cv[255])
        return 255.0 * X / cv[255]; /* beyond saturation: clipped by the caller */
    /* The curve is non-decreasing (checked on load): binary search for the segment. */
    int lo = 0, hi = 255;
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (cv[mid] <= X)
            lo = mid;
        else
            hi = mid;
    }
    double span = cv[hi] - cv[lo];
    return lo + (span > 0 ? (X - cv[lo]) / span : 0.0);
}

int lr_sensor_parse_vignette(const char *text, lr_sensor *s, lr_err *e)
{
    int n = 0;
    double v[3];
    if (!strcmp(text, "none")) {
        s->vignette = LR_VIGNETTE_NONE;
    } else if (!strcmp(text, "cos4")) {
        s->vignette = LR_VIGNETTE_COS4;
    } else if (sscanf(text, "poly:%lf,%lf,%lf%n", &v[0], &v[1], &v[2], &n) == 3 && !text[n] &&
               isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2])) {
        s->vignette = LR_VIGNETTE_POLY;
        memcpy(s->vignette_poly, v, sizeof v);
    } else {
        return lr_err_set(e, LR_EINVAL,
                          "'%s': expected none, cos4 or poly:V1,V2,V3", text);
    }
    return LR_OK;
}

static double gauss(lr_rng *r)
{
    /* Box-Muller; 1 - u keeps the log finite. */
    double u1 = 1.0 - lr_rng_next(r), u2 = lr_rng_next(r);
    return sqrt(-2.0 * log(u1)) * cos(2.0 * M_PI * u2);
}

/* Photo-electron count for mean lambda: Knuth's product method below 64 (exact Poisson,
 * where its skew matters), the normal approximation N(lambda, lambda) above. */
static double poisson(lr_rng *r, double lambda)
{
    if (lambda <= 0)
        return 0;
    if (lambda >= 64)
        return lambda + sqrt(lambda) * gauss(r);
    double limit = exp(-lambda), p = 1.0;
    int k = -1;
    do {
        k++;
        p *= lr_rng_next(r);
    } while (p > limit);
    return k;
}

int lr_sensor_capture(const lr_sensor *s, const lr_image *radiance, lr_img *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    int w = radiance->width, h = radiance->height;
    size_t n = (size_t)w * h;
    double *X = malloc(n * 3 * sizeof *X);
    if (!X)
        return lr_err_set(e, LR_ENOMEM, "capture simulator: out of memory (%dx%d)", w, h);
    int rc = lr_sensor_exposure(s, radiance, X, e);
    int bits = s->bits ? s->bits : 8;
    if (!rc)
        rc = lr_img_alloc(out, w, h, 3, bits / 8, e);
    if (rc) {
        free(X);
        return rc;
    }
    double sat[3];
    for (int c = 0; c < 3; c++)
        sat[c] = lr_sensor_saturation(s, c);
    uint64_t seed = s->seed;
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            double x = X[3 * i + c];
            if (s->full_well_e > 0) {
                lr_rng r = lr_rng_init(lr_rng_key(seed, i, (uint64_t)c, 0x43415053u));
                double el = poisson(&r, x > 0 ? x / sat[c] * s->full_well_e : 0.0);
                if (s->read_noise_e > 0)
                    el += s->read_noise_e * gauss(&r);
                x = el / s->full_well_e * sat[c];
            }
            double z = lr_sensor_encode(s, c, x);
            z = z < 0 ? 0 : z > 255 ? 255 : z;
            if (bits == 8)
                ((uint8_t *)out->px)[3 * i + c] = (uint8_t)lround(z);
            else
                ((uint16_t *)out->px)[3 * i + c] = (uint16_t)lround(z * (65535.0 / 255.0));
        }
    free(X);
    return LR_OK;
}
