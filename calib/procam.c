#include "calib/procam.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "calib/calfile.h"
#include "calib/camcal.h"
#include "calib/cv_shim.h"

void lr_procam_free(lr_procam *p)
{
    if (!p)
        return;
    for (int i = 0; i < p->nposes; i++)
        free(p->poses[i].name);
    for (int i = 0; i < p->nrejected; i++) {
        free(p->rejected[i].name);
        free(p->rejected[i].reason);
    }
    free(p->poses);
    free(p->rejected);
    memset(p, 0, sizeof *p);
}

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

static bool is_file(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

/* Sub-folders of dir that hold a white.png, sorted by name. */
static int list_poses(const char *dir, char ***out, int *n, lr_err *e)
{
    *out = NULL;
    *n = 0;
    DIR *d = opendir(dir);
    if (!d)
        return lr_err_set(e, LR_EIO, "%s: cannot open captures folder", dir);
    char **names = NULL;
    int count = 0, rc = LR_OK;
    struct dirent *ent;
    while ((ent = readdir(d))) {
        if (ent->d_name[0] == '.')
            continue;
        size_t len = strlen(dir) + strlen(ent->d_name) + 16;
        char *path = malloc(len);
        if (!path) {
            rc = lr_err_set(e, LR_ENOMEM, "out of memory");
            break;
        }
        snprintf(path, len, "%s/%s/white.png", dir, ent->d_name);
        if (!is_file(path)) {
            free(path);
            continue;
        }
        snprintf(path, len, "%s/%s", dir, ent->d_name);
        char **grown = realloc(names, sizeof *names * (size_t)(count + 1));
        if (!grown) {
            free(path);
            rc = lr_err_set(e, LR_ENOMEM, "out of memory");
            break;
        }
        names = grown;
        names[count++] = path;
    }
    closedir(d);
    if (rc) {
        for (int i = 0; i < count; i++)
            free(names[i]);
        free(names);
        return rc;
    }
    if (count > 1)
        qsort(names, (size_t)count, sizeof *names, cmp_str);
    *out = names;
    *n = count;
    return LR_OK;
}

static int add_reject(lr_procam *p, const char *name, const char *reason, lr_err *e)
{
    lr_procam_reject *r = realloc(p->rejected, sizeof *r * (size_t)(p->nrejected + 1));
    if (!r)
        return lr_err_set(e, LR_ENOMEM, "out of memory");
    p->rejected = r;
    r[p->nrejected].name = strdup(name);
    r[p->nrejected].reason = strdup(reason);
    p->nrejected++;
    if (!r[p->nrejected - 1].name || !r[p->nrejected - 1].reason)
        return lr_err_set(e, LR_ENOMEM, "out of memory");
    return LR_OK;
}

/* One pose's measurements. */
typedef struct pose_data {
    char *name;
    double *cam;   /* all board points in the camera (np x 2) */
    double *proj;  /* projector positions (np x 2), NaN where not mapped */
    bool *ok;
    int mapped;
    long valid;
} pose_data;

static void pose_free(pose_data *p)
{
    free(p->name);
    free(p->cam);
    free(p->proj);
    free(p->ok);
}

/* Returns LR_OK with *usable = false (and a reason) when the pose is to be skipped. */
static int measure_pose(const lr_procam_desc *d, const char *dir, int *cam_w, int *cam_h,
                        int *proj_w, int *proj_h, pose_data *out, bool *usable, char *reason,
                        size_t cap, lr_err *e)
{
    int np = lr_board_points(&d->board);
    *usable = false;
    out->cam = malloc(sizeof(double) * 2 * (size_t)np);
    out->proj = malloc(sizeof(double) * 2 * (size_t)np);
    out->ok = malloc(sizeof(bool) * (size_t)np);
    if (!out->cam || !out->proj || !out->ok)
        return lr_err_set(e, LR_ENOMEM, "out of memory");
    char path[4096];
    snprintf(path, sizeof path, "%s/white.png", dir);
    lr_img gray;
    lr_err sub = {0};
    int rc = lr_img_read(path, LR_IMG_GRAY8, &gray, &sub);
    if (rc) {
        snprintf(reason, cap, "%s", sub.msg);
        return rc == LR_ENOMEM ? lr_err_set(e, rc, "%s", sub.msg) : LR_OK;
    }
    if (*cam_w == 0) {
        *cam_w = gray.w;
        *cam_h = gray.h;
    } else if (gray.w != *cam_w || gray.h != *cam_h) {
        snprintf(reason, cap, "camera frames %dx%d, other poses %dx%d", gray.w, gray.h, *cam_w,
                 *cam_h);
        lr_img_free(&gray);
        return LR_OK;
    }
    bool found = false;
    int win = d->subpix_window == 0 ? 11 : d->subpix_window;
    rc = lr_board_detect(&d->board, &gray, win, out->cam, &found, &sub);
    lr_img_free(&gray);
    if (rc || !found) {
        snprintf(reason, cap, "%s", rc ? sub.msg : "board not found in white.png");
        return LR_OK;
    }
    int pw = d->proj_w, ph = d->proj_h;
    if (pw <= 0 || ph <= 0) {
        if (lr_gc_read_sequence(dir, &pw, &ph, &sub)) {
            snprintf(reason, cap, "projector size unknown: %.400s", sub.msg);
            return LR_OK;
        }
    }
    if (*proj_w == 0) {
        *proj_w = pw;
        *proj_h = ph;
    } else if (pw != *proj_w || ph != *proj_h) {
        snprintf(reason, cap, "projector %dx%d, other poses %dx%d", pw, ph, *proj_w, *proj_h);
        return LR_OK;
    }
    lr_gc_map *map;
    rc = lr_gc_decode_dir(dir, pw, ph, &d->decode, d->progress, &map, &sub);
    if (rc) {
        snprintf(reason, cap, "%s", sub.msg);
        return rc == LR_ENOMEM ? lr_err_set(e, rc, "%s", sub.msg) : LR_OK;
    }
    if (lr_gc_map_width(map) != *cam_w || lr_gc_map_height(map) != *cam_h) {
        snprintf(reason, cap, "pattern captures are %dx%d, white.png %dx%d",
                 lr_gc_map_width(map), lr_gc_map_height(map), *cam_w, *cam_h);
        lr_gc_map_destroy(map);
        return LR_OK;
    }
    out->valid = lr_gc_map_count(map, LR_GC_VALID);
    rc = lr_gc_local_homography(map, out->cam, np, &d->local, out->proj, out->ok, &out->mapped,
                                e);
    lr_gc_map_destroy(map);
    if (rc)
        return rc;
    int min_corners = d->min_corners > 0 ? d->min_corners : (np + 1) / 2;
    if (out->mapped < min_corners) {
        snprintf(reason, cap, "only %d of %d corners map into the projector (need %d)",
                 out->mapped, np, min_corners);
        return LR_OK;
    }
    *usable = true;
    return LR_OK;
}

static double rotation_error(const double R[9])
{
    double worst = 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double dot = 0;
            for (int k = 0; k < 3; k++)
                dot += R[3 * k + i] * R[3 * k + j];
            worst = fmax(worst, fabs(dot - (i == j)));
        }
    double det = R[0] * (R[4] * R[8] - R[5] * R[7]) - R[1] * (R[3] * R[8] - R[5] * R[6]) +
                 R[2] * (R[3] * R[7] - R[4] * R[6]);
    return fmax(worst, fabs(det - 1));
}

