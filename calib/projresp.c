#include "calib/projresp.h"

#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "calib/calfile.h"
#include "calib/isotonic.h"

static const char channel_names[3] = {'r', 'g', 'b'};

/* Power law through (va, ya) with exponent p, evaluated at v. */
static double power_segment(double v, double va, double ya, double p)
{
    return ya * pow(v / va, p);
}

static double segment_exponent(double va, double ya, double vb, double yb)
{
    if (!(va > 0 && ya > 0 && yb > ya))
        return NAN;
    return log(yb / ya) / log(vb / va);
}

static void build_lut(const double *lv, const double *y, int n, double *lut)
{
    int k = 0;
    for (int i = 0; i < 256; i++) {
        double v = i / 255.0;
        while (k + 2 < n && v > lv[k + 1])
            k++;
        double va = lv[k], vb = lv[k + 1], ya = y[k], yb = y[k + 1], out;
        double p = segment_exponent(va, ya, vb, yb);
        if (va == 0 && n > 2) {
            /* First segment starts at 0 where a power law has no anchor: continue the next
             * segment's exponent down to 0 (through (vb, yb)). */
            double p1 = segment_exponent(lv[1], y[1], lv[2], y[2]);
            out = isfinite(p1) && p1 > 0 && yb > 0 ? power_segment(v > 0 ? v : 1e-300, vb, yb, p1)
                                                   : ya + (yb - ya) * (v - va) / (vb - va);
            if (v == 0)
                out = 0;
        } else if (isfinite(p) && p > 0) {
            out = power_segment(v, va, ya, p);
        } else {
            out = ya + (yb - ya) * (v - va) / (vb - va);
        }
        lut[i] = out < 0 ? 0 : out > 1 ? 1 : out;
    }
    lut[0] = 0;
    lut[255] = 1;
    /* The first segment's extrapolated exponent can overshoot the next measured point;
     * keep the table monotone. */
    for (int i = 1; i < 256; i++)
        if (lut[i] < lut[i - 1])
            lut[i] = lut[i - 1];
}

int lr_projresp_fit(const double *levels, const double *light, int n, lr_projresp *out,
                    lr_err *e)
{
    memset(out, 0, sizeof *out);
    if (n < 3 || n > LR_PROJRESP_MAX_LEVELS)
        return lr_err_set(e, LR_EINVAL, "projector response: %d levels (need 3..%d)", n,
                          LR_PROJRESP_MAX_LEVELS);
    if (levels[0] != 0 || levels[n - 1] != 1)
        return lr_err_set(e, LR_EINVAL,
                          "projector response: levels must start at 0 (black) and end at 1 "
                          "(full), got %g .. %g",
                          levels[0], levels[n - 1]);
    for (int k = 1; k < n; k++)
        if (!(levels[k] > levels[k - 1]))
            return lr_err_set(e, LR_EINVAL, "projector response: levels not increasing at %d",
                              k);
    out->nlevels = n;
    memcpy(out->levels, levels, sizeof *levels * (size_t)n);
    for (int c = 0; c < 3; c++) {
        double l0 = light[c], l1 = light[(n - 1) * 3 + c];
        for (int k = 0; k < n; k++)
            if (!isfinite(light[k * 3 + c]))
                return lr_err_set(e, LR_EINVAL, "projector response: channel %c level %g: "
                                  "measurement not finite", channel_names[c], levels[k]);
        if (!(l1 - l0 > 1e-9 * fabs(l1)) || !(l1 > 0))
            return lr_err_set(e, LR_EINVAL,
                              "projector response: channel %c gives no more light at full level "
                              "(%g) than at black (%g): is the projector on and in view?",
                              channel_names[c], l1, l0);
        out->black[c] = l0 > 0 ? l0 / l1 : 0;
        double y[LR_PROJRESP_MAX_LEVELS];
        for (int k = 0; k < n; k++)
            y[k] = out->measured[c][k] = (light[k * 3 + c] - l0) / (l1 - l0);
        int rc = lr_isotonic(y, NULL, n, e);
        if (rc)
            return rc;
        for (int k = 0; k < n; k++)
            y[k] = y[k] < 0 ? 0 : y[k] > 1 ? 1 : y[k];
        y[0] = 0;
        y[n - 1] = 1;
        build_lut(levels, y, n, out->lut[c]);
        /* ln y = gamma ln v through the origin, on the well-measured middle of the curve. */
        double sxy = 0, sxx = 0;
        for (int k = 1; k < n - 1; k++)
            if (y[k] > 0.02 && y[k] < 0.98) {
                double lx = log(levels[k]), ly = log(y[k]);
                sxy += lx * ly;
                sxx += lx * lx;
            }
        out->gamma[c] = sxx > 0 ? sxy / sxx : 0;
    }
    return LR_OK;
}

