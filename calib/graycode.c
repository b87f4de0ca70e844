#include "calib/graycode.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "calib/calfile.h"

struct lr_gc_map {
    int w, h;       /* camera */
    int pw, ph;     /* projector */
    int32_t *xy;    /* 2 per camera pixel, -1 where not valid */
    uint8_t *status;
};

int lr_gc_frame_count(int pw, int ph, int *count, lr_err *e)
{
    int n;
    int rc = lr_cv_graycode_count(pw, ph, &n, e);
    if (rc)
        return rc;
    *count = n + 2;
    return LR_OK;
}

void lr_gc_frame_name(int i, char *buf, size_t cap)
{
    if (i == 0)
        snprintf(buf, cap, "white.png");
    else if (i == 1)
        snprintf(buf, cap, "black.png");
    else
        snprintf(buf, cap, "pattern_%02d.png", i - 2);
}

typedef struct seq_ctx {
    lr_gc_show_fn show;
    void *ctx;
} seq_ctx;

static int pattern_sink(void *ctx, int index, const lr_img *img, lr_err *e)
{
    seq_ctx *s = ctx;
    char name[32];
    lr_gc_frame_name(index + 2, name, sizeof name);
    return s->show(s->ctx, index + 2, img, name, e);
}

int lr_gc_run_sequence(int pw, int ph, lr_gc_show_fn show, void *ctx, lr_err *e)
{
    int n;
    int rc = lr_gc_frame_count(pw, ph, &n, e);
    if (rc)
        return rc;
    lr_img flat;
    if ((rc = lr_img_alloc(&flat, pw, ph, 1, 1, e)))
        return rc;
    memset(flat.px, 255, (size_t)pw * (size_t)ph);
    rc = show(ctx, 0, &flat, "white.png", e);
    if (!rc) {
        memset(flat.px, 0, (size_t)pw * (size_t)ph);
        rc = show(ctx, 1, &flat, "black.png", e);
    }
    lr_img_free(&flat);
    if (rc)
        return rc;
    seq_ctx s = {show, ctx};
    return lr_cv_graycode_generate(pw, ph, pattern_sink, &s, e);
}

static int make_dir(const char *dir, lr_err *e)
{
    if (mkdir(dir, 0755) != 0 && errno != EEXIST)
        return lr_err_set(e, LR_EIO, "%s: cannot create directory: %s", dir, strerror(errno));
    struct stat st;
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode))
        return lr_err_set(e, LR_EIO, "%s: not a directory", dir);
    return LR_OK;
}

typedef struct write_ctx {
    const char *dir;
    int total;
    const lr_progress *progress;
} write_ctx;

static int write_frame(void *ctx, int index, const lr_img *frame, const char *name, lr_err *e)
{
    write_ctx *w = ctx;
    char path[4096];
    if (snprintf(path, sizeof path, "%s/%s", w->dir, name) >= (int)sizeof path)
        return lr_err_set(e, LR_EINVAL, "%s: path too long", w->dir);
    int rc = lr_img_write_frame(path, frame, e);
    lr_progress_report(w->progress, "write patterns", index + 1, w->total);
    return rc;
}

int lr_gc_write_patterns(const char *dir, int pw, int ph, const lr_progress *progress,
                         lr_err *e)
{
    int n;
    int rc = lr_gc_frame_count(pw, ph, &n, e);
    if (rc || (rc = make_dir(dir, e)))
        return rc;
    write_ctx w = {dir, n, progress};
    if ((rc = lr_gc_run_sequence(pw, ph, write_frame, &w, e)))
        return rc;
    return lr_gc_write_sequence(dir, pw, ph, e);
}

/* ---- sequence.json -------------------------------------------------------------------- */

typedef struct seq_desc {
    int pw, ph, n;
} seq_desc;

