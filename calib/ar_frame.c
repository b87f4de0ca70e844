#include "calib/ar_frame.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/cpu/frame.h"

static int set_vec(lr_scene *s, const char *key, lr_vec3 v, lr_err *e)
{
    char val[160];
    snprintf(val, sizeof val, "%.17g,%.17g,%.17g", v.x, v.y, v.z);
    return lr_scene_set(s, key, val, NULL, e);
}

static int set_num(lr_scene *s, const char *key, double v, lr_err *e)
{
    char val[64];
    snprintf(val, sizeof val, "%.17g", v);
    return lr_scene_set(s, key, val, NULL, e);
}

int lr_ar_set_camera(lr_scene *s, const lr_camera *c, lr_err *e)
{
    int rc;
    /* far before near (and position before target) would be refused midway when the new
     * values cross the old ones; each set is validated alone, so order them safely */
    if ((rc = set_num(s, "camera.far", fmax(c->far_mm, lr_scene_camera(s)->far_mm), e)) ||
        (rc = set_num(s, "camera.near", c->near_mm, e)) ||
        (rc = set_num(s, "camera.far", c->far_mm, e)) ||
        (rc = set_num(s, "camera.fov_deg", c->fov_deg, e)))
        return rc;
    /* position, target and up are validated together at each set (position != target, up
     * not along the view), so go through an up that is valid for the old view, the new one
     * and (but for degenerate placements) the view in between: perpendicular to both. */
    const lr_camera *old = lr_scene_camera(s);
    lr_vec3 v0 = lr_v3_normalize(lr_v3_sub(old->target, old->position));
    lr_vec3 v1 = lr_v3_normalize(lr_v3_sub(c->target, c->position));
    lr_vec3 mid = lr_v3_cross(v0, v1);
    if (lr_v3_len(mid) < 1e-6) /* same or opposite view: any perpendicular of it */
        mid = lr_v3_cross(v0, fabs(v0.x) < 0.9 ? lr_v3(1, 0, 0) : lr_v3(0, 1, 0));
    if ((rc = set_vec(s, "camera.up", lr_v3_normalize(mid), e)))
        return rc;
    if (set_vec(s, "camera.position", c->position, NULL) == LR_OK)
        rc = set_vec(s, "camera.target", c->target, e);
    else if ((rc = set_vec(s, "camera.target", c->target, e)) == LR_OK)
        rc = set_vec(s, "camera.position", c->position, e);
    return rc ? rc : set_vec(s, "camera.up", c->up, e);
}

int lr_ar_frame(const lr_ar_frame_desc *d, lr_image *levels, lr_image *target,
                lr_ar_stats *stats, lr_err *e)
{
    const lr_rig_calib *cal = d->calib;
    if (!cal || !cal->has_procam)
        return lr_err_set(e, LR_EINVAL,
                          "spatial AR: the calibration has no projector.json (projector "
                          "intrinsics)");
    if (!cal->has_pose || !cal->pose.has_projector)
        return lr_err_set(e, LR_EINVAL,
                          "spatial AR: the calibration has no projector pose in scene "
                          "coordinates (pose.json from `lamprig calib pose --projector ...`)");
    const lr_intrinsics *k = &cal->procam.proj;
    lr_ar_pose pose;
    memcpy(pose.R, cal->pose.projector.R, sizeof pose.R);
    memcpy(pose.T, cal->pose.projector.T, sizeof pose.T);
    lr_camera cam, saved = *lr_scene_camera(d->scene);
    double aspect;
    int rc = lr_ar_view_camera(k, &pose, 0.02, &cam, &aspect, e);
    if (rc)
        return rc;
    int rw = d->render_width > 0 ? d->render_width : k->width;
    int rh = (int)ceil(rw / aspect);
    float *map = NULL;
    lr_image render = {0}, tgt = {0}, geom = {0};
    if ((rc = lr_ar_warp_map(k, &cam, rw, rh, &map, e)))
        return rc;
    if ((rc = lr_ar_set_camera(d->scene, &cam, e)))
        goto done;
    lr_cpu_render_desc rd = {.scene = d->scene, .width = rw, .height = rh,
                             .mode = LR_CPU_REFERENCE,
                             .samples = d->samples > 0 ? d->samples : 64,
                             .no_vpl = d->no_vpl, .seed = d->seed, .threads = d->threads};
    rc = lr_cpu_render(&rd, &render, NULL, NULL, e);
    lr_err re = {0};
    if (lr_ar_set_camera(d->scene, &saved, &re) && !rc)
        rc = lr_err_set(e, re.code, "spatial AR: restoring the scene's camera: %s", re.msg);
    if (rc || (rc = lr_ar_warp(&render, map, k->width, k->height, &tgt, e)))
        goto done;
    const lr_image *resp = d->response;
    if (resp && (resp->width != k->width || resp->height != k->height)) {
        rc = lr_err_set(e, LR_EINVAL,
                        "spatial AR: the mockup response is %d x %d but the projector is %d x %d",
                        resp->width, resp->height, k->width, k->height);
        goto done;
    }
    if (!resp) {
        long lit;
        double gmax;
        if ((rc = lr_ar_geometry(d->scene, k, &pose, &geom, &lit, &gmax, e)))
            goto done;
        resp = &geom;
    }
    lr_ar_desc ad = {.target = &tgt, .response = resp, .gain = d->gain, .calib = cal};
    rc = lr_ar_compensate(&ad, levels, stats, e);
done:
    if (!rc && target) {
        *target = tgt;
        tgt.rgb = NULL;
    }
    lr_image_free(&tgt);
    lr_image_free(&render);
    lr_image_free(&geom);
    free(map);
    return rc;
}