double lr_projresp_eval(const lr_projresp *r, int c, double v)
{
    if (!(v > 0))
        return r->lut[c][0];
    if (v >= 1)
        return r->lut[c][255];
    double x = v * 255;
    int i = (int)x;
    double f = x - i;
    return r->lut[c][i] * (1 - f) + r->lut[c][i + 1] * f;
}

double lr_projresp_inverse(const lr_projresp *r, int c, double y)
{
    const double *t = r->lut[c];
    if (!(y > t[0]))
        return 0;
    if (y >= t[255])
        return 1;
    int lo = 0, hi = 255; /* t[lo] < y <= t[hi] */
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (t[mid] >= y)
            hi = mid;
        else
            lo = mid;
    }
    return (lo + (y - t[lo]) / (t[hi] - t[lo])) / 255.0;
}

/* ---- flat frames ---------------------------------------------------------------------- */

int lr_projresp_levels(int steps, int *levels, int *n, lr_err *e)
{
    if (steps == 0)
        steps = 17;
    if (steps < 3 || steps > 256)
        return lr_err_set(e, LR_EINVAL, "projector response: %d steps (3..256)", steps);
    for (int k = 0; k < steps; k++) {
        double l = 256 % (steps - 1) == 0 ? k * (256.0 / (steps - 1)) : k * (255.0 / (steps - 1));
        long v = lround(l);
        levels[k] = v > 255 ? 255 : (int)v;
        if (k > 0 && levels[k] <= levels[k - 1])
            return lr_err_set(e, LR_EINVAL, "projector response: %d steps repeat a level", steps);
    }
    *n = steps;
    return LR_OK;
}

int lr_projresp_run_sequence_steps(int pw, int ph, int steps, lr_gc_show_fn show, void *ctx,
                                   lr_err *e)
{
    int levels[256], n;
    int rc = lr_projresp_levels(steps, levels, &n, e);
    if (rc)
        return rc;
    lr_img frame;
    if ((rc = lr_img_alloc(&frame, pw, ph, 3, 1, e)))
        return rc;
    uint8_t *p = frame.px;
    size_t np = (size_t)pw * (size_t)ph;
    int index = 0;
    for (int c = 0; c < 3 && !rc; c++)
        for (int k = 0; k < n && !rc; k++) {
            memset(p, 0, np * 3);
            for (size_t i = 0; i < np; i++)
                p[3 * i + (size_t)c] = (uint8_t)levels[k];
            char name[32];
            snprintf(name, sizeof name, "%c_%03d.png", channel_names[c], levels[k]);
            rc = show(ctx, index++, &frame, name, e);
        }
    lr_img_free(&frame);
    return rc;
}

int lr_projresp_run_sequence(int pw, int ph, lr_gc_show_fn show, void *ctx, lr_err *e)
{
    return lr_projresp_run_sequence_steps(pw, ph, 0, show, ctx, e);
}

static int write_flat(void *ctx, int index, const lr_img *frame, const char *name, lr_err *e)
{
    (void)index;
    char path[4096];
    if (snprintf(path, sizeof path, "%s/%s", (const char *)ctx, name) >= (int)sizeof path)
        return lr_err_set(e, LR_EINVAL, "%s: path too long", (const char *)ctx);
    return lr_img_write_frame(path, frame, e);
}

int lr_projresp_write_patterns(const char *dir, int pw, int ph, int steps, lr_err *e)
{
    if (mkdir(dir, 0755) != 0 && errno != EEXIST)
        return lr_err_set(e, LR_EIO, "%s: cannot create: %s", dir, strerror(errno));
    return lr_projresp_run_sequence_steps(pw, ph, steps, write_flat, (void *)dir, e);
}

/* ---- measuring a folder --------------------------------------------------------------- */