static void seq_fill(lr_jw *w, const void *obj)
{
    const seq_desc *s = obj;
    double size[2] = {s->pw, s->ph};
    lr_jw_numbers(w, "projector", size, 2);
    lr_jw_array(w, "frames");
    for (int i = 0; i < s->n; i++) {
        char name[32];
        lr_gc_frame_name(i, name, sizeof name);
        lr_jw_string(w, NULL, name);
    }
    lr_jw_array_end(w);
}

static int seq_parse(const lr_json *j, lr_jnode root, int *pw, int *ph, lr_err *e)
{
    double size[2];
    int rc = lr_calfile_numbers(j, root, NULL, "projector", 2, 2, 16384, size, e);
    if (rc)
        return rc;
    if (size[0] != floor(size[0]) || size[1] != floor(size[1]))
        return lr_json_fail(j, lr_json_get(j, root, "projector"), "projector", e, LR_EINVAL,
                            "must be whole pixels");
    *pw = (int)size[0];
    *ph = (int)size[1];
    int n, count;
    lr_jnode frames;
    if ((rc = lr_calfile_array(j, root, NULL, "frames", &frames, &count, e)) ||
        (rc = lr_gc_frame_count(*pw, *ph, &n, e)))
        return rc;
    if (count != n)
        return lr_json_fail(j, frames, "frames", e, LR_EINVAL,
                            "%d frames listed, a %dx%d projector needs %d", count, *pw, *ph, n);
    return LR_OK;
}

static int seq_check(const lr_json *j, lr_jnode root, lr_err *e)
{
    int pw, ph;
    return seq_parse(j, root, &pw, &ph, e);
}

int lr_gc_write_sequence(const char *dir, int pw, int ph, lr_err *e)
{
    seq_desc s = {pw, ph, 0};
    int rc = lr_gc_frame_count(pw, ph, &s.n, e);
    if (rc)
        return rc;
    char path[4096];
    if (snprintf(path, sizeof path, "%s/sequence.json", dir) >= (int)sizeof path)
        return lr_err_set(e, LR_EINVAL, "%s: path too long", dir);
    return lr_calfile_save(path, LR_GC_SEQUENCE_KIND, seq_fill, &s, seq_check, e);
}

int lr_gc_read_sequence(const char *dir, int *pw, int *ph, lr_err *e)
{
    char path[4096];
    if (snprintf(path, sizeof path, "%s/sequence.json", dir) >= (int)sizeof path)
        return lr_err_set(e, LR_EINVAL, "%s: path too long", dir);
    lr_json *j;
    lr_jnode root;
    int rc = lr_calfile_load(path, LR_GC_SEQUENCE_KIND, &j, &root, e);
    if (rc)
        return rc;
    rc = seq_parse(j, root, pw, ph, e);
    lr_json_destroy(j);
    return rc;
}

/* ---- decoding ------------------------------------------------------------------------- */

int lr_gc_decode_dir(const char *dir, int pw, int ph, const lr_gc_params *params,
                     const lr_progress *progress, lr_gc_map **out, lr_err *e)
{
    *out = NULL;
    int rc;
    if (pw <= 0 || ph <= 0) {
        if ((rc = lr_gc_read_sequence(dir, &pw, &ph, e)))
            return lr_err_prefix(e, "projector size not given and not known from %s", dir);
    }
    int n;
    if ((rc = lr_gc_frame_count(pw, ph, &n, e)))
        return rc;
    int contrast = params && params->contrast > 0 ? params->contrast : LR_GC_DEFAULT_CONTRAST;
    int shadow = params && params->shadow > 0 ? params->shadow : LR_GC_DEFAULT_SHADOW;
    size_t cap = strlen(dir) + 32;
    char *names = malloc(cap * (size_t)n);
    const char **pats = malloc(sizeof *pats * (size_t)n);
    lr_gc_map *m = calloc(1, sizeof *m);
    if (!names || !pats || !m) {
        rc = lr_err_set(e, LR_ENOMEM, "out of memory");
        goto out;
    }
    for (int i = 0; i < n; i++) {
        char leaf[32];
        lr_gc_frame_name(i, leaf, sizeof leaf);
        snprintf(names + cap * (size_t)i, cap, "%s/%s", dir, leaf);
        pats[i] = names + cap * (size_t)i;
    }
    m->pw = pw;
    m->ph = ph;
    rc = lr_cv_graycode_decode(pw, ph, pats + 2, n - 2, pats[0], pats[1], contrast, shadow,
                               progress, dir, &m->w, &m->h, &m->xy, &m->status, e);
    if (!rc) {
        *out = m;
        m = NULL;
    }
out:
    free(names);
    free(pats);
    lr_gc_map_destroy(m);
    return rc;
}