int lr_procam_run(const lr_procam_desc *d, lr_procam *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    int rc = lr_board_check(&d->board, e);
    if (rc)
        return rc;
    if (d->camera && (rc = lr_intrinsics_check(d->camera, "camera intrinsics", e)))
        return rc;
    int min_poses = d->min_poses > 0 ? d->min_poses : 3;
    char **dirs = NULL;
    int ndirs = 0;
    if ((rc = list_poses(d->captures, &dirs, &ndirs, e)))
        return rc;
    if (ndirs == 0) {
        rc = lr_err_set(e, LR_EINVAL,
                        "%s: no pose folders (sub-folders with white.png, black.png and "
                        "pattern_NN.png)",
                        d->captures);
        free(dirs);
        return rc;
    }
    out->board = d->board;
    out->decode = d->decode;
    out->local = d->local;
    pose_data *poses = calloc((size_t)ndirs, sizeof *poses);
    int npose = 0, np = lr_board_points(&d->board);
    int cam_w = 0, cam_h = 0, proj_w = 0, proj_h = 0;
    double *obj = NULL, *cimg = NULL, *pimg = NULL, *call = NULL, *oall = NULL, *verr = NULL;
    int *npts = NULL, *nall = NULL;
    if (!poses) {
        rc = lr_err_set(e, LR_ENOMEM, "out of memory");
        goto done;
    }
    for (int i = 0; i < ndirs; i++) {
        char stage[4200];
        snprintf(stage, sizeof stage, "%s: board and decoding", dirs[i]);
        lr_progress_report(d->progress, stage, i, ndirs);
        char reason[LR_ERR_MSG_MAX] = "";
        bool usable;
        pose_data *p = &poses[npose];
        rc = measure_pose(d, dirs[i], &cam_w, &cam_h, &proj_w, &proj_h, p, &usable, reason,
                          sizeof reason, e);
        if (rc)
            goto done;
        if (!usable) {
            pose_free(p);
            memset(p, 0, sizeof *p);
            if ((rc = add_reject(out, dirs[i], reason, e)))
                goto done;
            continue;
        }
        p->name = dirs[i];
        dirs[i] = NULL;
        npose++;
    }
    if (npose < min_poses) {
        if (out->nrejected)
            rc = lr_err_set(e, LR_EINVAL, "%d usable poses of %d in %s; need at least %d "
                            "(first rejected: %s: %s)",
                            npose, ndirs, d->captures, min_poses, out->rejected[0].name,
                            out->rejected[0].reason);
        else
            rc = lr_err_set(e, LR_EINVAL, "%d usable poses of %d in %s; need at least %d",
                            npose, ndirs, d->captures, min_poses);
        goto done;
    }
    if (d->camera && (d->camera->width != cam_w || d->camera->height != cam_h)) {
        rc = lr_err_set(e, LR_EINVAL,
                        "camera intrinsics are for %dx%d images, the captures are %dx%d",
                        d->camera->width, d->camera->height, cam_w, cam_h);
        goto done;
    }

    /* Packed point sets: all corners for the camera, mapped corners for the projector. */
    size_t cap = (size_t)npose * (size_t)np;
    obj = malloc(sizeof *obj * 3 * cap);
    cimg = malloc(sizeof *cimg * 2 * cap);
    pimg = malloc(sizeof *pimg * 2 * cap);
    oall = malloc(sizeof *oall * 3 * cap);
    call = malloc(sizeof *call * 2 * cap);
    npts = malloc(sizeof *npts * (size_t)npose);
    nall = malloc(sizeof *nall * (size_t)npose);
    verr = malloc(sizeof *verr * 2 * (size_t)npose);
    double *board_pts = malloc(sizeof *board_pts * 3 * (size_t)np);
    if (!obj || !cimg || !pimg || !oall || !call || !npts || !nall || !verr || !board_pts) {
        free(board_pts);
        rc = lr_err_set(e, LR_ENOMEM, "out of memory");
        goto done;
    }
    lr_board_object_points(&d->board, board_pts);
    size_t at = 0;
    for (int v = 0; v < npose; v++) {
        memcpy(oall + 3 * (size_t)v * (size_t)np, board_pts, sizeof *board_pts * 3 * (size_t)np);
        memcpy(call + 2 * (size_t)v * (size_t)np, poses[v].cam, sizeof(double) * 2 * (size_t)np);
        nall[v] = np;
        npts[v] = 0;
        for (int k = 0; k < np; k++) {
            if (!poses[v].ok[k])
                continue;
            memcpy(obj + 3 * at, board_pts + 3 * k, sizeof(double) * 3);
            memcpy(cimg + 2 * at, poses[v].cam + 2 * k, sizeof(double) * 2);
            memcpy(pimg + 2 * at, poses[v].proj + 2 * k, sizeof(double) * 2);
            at++;
            npts[v]++;
        }
    }
    free(board_pts);

    /* Camera intrinsics. */
    double Kc[9], dc[5];
    if (d->camera) {
        out->cam = *d->camera;
        out->cam_rms = d->camera_rms;
        out->camera_from_file = true;
    } else {
        lr_progress_report(d->progress, "calibrate camera", 0, 1);
        lr_cv_views cv = {npose, nall, oall, call, NULL};
        double K[9] = {0}, dist[5] = {0};
        if ((rc = lr_cv_calibrate(&cv, cam_w, cam_h, 0, K, dist, &out->cam_rms, NULL, NULL, e)))
            goto done;
        out->cam = (lr_intrinsics){cam_w, cam_h, K[0], K[4], K[2], K[5],
                                   {dist[0], dist[1], dist[2], dist[3], dist[4]}};
        if ((rc = lr_intrinsics_check(&out->cam, "camera calibration result", e)))
            goto done;
    }
    lr_intrinsics_matrix(&out->cam, Kc);
    memcpy(dc, out->cam.dist, sizeof dc);

    /* Projector intrinsics: the projector "photographs" the board at the mapped corners. */
    lr_progress_report(d->progress, "calibrate projector", 0, 1);
    lr_cv_views pv = {npose, npts, obj, pimg, NULL};
    double Kp[9] = {0}, dp[5] = {0};
    if ((rc = lr_cv_calibrate(&pv, proj_w, proj_h, d->proj_fix_aspect ? LR_CV_FIX_ASPECT : 0, Kp,
                              dp, &out->proj_rms, NULL, NULL, e)))
        goto done;
    out->proj = (lr_intrinsics){proj_w, proj_h, Kp[0], Kp[4], Kp[2], Kp[5],
                                {dp[0], dp[1], dp[2], dp[3], dp[4]}};
    if ((rc = lr_intrinsics_check(&out->proj, "projector calibration result", e)))
        goto done;

    /* Extrinsics with both intrinsics fixed. */
    lr_progress_report(d->progress, "stereo calibration", 0, 1);
    lr_cv_views sv = {npose, npts, obj, cimg, pimg};
    if ((rc = lr_cv_stereo_calibrate(&sv, cam_w, cam_h, Kc, dc, Kp, dp, out->R, out->T, &out->rms,
                                     verr, e)))
        goto done;
    lr_progress_report(d->progress, "stereo calibration", 1, 1);
    if (!isfinite(out->rms) || rotation_error(out->R) > 1e-6) {
        rc = lr_err_set(e, LR_EINVAL, "stereo calibration diverged (RMS %g)", out->rms);
        goto done;
    }
    out->poses = calloc((size_t)npose, sizeof *out->poses);
    if (!out->poses) {
        rc = lr_err_set(e, LR_ENOMEM, "out of memory");
        goto done;
    }
    out->nposes = npose;
    for (int v = 0; v < npose; v++) {
        lr_procam_pose *p = &out->poses[v];
        p->name = poses[v].name;
        poses[v].name = NULL;
        p->corners = npts[v];
        p->valid_pixels = poses[v].valid;
        p->cam_error = verr[2 * v];
        p->proj_error = verr[2 * v + 1];
    }
    rc = LR_OK;
done:
    for (int i = 0; i < ndirs; i++)
        free(dirs[i]);
    free(dirs);
    if (poses)
        for (int i = 0; i < ndirs; i++)
            pose_free(&poses[i]);
    free(poses);
    free(obj);
    free(cimg);
    free(pimg);
    free(oall);
    free(call);
    free(npts);
    free(nall);
    free(verr);
    if (rc)
        lr_procam_free(out);
    return rc;
}

