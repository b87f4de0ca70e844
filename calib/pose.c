#include "calib/pose.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calib/calfile.h"
#include "calib/cv_shim.h"

static double norm3(const double v[3]) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

int lr_board_placement_pose(const lr_board_placement *pl, lr_pose *out, lr_err *e)
{
    double x[3], y[3], z[3];
    double nx = norm3(pl->x_axis);
    for (int i = 0; i < 3; i++)
        if (!isfinite(pl->origin[i]) || !isfinite(pl->x_axis[i]) || !isfinite(pl->y_axis[i]))
            return lr_err_set(e, LR_EINVAL, "board placement: values must be finite");
    if (!(nx > 1e-12))
        return lr_err_set(e, LR_EINVAL, "board placement: x axis is zero");
    for (int i = 0; i < 3; i++)
        x[i] = pl->x_axis[i] / nx;
    /* Gram-Schmidt: y loses its component along x. */
    double d = x[0] * pl->y_axis[0] + x[1] * pl->y_axis[1] + x[2] * pl->y_axis[2];
    for (int i = 0; i < 3; i++)
        y[i] = pl->y_axis[i] - d * x[i];
    double ny = norm3(y);
    if (!(ny > 1e-6 * norm3(pl->y_axis)) || !(ny > 1e-12))
        return lr_err_set(e, LR_EINVAL, "board placement: y axis is zero or parallel to x");
    for (int i = 0; i < 3; i++)
        y[i] /= ny;
    z[0] = x[1] * y[2] - x[2] * y[1];
    z[1] = x[2] * y[0] - x[0] * y[2];
    z[2] = x[0] * y[1] - x[1] * y[0];
    /* X_board = B^T (X_scene - o): rows of R are the board axes in scene coordinates. */
    for (int i = 0; i < 3; i++) {
        out->R[i] = x[i];
        out->R[3 + i] = y[i];
        out->R[6 + i] = z[i];
    }
    for (int r = 0; r < 3; r++)
        out->T[r] = -(out->R[3 * r] * pl->origin[0] + out->R[3 * r + 1] * pl->origin[1] +
                      out->R[3 * r + 2] * pl->origin[2]);
    return LR_OK;
}

static void finish(const lr_procam *procam, lr_rig_pose *out)
{
    if (procam) {
        lr_procam_projector_pose(procam, out->camera.R, out->camera.T, out->projector.R,
                                 out->projector.T);
        out->has_projector = true;
    }
}

int lr_rig_pose_from_board(const lr_img *gray, const lr_board *b, const lr_board_placement *pl,
                           const lr_intrinsics *k, const lr_procam *procam, lr_rig_pose *out,
                           lr_err *e)
{
    memset(out, 0, sizeof *out);
    lr_pose scene_to_board;
    int rc = lr_board_check(b, e);
    if (rc || (rc = lr_intrinsics_check(k, "camera", e)) ||
        (rc = lr_board_placement_pose(pl, &scene_to_board, e)))
        return rc;
    if (gray->w != k->width || gray->h != k->height)
        return lr_err_set(e, LR_EINVAL,
                          "board photo is %dx%d but the camera was calibrated at %dx%d",
                          gray->w, gray->h, k->width, k->height);
    int n = lr_board_points(b);
    double *xy = malloc((size_t)n * 2 * sizeof *xy), *obj = malloc((size_t)n * 3 * sizeof *obj);
    if (!xy || !obj) {
        free(xy);
        free(obj);
        return lr_err_set(e, LR_ENOMEM, "out of memory");
    }
    bool found = false;
    rc = lr_board_detect(b, gray, 0, xy, &found, e);
    if (!rc && !found)
        rc = lr_err_set(e, LR_EINVAL, "board %dx%d not found in the photo", b->cols, b->rows);
    double K[9], rvec[3];
    lr_pose board_to_cam;
    if (!rc) {
        lr_board_object_points(b, obj);
        lr_intrinsics_matrix(k, K);
        rc = lr_cv_solve_pnp(n, obj, xy, K, k->dist, true, rvec, board_to_cam.T, &out->rms, e);
    }
    free(xy);
    free(obj);
    if (rc)
        return rc;
    lr_pose_rodrigues(rvec, board_to_cam.R);
    lr_pose_compose(&board_to_cam, &scene_to_board, &out->camera);
    out->points = n;
    snprintf(out->source, sizeof out->source, "board");
    out->has_board = true;
    out->board = *b;
    out->placement = *pl;
    finish(procam, out);
    return LR_OK;
}

int lr_rig_pose_from_points(int n, const double *scene_xyz, const double *uv,
                            const lr_intrinsics *k, const lr_procam *procam, lr_rig_pose *out,
                            lr_err *e)
{
    memset(out, 0, sizeof *out);
    int rc = lr_intrinsics_check(k, "camera", e);
    if (rc)
        return rc;
    for (int i = 0; i < 3 * n; i++)
        if (!isfinite(scene_xyz[i]))
            return lr_err_set(e, LR_EINVAL, "pose points: point %d is not finite", i / 3);
    double K[9], rvec[3];
    lr_intrinsics_matrix(k, K);
    if ((rc = lr_cv_solve_pnp(n, scene_xyz, uv, K, k->dist, false, rvec, out->camera.T,
                              &out->rms, e)))
        return rc;
    lr_pose_rodrigues(rvec, out->camera.R);
    out->points = n;
    snprintf(out->source, sizeof out->source, "points");
    finish(procam, out);
    return LR_OK;
}

