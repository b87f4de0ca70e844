#include "calib/rig.h"

#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

static bool present(const char *dir, const char *leaf, char *path, size_t cap)
{
    snprintf(path, cap, "%s/%s", dir, leaf);
    struct stat st;
    return stat(path, &st) == 0;
}

int lr_rig_calib_load(const char *dir, lr_rig_calib *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    struct stat st;
    if (stat(dir, &st) != 0 || !S_ISDIR(st.st_mode))
        return lr_err_set(e, LR_EIO, "%s: no such calibration folder", dir);
    char path[4096];
    int rc = LR_OK;
    if (present(dir, LR_RIG_CAMERA, path, sizeof path)) {
        if ((rc = lr_camcal_load(path, &out->camera, e)))
            goto fail;
        out->has_camera = true;
    }
    if (present(dir, LR_RIG_PROJECTOR, path, sizeof path)) {
        if ((rc = lr_procam_load(path, &out->procam, e)))
            goto fail;
        out->has_procam = true;
    }
    if (present(dir, LR_RIG_CAMERA_RESPONSE, path, sizeof path)) {
        if ((rc = lr_camresp_load(path, &out->camresp, e)))
            goto fail;
        out->has_camresp = true;
    }
    if (present(dir, LR_RIG_PROJECTOR_RESPONSE, path, sizeof path)) {
        if ((rc = lr_projresp_load(path, &out->projresp, e)))
            goto fail;
        out->has_projresp = true;
    }
    if (present(dir, LR_RIG_COLOR, path, sizeof path)) {
        if ((rc = lr_colormatrix_load(path, &out->color, e)))
            goto fail;
        out->has_color = true;
    }
    if (present(dir, LR_RIG_POSE, path, sizeof path)) {
        if ((rc = lr_rig_pose_load(path, &out->pose, e)))
            goto fail;
        out->has_pose = true;
    }
    return LR_OK;
fail:
    lr_rig_calib_free(out);
    return rc;
}

void lr_rig_calib_free(lr_rig_calib *r)
{
    if (!r)
        return;
    if (r->has_camera)
        lr_camcal_free(&r->camera);
    if (r->has_procam)
        lr_procam_free(&r->procam);
    /* lr_*_free leave zeroed structs; the fixed-size ones own nothing. */
    memset(r, 0, sizeof *r);
}

static double gamma_of(const lr_rig_calib *r)
{
    return r->gamma > 0 ? r->gamma : LR_CAMRESP_DEFAULT_GAMMA;
}

void lr_rig_camera_response(const lr_rig_calib *r, lr_camresp *out)
{
    if (r->has_camresp)
        *out = r->camresp;
    else
        lr_camresp_gamma(out, gamma_of(r));
}

int lr_rig_set_gamma(lr_rig_calib *r, double gamma, lr_err *e)
{
    if (!(gamma >= 0.1 && gamma <= 10))
        return lr_err_set(e, LR_EINVAL, "gamma %g: expected 0.1..10", gamma);
    if (r->has_camresp)
        return lr_err_set(e, LR_EINVAL,
                          "gamma %g: the calibration folder has %s, the measured camera response, "
                          "and captures are read with it; drop --gamma (or the file)",
                          gamma, LR_RIG_CAMERA_RESPONSE);
    r->gamma = gamma;
    return LR_OK;
}

const char *lr_rig_response_name(const lr_rig_calib *r, char *buf, size_t cap)
{
    if (r->has_camresp)
        snprintf(buf, cap, "%s", LR_RIG_CAMERA_RESPONSE);
    else
        snprintf(buf, cap, "gamma %g (%s: no %s; --gamma G to change)", gamma_of(r),
                 r->gamma > 0 ? "given" : "assumed", LR_RIG_CAMERA_RESPONSE);
    return buf;
}

void lr_rig_camera_to_linear(const lr_rig_calib *r, const uint8_t rgb[3], double out[3])
{
    double lin[3], g = gamma_of(r);
    for (int c = 0; c < 3; c++) /* the table's entries, without building the table per pixel */
        lin[c] = r->has_camresp ? r->camresp.curve[c][rgb[c]] : lr_camresp_gamma_at(g, rgb[c]);
    if (r->has_color)
        lr_colormatrix_apply(&r->color, lin, out);
    else
        memcpy(out, lin, sizeof lin);
}

void lr_rig_projector_input(const lr_rig_calib *r, const double light[3], double level[3])
{
    for (int c = 0; c < 3; c++) {
        double y = light[c] < 0 ? 0 : light[c] > 1 ? 1 : light[c];
        level[c] = r->has_projresp ? lr_projresp_inverse(&r->projresp, c, y) : y;
    }
}
