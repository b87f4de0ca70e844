#include "calib/albedo.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calib/calfile.h"

void lr_albedo_free(lr_albedo *a)
{
    if (!a)
        return;
    lr_image_free(&a->response);
    memset(a, 0, sizeof *a);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int lr_albedo_measure(const lr_image *white, const lr_image *black, const lr_gc_map *map,
                      int fill_passes, lr_albedo *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    int cw = lr_gc_map_width(map), ch = lr_gc_map_height(map), pw, ph;
    lr_gc_map_projector_size(map, &pw, &ph);
    if (white->width != cw || white->height != ch || black->width != cw ||
        black->height != ch)
        return lr_err_set(e, LR_EINVAL,
                          "albedo: white %d x %d and black %d x %d captures must match the "
                          "decoded camera size %d x %d",
                          white->width, white->height, black->width, black->height, cw, ch);
    if (fill_passes < 0)
        fill_passes = 2;
    size_t np = (size_t)pw * ph;
    double *sum = calloc(np * 3, sizeof *sum);
    int *cnt = calloc(np, sizeof *cnt);
    double *vals = NULL;
    int rc = LR_OK;
    if (!sum || !cnt) {
        rc = lr_err_set(e, LR_ENOMEM, "albedo: %d x %d projector", pw, ph);
        goto done;
    }
    for (int y = 0; y < ch; y++)
        for (int x = 0; x < cw; x++) {
            int px, py;
            if (lr_gc_map_get(map, x, y, &px, &py) != LR_GC_VALID)
                continue;
            if (px < 0 || py < 0 || px >= pw || py >= ph)
                continue;
            size_t c = (size_t)y * cw + x, p = (size_t)py * pw + px;
            for (int k = 0; k < 3; k++)
                sum[3 * p + k] += fmax(0.0, white->rgb[3 * c + k] - black->rgb[3 * c + k]);
            cnt[p]++;
        }
    long measured = 0;
    for (size_t p = 0; p < np; p++)
        if (cnt[p]) {
            for (int k = 0; k < 3; k++)
                sum[3 * p + k] /= cnt[p];
            measured++;
        }
    if (measured == 0) {
        rc = lr_err_set(e, LR_EINVAL,
                        "albedo: no camera pixel decoded to a projector pixel: is the mockup "
                        "lit and in view?");
        goto done;
    }
    /* scale: the 99.5th percentile of the brightest channel over measured pixels */
    vals = malloc((size_t)measured * sizeof *vals);
    if (!vals) {
        rc = lr_err_set(e, LR_ENOMEM, "albedo: out of memory");
        goto done;
    }
    long k = 0;
    for (size_t p = 0; p < np; p++)
        if (cnt[p])
            vals[k++] = fmax(sum[3 * p], fmax(sum[3 * p + 1], sum[3 * p + 2]));
    qsort(vals, (size_t)measured, sizeof *vals, cmp_double);
    double scale = vals[(long)floor(0.995 * (measured - 1))];
    if (!(scale > 0)) {
        rc = lr_err_set(e, LR_EINVAL,
                        "albedo: white and black captures do not differ (white - black <= 0 "
                        "almost everywhere): was the projector on?");
        goto done;
    }
    if ((rc = lr_image_alloc(&out->response, pw, ph, e)))
        goto done;
    for (size_t p = 0; p < np * 3; p++)
        out->response.rgb[p] = (float)fmin(LR_ALBEDO_MAX, sum[p] / scale);
    /* hole filling: mean of measured (or already filled) 8-neighbours, one ring per pass */
    long filled = 0;
    for (int pass = 0; pass < fill_passes; pass++) {
        int *next = malloc(np * sizeof *next);
        if (!next) {
            rc = lr_err_set(e, LR_ENOMEM, "albedo: out of memory");
            goto done;
        }
        memcpy(next, cnt, np * sizeof *next);
        for (int y = 0; y < ph; y++)
            for (int x = 0; x < pw; x++) {
                size_t p = (size_t)y * pw + x;
                if (cnt[p])
                    continue;
                double s[3] = {0, 0, 0};
                int n = 0;
                for (int dy = -1; dy <= 1; dy++)
                    for (int dx = -1; dx <= 1; dx++) {
                        int xx = x + dx, yy = y + dy;
                        if (xx < 0 || yy < 0 || xx >= pw || yy >= ph)
                            continue;
                        size_t q = (size_t)yy * pw + xx;
                        if (!cnt[q])
                            continue;
                        for (int c = 0; c < 3; c++)
                            s[c] += out->response.rgb[3 * q + c];
                        n++;
                    }
                if (n >= 3) { /* a lone neighbour is an edge, not a hole */
                    for (int c = 0; c < 3; c++)
                        out->response.rgb[3 * p + c] = (float)(s[c] / n);
                    next[p] = 1;
                    filled++;
                }
            }
        memcpy(cnt, next, np * sizeof *next);
        free(next);
    }
    out->scale = scale;
    out->measured_pixels = measured;
    out->filled_pixels = filled;
done:
    free(sum);
    free(cnt);
    free(vals);
    if (rc)
        lr_albedo_free(out);
    return rc;
}

typedef struct doc {
    const lr_albedo *a;
    const char *image; /* file name relative to the JSON */
} doc;

static void fill(lr_jw *w, const void *obj)
{
    const doc *d = obj;
    lr_jw_string(w, "image", d->image);
    double size[2] = {d->a->response.width, d->a->response.height};
    lr_jw_numbers(w, "size", size, 2);
    lr_jw_number(w, "scale", d->a->scale);
    lr_jw_int(w, "measured_pixels", d->a->measured_pixels);
    lr_jw_int(w, "filled_pixels", d->a->filled_pixels);
}

typedef struct fields {
    char image[256];
    double size[2], scale;
    long measured, filled;
} fields;

static int from_json(const lr_json *j, lr_jnode root, fields *f, lr_err *e)
{
    static const char *const keys[] = {"version", "kind", "image", "size", "scale",
                                       "measured_pixels", "filled_pixels", NULL};
    int rc = lr_json_check_keys(j, root, "mockup albedo", keys, e);
    if (rc || (rc = lr_json_get_string(j, root, "image", true, f->image, sizeof f->image, e)) ||
        (rc = lr_calfile_numbers(j, root, NULL, "size", 2, 1, 65536, f->size, e)) ||
        (rc = lr_calfile_number(j, root, NULL, "scale", 0, 1e30, &f->scale, e)) ||
        (rc = lr_calfile_int(j, root, NULL, "measured_pixels", 1, 1L << 32, &f->measured, e)) ||
        (rc = lr_calfile_int(j, root, NULL, "filled_pixels", 0, 1L << 32, &f->filled, e)))
        return rc;
    if (f->size[0] != floor(f->size[0]) || f->size[1] != floor(f->size[1]))
        return lr_json_fail(j, lr_json_get(j, root, "size"), "size", e, LR_EINVAL,
                            "must be whole pixels");
    if (strchr(f->image, '/') || f->image[0] == '.' || f->image[0] == 0)
        return lr_json_fail(j, lr_json_get(j, root, "image"), "image", e, LR_EINVAL,
                            "'%s' must be a plain file name beside the JSON", f->image);
    return LR_OK;
}

static int check(const lr_json *j, lr_jnode root, lr_err *e)
{
    fields f;
    return from_json(j, root, &f, e);
}

/* dir part of path (with the slash) into buf */
static void dir_of(const char *path, char *buf, size_t cap)
{
    const char *s = strrchr(path, '/');
    size_t n = s ? (size_t)(s - path + 1) : 0;
    if (n >= cap)
        n = cap - 1;
    memcpy(buf, path, n);
    buf[n] = 0;
}

int lr_albedo_save(const char *path, const lr_albedo *a, lr_err *e)
{
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    char image[256];
    size_t n = strlen(base);
    if (n > 5 && !strcmp(base + n - 5, ".json"))
        n -= 5;
    if (n == 0 || n + 5 > sizeof image)
        return lr_err_set(e, LR_EINVAL, "%s: bad albedo file name", path);
    snprintf(image, sizeof image, "%.*s.pfm", (int)n, base);
    char dir[4096], full[4352];
    dir_of(path, dir, sizeof dir);
    snprintf(full, sizeof full, "%s%s", dir, image);
    int rc = lr_image_write_pfm(full, &a->response, e);
    if (rc)
        return rc;
    doc d = {a, image};
    return lr_calfile_save(path, LR_ALBEDO_KIND, fill, &d, check, e);
}

int lr_albedo_load(const char *path, lr_albedo *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    lr_json *j;
    lr_jnode root;
    int rc = lr_calfile_load(path, LR_ALBEDO_KIND, &j, &root, e);
    if (rc)
        return rc;
    fields f;
    rc = from_json(j, root, &f, e);
    lr_json_destroy(j);
    if (rc)
        return rc;
    char dir[4096], full[4352];
    dir_of(path, dir, sizeof dir);
    snprintf(full, sizeof full, "%s%s", dir, f.image);
    if ((rc = lr_image_read_pfm(full, &out->response, e)))
        return lr_err_prefix(e, "%s: field 'image'", path);
    if (out->response.width != (int)f.size[0] || out->response.height != (int)f.size[1]) {
        rc = lr_err_set(e, LR_EINVAL, "%s: field 'size': [%g, %g] but %s is %d x %d", path,
                        f.size[0], f.size[1], full, out->response.width, out->response.height);
        lr_albedo_free(out);
        return rc;
    }
    size_t np = (size_t)out->response.width * out->response.height * 3;
    for (size_t p = 0; p < np; p++) {
        float v = out->response.rgb[p];
        if (!(isfinite(v) && v >= 0 && v <= LR_ALBEDO_MAX)) {
            rc = lr_err_set(e, LR_EINVAL, "%s: pixel (%zu, %zu) channel %zu is %g (0..%g)", full,
                            (p / 3) % out->response.width, (p / 3) / out->response.width, p % 3,
                            (double)v, LR_ALBEDO_MAX);
            lr_albedo_free(out);
            return rc;
        }
    }
    out->scale = f.scale;
    out->measured_pixels = f.measured;
    out->filled_pixels = f.filled;
    return LR_OK;
}