/* Levels present for channel c (file c_LLL.png), sorted. */
static int scan_levels(const char *dir, int c, int *levels, int *n, lr_err *e)
{
    DIR *d = opendir(dir);
    if (!d)
        return lr_err_set(e, LR_EIO, "%s: cannot open folder", dir);
    bool have[256] = {false};
    struct dirent *ent;
    while ((ent = readdir(d))) {
        int lv, used = 0;
        char ch;
        if (sscanf(ent->d_name, "%c_%3d.png%n", &ch, &lv, &used) == 2 && used > 0 &&
            ent->d_name[used] == '\0' && ch == channel_names[c] && lv >= 0 && lv <= 255 &&
            strlen(ent->d_name) == 9)
            have[lv] = true;
    }
    closedir(d);
    *n = 0;
    for (int v = 0; v < 256; v++)
        if (have[v])
            levels[(*n)++] = v;
    if (*n < 3 || !have[0] || !have[255])
        return lr_err_set(e, LR_EINVAL,
                          "%s: channel %c needs captures %c_000.png, %c_255.png and at least one "
                          "level between (found %d)",
                          dir, channel_names[c], channel_names[c], channel_names[c], *n);
    return LR_OK;
}

static int read_flat(const char *dir, int c, int level, int w, int h, lr_img *img, lr_err *e)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%c_%03d.png", dir, channel_names[c], level);
    int rc = lr_img_read(path, LR_IMG_RGB8, img, e);
    if (rc)
        return rc;
    if (w && (img->w != w || img->h != h)) {
        lr_img_free(img);
        return lr_err_set(e, LR_EINVAL, "%s: %dx%d, other captures are %dx%d", path, img->w,
                          img->h, w, h);
    }
    return LR_OK;
}

int lr_projresp_measure(const char *dir, const lr_camresp *cam, lr_projresp *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    int levels[3][256], n[3];
    int rc;
    for (int c = 0; c < 3; c++)
        if ((rc = scan_levels(dir, c, levels[c], &n[c], e)))
            return rc;
    for (int c = 1; c < 3; c++)
        if (n[c] != n[0] || memcmp(levels[c], levels[0], sizeof(int) * (size_t)n[0]) != 0)
            return lr_err_set(e, LR_EINVAL, "%s: the r, g and b sweeps have different levels",
                              dir);
    lr_camresp linear;
    if (!cam) {
        lr_camresp_gamma(&linear, 1.0);
        cam = &linear;
    }
    /* Lit mask: every sweep's full level is brighter than its black by > 8 DN per channel
     * on average, and not clipped in any channel. */
    lr_img black, full;
    int w = 0, h = 0;
    unsigned char *mask = NULL;
    for (int c = 0; c < 3; c++) {
        if ((rc = read_flat(dir, c, 0, w, h, &black, e)))
            goto out;
        if ((rc = read_flat(dir, c, 255, black.w, black.h, &full, e))) {
            lr_img_free(&black);
            goto out;
        }
        if (!mask) {
            w = black.w;
            h = black.h;
            mask = malloc((size_t)w * (size_t)h);
            if (!mask) {
                lr_img_free(&black);
                lr_img_free(&full);
                rc = lr_err_set(e, LR_ENOMEM, "out of memory");
                goto out;
            }
            memset(mask, 1, (size_t)w * (size_t)h);
        }
        const uint8_t *b = black.px, *f = full.px;
        for (size_t i = 0; i < (size_t)w * (size_t)h; i++) {
            int diff = 0;
            bool clipped = false;
            for (int j = 0; j < 3; j++) {
                diff += f[3 * i + (size_t)j] - b[3 * i + (size_t)j];
                clipped |= f[3 * i + (size_t)j] == 255;
            }
            if (diff <= 24 || clipped)
                mask[i] = 0;
        }
        lr_img_free(&black);
        lr_img_free(&full);
    }
    long lit = 0;
    for (size_t i = 0; i < (size_t)w * (size_t)h; i++)
        lit += mask[i];
    if (lit < 100) {
        rc = lr_err_set(e, LR_EINVAL,
                        "%s: only %ld camera pixels are lit and unclipped in every sweep (need "
                        "100): is the projector in view, the exposure low enough?",
                        dir, lit);
        goto out;
    }
    double lv[256], light[256 * 3];
    for (int k = 0; k < n[0]; k++)
        lv[k] = levels[0][k] / 255.0;
    for (int c = 0; c < 3; c++)
        for (int k = 0; k < n[0]; k++) {
            lr_img img;
            if ((rc = read_flat(dir, c, levels[c][k], w, h, &img, e)))
                goto out;
            /* The sum over camera channels: the shape of a projector primary's response does
             * not depend on which camera channel sees it, and the sum has the best SNR. */
            const uint8_t *p = img.px;
            double acc = 0;
            for (size_t i = 0; i < (size_t)w * (size_t)h; i++)
                if (mask[i])
                    for (int j = 0; j < 3; j++)
                        acc += cam->curve[j][p[3 * i + (size_t)j]];
            light[k * 3 + c] = acc / (double)lit;
            lr_img_free(&img);
        }
    rc = lr_projresp_fit(lv, light, n[0], out, e);
    if (rc)
        lr_err_prefix(e, "%s", dir);
out:
    free(mask);
    return rc;
}