void lr_procam_projector_pose(const lr_procam *p, const double Rc[9], const double Tc[3],
                              double Rp[9], double Tp[3])
{
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) {
            double s = 0;
            for (int k = 0; k < 3; k++)
                s += p->R[3 * i + k] * Rc[3 * k + j];
            Rp[3 * i + j] = s;
        }
        double t = p->T[i];
        for (int k = 0; k < 3; k++)
            t += p->R[3 * i + k] * Tc[k];
        Tp[i] = t;
    }
}

/* ---- file ----------------------------------------------------------------------------- */

static void fill(lr_jw *w, const void *obj)
{
    const lr_procam *p = obj;
    lr_jw_object(w, "camera");
    lr_intrinsics_write(w, &p->cam);
    lr_jw_object_end(w);
    lr_jw_object(w, "projector");
    lr_intrinsics_write(w, &p->proj);
    lr_jw_object_end(w);
    lr_jw_matrix(w, "R", p->R, 3, 3);
    lr_jw_numbers(w, "T", p->T, 3);
    lr_jw_number(w, "rms", p->rms);
    lr_jw_number(w, "camera_rms", p->cam_rms);
    lr_jw_number(w, "projector_rms", p->proj_rms);
    lr_jw_bool(w, "camera_from_file", p->camera_from_file);
    lr_board_write(w, "board", &p->board);
    lr_jw_object(w, "decode");
    lr_jw_int(w, "contrast", p->decode.contrast > 0 ? p->decode.contrast : LR_GC_DEFAULT_CONTRAST);
    lr_jw_int(w, "shadow", p->decode.shadow > 0 ? p->decode.shadow : LR_GC_DEFAULT_SHADOW);
    lr_jw_int(w, "half_window", p->local.half_window > 0 ? p->local.half_window : 23);
    lr_jw_int(w, "min_points", p->local.min_points > 0 ? p->local.min_points : 50);
    lr_jw_number(w, "ransac_px", p->local.ransac_px > 0 ? p->local.ransac_px : 2.0);
    lr_jw_object_end(w);
    lr_jw_array(w, "poses");
    for (int i = 0; i < p->nposes; i++) {
        lr_jw_object(w, NULL);
        lr_jw_string(w, "name", p->poses[i].name);
        lr_jw_int(w, "corners", p->poses[i].corners);
        lr_jw_int(w, "valid_pixels", p->poses[i].valid_pixels);
        lr_jw_number(w, "camera_error", p->poses[i].cam_error);
        lr_jw_number(w, "projector_error", p->poses[i].proj_error);
        lr_jw_object_end(w);
    }
    lr_jw_array_end(w);
    lr_jw_array(w, "rejected");
    for (int i = 0; i < p->nrejected; i++) {
        lr_jw_object(w, NULL);
        lr_jw_string(w, "name", p->rejected[i].name);
        lr_jw_string(w, "reason", p->rejected[i].reason);
        lr_jw_object_end(w);
    }
    lr_jw_array_end(w);
}

