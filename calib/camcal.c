#include "calib/camcal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calib/calfile.h"
#include "calib/cv_shim.h"

void lr_camcal_free(lr_camcal *c)
{
    if (!c)
        return;
    for (int i = 0; i < c->nviews; i++)
        free(c->views[i].image);
    for (int i = 0; i < c->nrejected; i++) {
        free(c->rejected[i].image);
        free(c->rejected[i].reason);
    }
    free(c->views);
    free(c->rejected);
    memset(c, 0, sizeof *c);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, int n)
{
    if (n == 0)
        return 0;
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double lr_camcal_median_error(const lr_camcal *c)
{
    double *v = malloc(sizeof *v * (size_t)(c->nviews ? c->nviews : 1));
    if (!v)
        return NAN;
    int n = 0;
    for (int i = 0; i < c->nviews; i++)
        if (c->views[i].used)
            v[n++] = c->views[i].error;
    double m = median(v, n);
    free(v);
    return m;
}

static int add_reject(lr_camcal *c, const char *image, const char *reason, lr_err *e)
{
    lr_camcal_reject *r = realloc(c->rejected, sizeof *r * (size_t)(c->nrejected + 1));
    if (!r)
        return lr_err_set(e, LR_ENOMEM, "out of memory");
    c->rejected = r;
    r[c->nrejected].image = strdup(image);
    r[c->nrejected].reason = strdup(reason);
    c->nrejected++;
    if (!r[c->nrejected - 1].image || !r[c->nrejected - 1].reason)
        return lr_err_set(e, LR_ENOMEM, "out of memory");
    return LR_OK;
}

/* Detected board points of the accepted views, packed for lr_cv_calibrate. */
typedef struct detections {
    int n;        /* views */
    int per_view; /* points per view */
    double *img;  /* n * per_view * 2 */
    char **names;
} detections;

static void detections_free(detections *d)
{
    for (int i = 0; i < d->n; i++)
        free(d->names[i]);
    free(d->names);
    free(d->img);
}

/* Searches every image; the image size of the calibration is the size of the FIRST GOOD
 * VIEW (the first image in which the board is found), not of the first image read: a glob
 * sorts a stray photo of another size (or one without the board) first as easily as last,
 * and it must not decide the size the others are checked against. Each image that is not
 * used gets one entry in out->rejected (unreadable, board not found, another size); the
 * order of the views is the order of the images. */
static int detect_all(const lr_camcal_desc *d, lr_camcal *out, detections *det, int *w, int *h,
                      lr_err *e)
{
    int np = lr_board_points(&d->board);
    det->per_view = np;
    det->img = malloc(sizeof(double) * 2 * (size_t)np * (size_t)d->nimages);
    det->names = calloc((size_t)d->nimages, sizeof(char *));
    if (!det->img || !det->names)
        return lr_err_set(e, LR_ENOMEM, "out of memory");
    *w = *h = 0;
    for (int i = 0; i < d->nimages; i++) {
        const char *path = d->images[i];
        lr_progress_report(d->progress, "detect board", i, d->nimages);
        lr_img gray;
        lr_err re = {0};
        int rc = lr_img_read(path, LR_IMG_GRAY8, &gray, &re);
        if (rc == LR_ENOMEM)
            return lr_err_set(e, rc, "%s", re.msg);
        if (rc) {
            if ((rc = add_reject(out, path, re.msg, e)))
                return rc;
            continue;
        }
        char reason[LR_ERR_MSG_MAX] = "";
        if (det->n > 0 && (gray.w != *w || gray.h != *h))
            snprintf(reason, sizeof reason,
                     "size %dx%d differs from the first good view's %dx%d (%s)", gray.w,
                     gray.h, *w, *h, det->names[0]);
        bool found = false;
        if (!reason[0]) {
            rc = lr_board_detect(&d->board, &gray, d->subpix_window == 0 ? 11 : d->subpix_window,
                                 det->img + 2 * (size_t)np * (size_t)det->n,
                                 &found, &re);
            if (rc)
                snprintf(reason, sizeof reason, "%s", re.msg);
            else if (!found)
                snprintf(reason, sizeof reason, "%dx%d %s not found", d->board.cols,
                         d->board.rows, lr_board_pattern_name(d->board.pattern));
        }
        int gw = gray.w, gh = gray.h;
        lr_img_free(&gray);
        if (reason[0]) {
            if ((rc = add_reject(out, path, reason, e)))
                return rc;
            continue;
        }
        if (det->n == 0) {
            *w = gw;
            *h = gh;
        }
        if (!(det->names[det->n] = strdup(path)))
            return lr_err_set(e, LR_ENOMEM, "out of memory");
        det->n++;
    }
    lr_progress_report(d->progress, "detect board", d->nimages, d->nimages);
    return LR_OK;
}

/* Calibrates from the views whose use[] is set; fills k, rms and errors of those views. */
static int fit(const lr_camcal_desc *d, const detections *det, const bool *use, int w, int h,
               lr_intrinsics *k, double *rms, double *err, lr_err *e)
{
    int np = det->per_view, nv = 0;
    for (int i = 0; i < det->n; i++)
        nv += use[i];
    double *obj = malloc(sizeof(double) * 3 * (size_t)np * (size_t)nv);
    double *img = malloc(sizeof(double) * 2 * (size_t)np * (size_t)nv);
    int *npts = malloc(sizeof(int) * (size_t)nv);
    double *verr = malloc(sizeof(double) * (size_t)nv);
    int rc = LR_OK;
    if (!obj || !img || !npts || !verr) {
        rc = lr_err_set(e, LR_ENOMEM, "out of memory");
        goto out;
    }
    for (int i = 0, v = 0; i < det->n; i++) {
        if (!use[i])
            continue;
        lr_board_object_points(&d->board, obj + 3 * (size_t)np * (size_t)v);
        memcpy(img + 2 * (size_t)np * (size_t)v, det->img + 2 * (size_t)np * (size_t)i,
               sizeof(double) * 2 * (size_t)np);
        npts[v++] = np;
    }
    lr_cv_views views = {nv, npts, obj, img, NULL};
    double K[9] = {0}, dist[5] = {0};
    int flags = d->fix_aspect ? LR_CV_FIX_ASPECT : 0;
    lr_progress_report(d->progress, "calibrate", 0, 1);
    rc = lr_cv_calibrate(&views, w, h, flags, K, dist, rms, verr, NULL, e);
    lr_progress_report(d->progress, "calibrate", 1, 1);
    if (rc)
        goto out;
    *k = (lr_intrinsics){w, h, K[0], K[4], K[2], K[5], {dist[0], dist[1], dist[2], dist[3], dist[4]}};
    for (int i = 0, v = 0; i < det->n; i++)
        err[i] = use[i] ? verr[v++] : NAN;
    if (!isfinite(*rms))
        rc = lr_err_set(e, LR_EINVAL, "calibration diverged (RMS error not finite)");
    else
        rc = lr_intrinsics_check(k, "camera calibration result", e);
out:
    free(obj);
    free(img);
    free(npts);
    free(verr);
    return rc;
}

int lr_camcal_run(const lr_camcal_desc *d, lr_camcal *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    int rc = lr_board_check(&d->board, e);
    if (rc)
        return rc;
    double factor = d->outlier_factor > 0 ? d->outlier_factor : 3.0;
    double floor_px = d->outlier_floor_px > 0 ? d->outlier_floor_px : 0.5;
    int min_views = d->min_views > 0 ? d->min_views : 3;
    if (d->nimages <= 0)
        return lr_err_set(e, LR_EINVAL, "no images given");

    out->board = d->board;
    out->fix_aspect = d->fix_aspect;
    out->subpix_window = d->subpix_window == 0 ? 11 : d->subpix_window;
    detections det = {0};
    bool *use = NULL, *outlier = NULL;
    double *err = NULL, *tmp = NULL;
    int w, h;
    if ((rc = detect_all(d, out, &det, &w, &h, e)))
        goto fail;
    if (det.n < min_views) {
        rc = lr_err_set(e, LR_EINVAL,
                        "%d of %d images usable (board found, same size); need at least %d "
                        "(%d skipped, first: %s: %s)",
                        det.n, d->nimages, min_views, out->nrejected,
                        out->nrejected ? out->rejected[0].image : "-",
                        out->nrejected ? out->rejected[0].reason : "-");
        goto fail;
    }
    use = malloc(sizeof *use * (size_t)det.n);
    err = malloc(sizeof *err * (size_t)det.n);
    tmp = malloc(sizeof *tmp * (size_t)det.n);
    outlier = malloc(sizeof *outlier * (size_t)det.n);
    if (!use || !err || !tmp || !outlier) {
        rc = lr_err_set(e, LR_ENOMEM, "out of memory");
        goto fail;
    }
    for (int i = 0; i < det.n; i++)
        use[i] = true;
    if ((rc = fit(d, &det, use, w, h, &out->k, &out->rms, err, e)))
        goto fail;

    memcpy(tmp, err, sizeof *tmp * (size_t)det.n);
    double med = median(tmp, det.n);
    int noutliers = 0;
    for (int i = 0; i < det.n; i++) {
        outlier[i] = err[i] > factor * med && err[i] > floor_px;
        noutliers += outlier[i];
    }
    if (d->drop_outliers && noutliers > 0) {
        if (det.n - noutliers < min_views) {
            rc = lr_err_set(e, LR_EINVAL,
                            "%d of %d views are outliers; too few (%d) would remain to refit",
                            noutliers, det.n, min_views);
            goto fail;
        }
        for (int i = 0; i < det.n; i++)
            use[i] = !outlier[i];
        double *err2 = malloc(sizeof *err2 * (size_t)det.n);
        if (!err2) {
            rc = lr_err_set(e, LR_ENOMEM, "out of memory");
            goto fail;
        }
        rc = fit(d, &det, use, w, h, &out->k, &out->rms, err2, e);
        for (int i = 0; i < det.n && !rc; i++)
            if (use[i])
                err[i] = err2[i];
        free(err2);
        if (rc)
            goto fail;
    }
    out->views = calloc((size_t)det.n, sizeof *out->views);
    if (!out->views) {
        rc = lr_err_set(e, LR_ENOMEM, "out of memory");
        goto fail;
    }
    out->nviews = det.n;
    for (int i = 0; i < det.n; i++) {
        out->views[i].image = det.names[i];
        det.names[i] = NULL;
        out->views[i].error = err[i];
        out->views[i].outlier = outlier[i];
        out->views[i].used = use[i];
    }
    detections_free(&det);
    free(use);
    free(outlier);
    free(err);
    free(tmp);
    return LR_OK;
fail:
    detections_free(&det);
    free(use);
    free(outlier);
    free(err);
    free(tmp);
    /* The skipped images stay listed (the caller prints them and frees with
     * lr_camcal_free); nothing else of a failed run is kept. */
    lr_camcal_reject *rej = out->rejected;
    int nrej = out->nrejected;
    out->rejected = NULL;
    out->nrejected = 0;
    lr_camcal_free(out);
    out->rejected = rej;
    out->nrejected = nrej;
    return rc;
}

/* ---- file ----------------------------------------------------------------------------- */

static void fill(lr_jw *w, const void *obj)
{
    const lr_camcal *c = obj;
    lr_jw_number(w, "fx", c->k.fx);
    lr_jw_number(w, "fy", c->k.fy);
    lr_jw_number(w, "cx", c->k.cx);
    lr_jw_number(w, "cy", c->k.cy);
    lr_jw_numbers(w, "dist", c->k.dist, 5);
    lr_jw_number(w, "rms", c->rms);
    double size[2] = {c->k.width, c->k.height};
    lr_jw_numbers(w, "image_size", size, 2);
    lr_board_write(w, "board", &c->board);
    lr_jw_bool(w, "fix_aspect", c->fix_aspect);
    if (c->subpix_window > 0)
        lr_jw_int(w, "subpix_window", c->subpix_window);
    else
        lr_jw_string(w, "subpix_window", "auto");
    lr_jw_array(w, "views");
    for (int i = 0; i < c->nviews; i++) {
        lr_jw_object(w, NULL);
        lr_jw_string(w, "image", c->views[i].image);
        lr_jw_number(w, "error", c->views[i].error);
        lr_jw_bool(w, "outlier", c->views[i].outlier);
        lr_jw_bool(w, "used", c->views[i].used);
        lr_jw_object_end(w);
    }
    lr_jw_array_end(w);
    lr_jw_array(w, "outliers");
    for (int i = 0; i < c->nviews; i++)
        if (c->views[i].outlier)
            lr_jw_string(w, NULL, c->views[i].image);
    lr_jw_array_end(w);
    lr_jw_array(w, "rejected");
    for (int i = 0; i < c->nrejected; i++) {
        lr_jw_object(w, NULL);
        lr_jw_string(w, "image", c->rejected[i].image);
        lr_jw_string(w, "reason", c->rejected[i].reason);
        lr_jw_object_end(w);
    }
    lr_jw_array_end(w);
}

static char *json_strdup(const lr_json *j, lr_jnode n, const char *field, lr_err *e)
{
    char buf[4096];
    if (lr_json_string(j, n, field, buf, sizeof buf, e))
        return NULL;
    char *s = strdup(buf);
    if (!s)
        lr_err_set(e, LR_ENOMEM, "out of memory");
    return s;
}

int lr_camcal_from_json(const lr_json *j, lr_jnode root, lr_camcal *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    static const char *const keys[] = {"version", "kind", "fx", "fy", "cx", "cy", "dist", "rms",
                                       "image_size", "board", "fix_aspect", "subpix_window", "views",
                                       "outliers", "rejected", NULL};
    int rc = lr_json_check_keys(j, root, "camera calibration", keys, e);
    if (rc)
        return rc;
    if ((rc = lr_intrinsics_read(j, root, NULL, &out->k, e)) ||
        (rc = lr_calfile_number(j, root, NULL, "rms", 0, 1e4, &out->rms, e)))
        return rc;
    /* Optional provenance: files written by hand or by other tools may omit it. */
    if (lr_json_get(j, root, "board") != LR_JNONE &&
        (rc = lr_board_read(j, root, "board", &out->board, e)))
        return rc;
    if ((rc = lr_json_get_bool(j, root, "fix_aspect", false, &out->fix_aspect, e)))
        return rc;
    lr_jnode sw = lr_json_get(j, root, "subpix_window");
    out->subpix_window = 11;
    if (sw != LR_JNONE) {
        if (lr_json_str_eq(j, sw, "auto")) {
            out->subpix_window = LR_SUBPIX_AUTO;
        } else {
            long v;
            if ((rc = lr_calfile_int(j, root, NULL, "subpix_window", 1, 100, &v, e)))
                return rc;
            out->subpix_window = (int)v;
        }
    }
    lr_jnode views = lr_json_get(j, root, "views");
    if (views != LR_JNONE) {
        int n;
        if ((rc = lr_calfile_array(j, root, NULL, "views", &views, &n, e)))
            return rc;
        out->views = calloc((size_t)(n ? n : 1), sizeof *out->views);
        if (!out->views)
            return lr_err_set(e, LR_ENOMEM, "out of memory");
        for (int i = 0; i < n; i++) {
            lr_jnode v = lr_json_at(j, views, i);
            char where[32];
            snprintf(where, sizeof where, "views[%d]", i);
            lr_camcal_view *cv = &out->views[i];
            out->nviews = i + 1;
            cv->used = true;
            if (lr_json_type(j, v) != LR_JSON_OBJECT)
                return lr_json_fail(j, v, where, e, LR_EPARSE, "expected an object");
            lr_jnode img = lr_json_get(j, v, "image");
            if (img == LR_JNONE)
                return lr_json_fail(j, v, where, e, LR_EPARSE, "missing 'image'");
            if (!(cv->image = json_strdup(j, img, "image", e)))
                return e ? e->code : LR_EPARSE;
            if ((rc = lr_calfile_number(j, v, where, "error", 0, 1e4, &cv->error, e)) ||
                (rc = lr_json_get_bool(j, v, "outlier", false, &cv->outlier, e)) ||
                (rc = lr_json_get_bool(j, v, "used", false, &cv->used, e)))
                return rc;
        }
    }
    lr_jnode rej = lr_json_get(j, root, "rejected");
    if (rej != LR_JNONE) {
        int n;
        if ((rc = lr_calfile_array(j, root, NULL, "rejected", &rej, &n, e)))
            return rc;
        out->rejected = calloc((size_t)(n ? n : 1), sizeof *out->rejected);
        if (!out->rejected)
            return lr_err_set(e, LR_ENOMEM, "out of memory");
        for (int i = 0; i < n; i++) {
            lr_jnode v = lr_json_at(j, rej, i);
            out->nrejected = i + 1;
            lr_jnode a = lr_json_get(j, v, "image"), b = lr_json_get(j, v, "reason");
            if (a == LR_JNONE || b == LR_JNONE)
                return lr_json_fail(j, v, "rejected", e, LR_EPARSE,
                                    "each entry needs 'image' and 'reason'");
            if (!(out->rejected[i].image = json_strdup(j, a, "rejected.image", e)) ||
                !(out->rejected[i].reason = json_strdup(j, b, "rejected.reason", e)))
                return e ? e->code : LR_EPARSE;
        }
    }
    return LR_OK;
}

static int check(const lr_json *j, lr_jnode root, lr_err *e)
{
    lr_camcal tmp;
    int rc = lr_camcal_from_json(j, root, &tmp, e);
    lr_camcal_free(&tmp);
    return rc;
}

int lr_camcal_save(const char *path, const lr_camcal *c, lr_err *e)
{
    return lr_calfile_save(path, LR_CAMCAL_KIND, fill, c, check, e);
}

int lr_camcal_load(const char *path, lr_camcal *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    lr_json *j;
    lr_jnode root;
    int rc = lr_calfile_load(path, LR_CAMCAL_KIND, &j, &root, e);
    if (rc)
        return rc;
    rc = lr_camcal_from_json(j, root, out, e);
    if (rc)
        lr_camcal_free(out);
    lr_json_destroy(j);
    return rc;
}
