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

void lr_rig_camera_to_linear(const lr_rig_calib *r, const uint8_t rgb[3], double out[3])
{
    double lin[3];
    for (int c = 0; c < 3; c++)
        lin[c] = r->has_camresp ? r->camresp.curve[c][rgb[c]] : rgb[c] / 255.0;
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