/* ---- file ------------------------------------------------------------------------------- */

static void write_pose(lr_jw *w, const char *key, const lr_pose *p)
{
    lr_jw_object(w, key);
    lr_jw_matrix(w, "R", p->R, 3, 3);
    lr_jw_numbers(w, "T", p->T, 3);
    lr_jw_object_end(w);
}

static void fill(lr_jw *w, const void *obj)
{
    const lr_rig_pose *p = obj;
    lr_jw_string(w, "source", p->source);
    write_pose(w, "camera", &p->camera);
    if (p->has_projector)
        write_pose(w, "projector", &p->projector);
    lr_jw_number(w, "rms", p->rms);
    lr_jw_int(w, "points", p->points);
    if (p->has_board) {
        lr_board_write(w, "board", &p->board);
        lr_jw_object(w, "placement");
        lr_jw_numbers(w, "origin", p->placement.origin, 3);
        lr_jw_numbers(w, "x_axis", p->placement.x_axis, 3);
        lr_jw_numbers(w, "y_axis", p->placement.y_axis, 3);
        lr_jw_object_end(w);
    }
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

static int read_pose(const lr_json *j, lr_jnode root, const char *key, lr_pose *p, lr_err *e)
{
    lr_jnode o;
    int rc = lr_calfile_object(j, root, NULL, key, &o, e);
    static const char *const keys[] = {"R", "T", NULL};
    if (rc || (rc = lr_json_check_keys(j, o, key, keys, e)) ||
        (rc = lr_calfile_matrix(j, o, key, "R", 3, 3, -1.0 - 1e-9, 1.0 + 1e-9, p->R, e)) ||
        (rc = lr_calfile_numbers(j, o, key, "T", 3, -1e5, 1e5, p->T, e)))
        return rc;
    if (rotation_error(p->R) > 1e-6) {
        char field[32];
        snprintf(field, sizeof field, "%s.R", key);
        return lr_json_fail(j, lr_json_get(j, o, "R"), field, e, LR_EINVAL,
                            "not a rotation (orthonormality/determinant off by %.2g)",
                            rotation_error(p->R));
    }
    return LR_OK;
}

static int from_json(const lr_json *j, lr_jnode root, lr_rig_pose *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    static const char *const keys[] = {"version", "kind", "source", "camera", "projector",
                                       "rms", "points", "board", "placement", NULL};
    int rc = lr_json_check_keys(j, root, "pose", keys, e);
    long points;
    if (rc ||
        (rc = lr_json_get_string(j, root, "source", true, out->source, sizeof out->source, e)) ||
        (rc = read_pose(j, root, "camera", &out->camera, e)) ||
        (rc = lr_calfile_number(j, root, NULL, "rms", 0, 1e4, &out->rms, e)) ||
        (rc = lr_calfile_int(j, root, NULL, "points", 4, 1000000, &points, e)))
        return rc;
    out->points = (int)points;
    bool board = !strcmp(out->source, "board");
    if (!board && strcmp(out->source, "points"))
        return lr_json_fail(j, lr_json_get(j, root, "source"), "source", e, LR_EINVAL,
                            "expected \"board\" or \"points\", got \"%s\"", out->source);
    if (lr_json_get(j, root, "projector") != LR_JNONE) {
        if ((rc = read_pose(j, root, "projector", &out->projector, e)))
            return rc;
        out->has_projector = true;
    }
    if (board) {
        lr_jnode pl;
        static const char *const pkeys[] = {"origin", "x_axis", "y_axis", NULL};
        if ((rc = lr_board_read(j, root, "board", &out->board, e)) ||
            (rc = lr_calfile_object(j, root, NULL, "placement", &pl, e)) ||
            (rc = lr_json_check_keys(j, pl, "placement", pkeys, e)) ||
            (rc = lr_calfile_numbers(j, pl, "placement", "origin", 3, -1e5, 1e5,
                                     out->placement.origin, e)) ||
            (rc = lr_calfile_numbers(j, pl, "placement", "x_axis", 3, -1e5, 1e5,
                                     out->placement.x_axis, e)) ||
            (rc = lr_calfile_numbers(j, pl, "placement", "y_axis", 3, -1e5, 1e5,
                                     out->placement.y_axis, e)))
            return rc;
        lr_pose tmp;
        lr_err sub = {0};
        if (lr_board_placement_pose(&out->placement, &tmp, &sub))
            return lr_json_fail(j, pl, "placement", e, LR_EINVAL, "%s", sub.msg);
        out->has_board = true;
    }
    return LR_OK;
}

static int check(const lr_json *j, lr_jnode root, lr_err *e)
{
    lr_rig_pose tmp;
    return from_json(j, root, &tmp, e);
}

int lr_rig_pose_save(const char *path, const lr_rig_pose *p, lr_err *e)
{
    return lr_calfile_save(path, LR_POSE_KIND, fill, p, check, e);
}

int lr_rig_pose_load(const char *path, lr_rig_pose *out, lr_err *e)
{
    lr_json *j;
    lr_jnode root;
    int rc = lr_calfile_load(path, LR_POSE_KIND, &j, &root, e);
    if (rc)
        return rc;
    rc = from_json(j, root, out, e);
    lr_json_destroy(j);
    return rc;
}