static char *dup_string(const lr_json *j, lr_jnode obj, const char *key, const char *field,
                        lr_err *e)
{
    char buf[4096];
    lr_jnode n = lr_json_get(j, obj, key);
    if (n == LR_JNONE) {
        lr_json_fail(j, obj, field, e, LR_EPARSE, "missing");
        return NULL;
    }
    if (lr_json_string(j, n, field, buf, sizeof buf, e))
        return NULL;
    char *s = strdup(buf);
    if (!s)
        lr_err_set(e, LR_ENOMEM, "out of memory");
    return s;
}

static int from_json(const lr_json *j, lr_jnode root, lr_procam *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    static const char *const keys[] = {"version", "kind", "camera", "projector", "R", "T", "rms",
                                       "camera_rms", "projector_rms", "camera_from_file",
                                       "board", "decode", "poses", "rejected", NULL};
    int rc = lr_json_check_keys(j, root, "projector-camera calibration", keys, e);
    if (rc)
        return rc;
    lr_jnode cam, proj;
    if ((rc = lr_calfile_object(j, root, NULL, "camera", &cam, e)) ||
        (rc = lr_intrinsics_read(j, cam, "camera", &out->cam, e)) ||
        (rc = lr_calfile_object(j, root, NULL, "projector", &proj, e)) ||
        (rc = lr_intrinsics_read(j, proj, "projector", &out->proj, e)) ||
        (rc = lr_calfile_matrix(j, root, NULL, "R", 3, 3, -1.0 - 1e-9, 1.0 + 1e-9, out->R, e)) ||
        (rc = lr_calfile_numbers(j, root, NULL, "T", 3, -1e5, 1e5, out->T, e)) ||
        (rc = lr_calfile_number(j, root, NULL, "rms", 0, 1e4, &out->rms, e)))
        return rc;
    if (rotation_error(out->R) > 1e-6)
        return lr_json_fail(j, lr_json_get(j, root, "R"), "R", e, LR_EINVAL,
                            "not a rotation (orthonormality/determinant off by %.2g)",
                            rotation_error(out->R));
    /* Optional provenance. */
    if (lr_json_get(j, root, "camera_rms") != LR_JNONE &&
        (rc = lr_calfile_number(j, root, NULL, "camera_rms", 0, 1e4, &out->cam_rms, e)))
        return rc;
    if (lr_json_get(j, root, "projector_rms") != LR_JNONE &&
        (rc = lr_calfile_number(j, root, NULL, "projector_rms", 0, 1e4, &out->proj_rms, e)))
        return rc;
    if ((rc = lr_json_get_bool(j, root, "camera_from_file", false, &out->camera_from_file, e)))
        return rc;
    if (lr_json_get(j, root, "board") != LR_JNONE &&
        (rc = lr_board_read(j, root, "board", &out->board, e)))
        return rc;
    lr_jnode dec = lr_json_get(j, root, "decode");
    if (dec != LR_JNONE) {
        long c, s, hw, mp;
        if ((rc = lr_calfile_object(j, root, NULL, "decode", &dec, e)) ||
            (rc = lr_calfile_int(j, dec, "decode", "contrast", 1, 255, &c, e)) ||
            (rc = lr_calfile_int(j, dec, "decode", "shadow", 1, 255, &s, e)) ||
            (rc = lr_calfile_int(j, dec, "decode", "half_window", 1, 1000, &hw, e)) ||
            (rc = lr_calfile_int(j, dec, "decode", "min_points", 4, 1000000, &mp, e)) ||
            (rc = lr_calfile_number(j, dec, "decode", "ransac_px", 1e-3, 100,
                                    &out->local.ransac_px, e)))
            return rc;
        out->decode = (lr_gc_params){(int)c, (int)s};
        out->local.half_window = (int)hw;
        out->local.min_points = (int)mp;
    }
    lr_jnode poses = lr_json_get(j, root, "poses");
    if (poses != LR_JNONE) {
        int n;
        if ((rc = lr_calfile_array(j, root, NULL, "poses", &poses, &n, e)))
            return rc;
        out->poses = calloc((size_t)(n ? n : 1), sizeof *out->poses);
        if (!out->poses)
            return lr_err_set(e, LR_ENOMEM, "out of memory");
        for (int i = 0; i < n; i++) {
            lr_jnode v = lr_json_at(j, poses, i);
            char where[32];
            snprintf(where, sizeof where, "poses[%d]", i);
            lr_procam_pose *p = &out->poses[i];
            out->nposes = i + 1;
            long corners, valid;
            if (!(p->name = dup_string(j, v, "name", where, e)))
                return e ? e->code : LR_EPARSE;
            if ((rc = lr_calfile_int(j, v, where, "corners", 0, 100000, &corners, e)) ||
                (rc = lr_calfile_int(j, v, where, "valid_pixels", 0, 1L << 40, &valid, e)) ||
                (rc = lr_calfile_number(j, v, where, "camera_error", 0, 1e4, &p->cam_error, e)) ||
                (rc = lr_calfile_number(j, v, where, "projector_error", 0, 1e4, &p->proj_error,
                                        e)))
                return rc;
            p->corners = (int)corners;
            p->valid_pixels = valid;
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
            if (!(out->rejected[i].name = dup_string(j, v, "name", "rejected.name", e)) ||
                !(out->rejected[i].reason = dup_string(j, v, "reason", "rejected.reason", e)))
                return e ? e->code : LR_EPARSE;
        }
    }
    return LR_OK;
}

static int check(const lr_json *j, lr_jnode root, lr_err *e)
{
    lr_procam tmp;
    int rc = from_json(j, root, &tmp, e);
    lr_procam_free(&tmp);
    return rc;
}

int lr_procam_save(const char *path, const lr_procam *p, lr_err *e)
{
    return lr_calfile_save(path, LR_PROCAM_KIND, fill, p, check, e);
}

int lr_procam_load(const char *path, lr_procam *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    lr_json *j;
    lr_jnode root;
    int rc = lr_calfile_load(path, LR_PROCAM_KIND, &j, &root, e);
    if (rc)
        return rc;
    rc = from_json(j, root, out, e);
    if (rc)
        lr_procam_free(out);
    lr_json_destroy(j);
    return rc;
}