void lr_gc_map_destroy(lr_gc_map *m)
{
    if (!m)
        return;
    free(m->xy);
    free(m->status);
    free(m);
}

int lr_gc_map_width(const lr_gc_map *m) { return m->w; }
int lr_gc_map_height(const lr_gc_map *m) { return m->h; }

void lr_gc_map_projector_size(const lr_gc_map *m, int *pw, int *ph)
{
    *pw = m->pw;
    *ph = m->ph;
}

int lr_gc_map_get(const lr_gc_map *m, int x, int y, int *px, int *py)
{
    size_t i = (size_t)y * (size_t)m->w + (size_t)x;
    if (m->status[i] == LR_GC_VALID) {
        *px = m->xy[2 * i];
        *py = m->xy[2 * i + 1];
    }
    return m->status[i];
}

long lr_gc_map_count(const lr_gc_map *m, int status)
{
    long n = 0;
    for (size_t i = 0; i < (size_t)m->w * (size_t)m->h; i++)
        n += m->status[i] == status;
    return n;
}

const char *lr_gc_status_name(int status)
{
    switch (status) {
    case LR_GC_VALID: return "valid";
    case LR_GC_SHADOW: return "shadow";
    case LR_GC_LOW_CONTRAST: return "low contrast";
    case LR_GC_OUT_OF_RANGE: return "out of range";
    default: return "unknown";
    }
}

int lr_gc_map_save(const lr_gc_map *m, const char *path, lr_err *e)
{
    lr_img img;
    int rc = lr_img_alloc(&img, m->w, m->h, 3, 2, e);
    if (rc)
        return rc;
    uint16_t *p = img.px;
    for (size_t i = 0; i < (size_t)m->w * (size_t)m->h; i++) {
        bool ok = m->status[i] == LR_GC_VALID;
        p[3 * i] = ok ? (uint16_t)m->xy[2 * i] : 0;
        p[3 * i + 1] = ok ? (uint16_t)m->xy[2 * i + 1] : 0;
        p[3 * i + 2] = m->status[i];
    }
    rc = lr_img_write(path, &img, e);
    lr_img_free(&img);
    return rc;
}