/* ---- file ----------------------------------------------------------------------------- */

static void fill(lr_jw *w, const void *obj)
{
    const lr_projresp *r = obj;
    lr_jw_array(w, "lut");
    for (int c = 0; c < 3; c++)
        lr_jw_numbers(w, NULL, r->lut[c], 256);
    lr_jw_array_end(w);
    lr_jw_numbers(w, "black", r->black, 3);
    lr_jw_numbers(w, "gamma", r->gamma, 3);
    lr_jw_numbers(w, "levels", r->levels, r->nlevels);
    lr_jw_array(w, "measured");
    for (int c = 0; c < 3; c++)
        lr_jw_numbers(w, NULL, r->measured[c], r->nlevels);
    lr_jw_array_end(w);
}

static int from_json(const lr_json *j, lr_jnode root, lr_projresp *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    static const char *const keys[] = {"version", "kind", "lut", "black", "gamma", "levels",
                                       "measured", NULL};
    int rc = lr_json_check_keys(j, root, "projector response", keys, e);
    if (rc)
        return rc;
    double m[3 * 256];
    if ((rc = lr_calfile_matrix(j, root, NULL, "lut", 3, 256, 0, 1, m, e)))
        return rc;
    lr_jnode lut = lr_json_get(j, root, "lut");
    for (int c = 0; c < 3; c++) {
        for (int i = 0; i < 256; i++) {
            out->lut[c][i] = m[c * 256 + i];
            if (i > 0 && m[c * 256 + i] < m[c * 256 + i - 1])
                return lr_json_fail(j, lut, "lut", e, LR_EINVAL,
                                    "channel %d decreases at level %d: a response must be "
                                    "non-decreasing",
                                    c, i);
        }
        if (out->lut[c][0] != 0 || out->lut[c][255] != 1)
            return lr_json_fail(j, lut, "lut", e, LR_EINVAL,
                                "channel %d must run from 0 (level 0) to 1 (level 255), got %g .. "
                                "%g",
                                c, out->lut[c][0], out->lut[c][255]);
    }
    if ((rc = lr_calfile_numbers(j, root, NULL, "black", 3, 0, 1, out->black, e)) ||
        (rc = lr_calfile_numbers(j, root, NULL, "gamma", 3, 0, 20, out->gamma, e)))
        return rc;
    lr_jnode lv;
    int n = 0;
    if ((rc = lr_calfile_array(j, root, NULL, "levels", &lv, &n, e)))
        return rc;
    if (n < 3 || n > LR_PROJRESP_MAX_LEVELS)
        return lr_json_fail(j, lv, "levels", e, LR_EINVAL, "%d levels (3..%d)", n,
                            LR_PROJRESP_MAX_LEVELS);
    if ((rc = lr_calfile_numbers(j, root, NULL, "levels", n, 0, 1, out->levels, e)))
        return rc;
    for (int k = 1; k < n; k++)
        if (!(out->levels[k] > out->levels[k - 1]))
            return lr_json_fail(j, lv, "levels", e, LR_EINVAL, "not increasing at %d", k);
    out->nlevels = n;
    double meas[3 * LR_PROJRESP_MAX_LEVELS];
    if ((rc = lr_calfile_matrix(j, root, NULL, "measured", 3, n, -10, 10, meas, e)))
        return rc;
    for (int c = 0; c < 3; c++)
        memcpy(out->measured[c], meas + c * n, sizeof(double) * (size_t)n);
    return LR_OK;
}

static int check(const lr_json *j, lr_jnode root, lr_err *e)
{
    lr_projresp *tmp = malloc(sizeof *tmp);
    if (!tmp)
        return lr_err_set(e, LR_ENOMEM, "out of memory");
    int rc = from_json(j, root, tmp, e);
    free(tmp);
    return rc;
}

int lr_projresp_save(const char *path, const lr_projresp *r, lr_err *e)
{
    return lr_calfile_save(path, LR_PROJRESP_KIND, fill, r, check, e);
}

int lr_projresp_load(const char *path, lr_projresp *out, lr_err *e)
{
    lr_json *j;
    lr_jnode root;
    int rc = lr_calfile_load(path, LR_PROJRESP_KIND, &j, &root, e);
    if (rc)
        return rc;
    rc = from_json(j, root, out, e);
    lr_json_destroy(j);
    return rc;
}