int lr_gc_map_load(const char *path, int pw, int ph, lr_gc_map **out, lr_err *e)
{
    *out = NULL;
    lr_img img;
    int rc = lr_img_read(path, LR_IMG_AS_IS, &img, e);
    if (rc)
        return rc;
    if (img.channels != 3 || img.depth != 2) {
        lr_img_free(&img);
        return lr_err_set(e, LR_EINVAL, "%s: not a correspondence map (16-bit RGB expected)",
                          path);
    }
    lr_gc_map *m = calloc(1, sizeof *m);
    size_t np = (size_t)img.w * (size_t)img.h;
    if (m) {
        m->xy = malloc(sizeof *m->xy * 2 * np);
        m->status = malloc(np);
    }
    if (!m || !m->xy || !m->status) {
        lr_gc_map_destroy(m);
        lr_img_free(&img);
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
    }
    m->w = img.w;
    m->h = img.h;
    m->pw = pw;
    m->ph = ph;
    const uint16_t *p = img.px;
    for (size_t i = 0; i < np; i++) {
        int st = p[3 * i + 2];
        if (st > LR_GC_OUT_OF_RANGE ||
            (st == LR_GC_VALID && (p[3 * i] >= pw || p[3 * i + 1] >= ph))) {
            lr_err_set(e, LR_EINVAL,
                       "%s: pixel (%zu, %zu) holds status %d / (%d, %d), not a valid entry "
                       "for a %dx%d projector",
                       path, i % (size_t)img.w, i / (size_t)img.w, st, p[3 * i], p[3 * i + 1],
                       pw, ph);
            lr_gc_map_destroy(m);
            lr_img_free(&img);
            return LR_EINVAL;
        }
        m->status[i] = (uint8_t)st;
        m->xy[2 * i] = st == LR_GC_VALID ? p[3 * i] : -1;
        m->xy[2 * i + 1] = st == LR_GC_VALID ? p[3 * i + 1] : -1;
    }
    lr_img_free(&img);
    *out = m;
    return LR_OK;
}

/* ---- local homographies --------------------------------------------------------------- */

int lr_gc_local_homography(const lr_gc_map *m, const double *cam_xy, int n,
                           const lr_gc_local_params *params, double *proj_xy, bool *ok,
                           int *mapped, lr_err *e)
{
    int half = params && params->half_window > 0 ? params->half_window : 23;
    int min_points = params && params->min_points > 0 ? params->min_points : 50;
    double ransac = params && params->ransac_px > 0 ? params->ransac_px : 2.0;
    if (min_points < 4)
        min_points = 4;
    size_t cap = (size_t)(2 * half + 1) * (size_t)(2 * half + 1);
    double *src = malloc(sizeof *src * 2 * cap), *dst = malloc(sizeof *dst * 2 * cap);
    if (!src || !dst) {
        free(src);
        free(dst);
        return lr_err_set(e, LR_ENOMEM, "out of memory");
    }
    *mapped = 0;
    for (int k = 0; k < n; k++) {
        double cx = cam_xy[2 * k], cy = cam_xy[2 * k + 1];
        ok[k] = false;
        proj_xy[2 * k] = proj_xy[2 * k + 1] = NAN;
        int x0 = (int)lround(cx), y0 = (int)lround(cy);
        int cnt = 0;
        for (int y = y0 - half; y <= y0 + half; y++)
            for (int x = x0 - half; x <= x0 + half; x++) {
                if (x < 0 || y < 0 || x >= m->w || y >= m->h)
                    continue;
                size_t i = (size_t)y * (size_t)m->w + (size_t)x;
                if (m->status[i] != LR_GC_VALID)
                    continue;
                /* Camera pixel centres are at integer coordinates (OpenCV's convention, the
                 * one corner detection uses); a decoded projector index is the pixel whose
                 * centre is nearest the lit point, so both sides are unbiased. */
                src[2 * cnt] = x;
                src[2 * cnt + 1] = y;
                dst[2 * cnt] = m->xy[2 * i];
                dst[2 * cnt + 1] = m->xy[2 * i + 1];
                cnt++;
            }
        if (cnt < min_points)
            continue;
        double H[9];
        lr_err he = {0};
        if (lr_cv_find_homography(cnt, src, dst, ransac, H, NULL, &he))
            continue;
        double w = H[6] * cx + H[7] * cy + H[8];
        if (!(fabs(w) > 1e-12))
            continue;
        double px = (H[0] * cx + H[1] * cy + H[2]) / w, py = (H[3] * cx + H[4] * cy + H[5]) / w;
        if (!isfinite(px) || !isfinite(py))
            continue;
        proj_xy[2 * k] = px;
        proj_xy[2 * k + 1] = py;
        ok[k] = true;
        (*mapped)++;
    }
    free(src);
    free(dst);
    return LR_OK;
}
