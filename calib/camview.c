#include "calib/camview.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/mesh/bvh.h"

struct lr_camview {
    lr_intrinsics k;
    lr_pose pose;
    int rw, rh;      /* pinhole render */
    double f_r;      /* its focal length, pixels */
    float *map;      /* k.width * k.height * 2: render pixel coordinates, NaN when invalid */
    double *ray_xy;  /* k.width * k.height * 2: normalised undistorted (x', y') */
};

void lr_pose_rodrigues(const double rv[3], double R[9])
{
    double th = sqrt(rv[0] * rv[0] + rv[1] * rv[1] + rv[2] * rv[2]);
    if (th < 1e-300) {
        const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
        memcpy(R, I, sizeof I);
        return;
    }
    double x = rv[0] / th, y = rv[1] / th, z = rv[2] / th, c = cos(th), s = sin(th), t = 1 - c;
    /* R = c I + (1 - c) k k^T + s [k]x */
    R[0] = c + t * x * x;
    R[1] = t * x * y - s * z;
    R[2] = t * x * z + s * y;
    R[3] = t * x * y + s * z;
    R[4] = c + t * y * y;
    R[5] = t * y * z - s * x;
    R[6] = t * x * z - s * y;
    R[7] = t * y * z + s * x;
    R[8] = c + t * z * z;
}

void lr_pose_rvec(const double R[9], double rv[3])
{
    double c = 0.5 * (R[0] + R[4] + R[8] - 1.0);
    c = c > 1 ? 1 : c < -1 ? -1 : c;
    double th = acos(c);
    double ax = R[7] - R[5], ay = R[2] - R[6], az = R[3] - R[1]; /* 2 sin(th) k */
    double s2 = sqrt(ax * ax + ay * ay + az * az);
    if (s2 > 1e-6) {
        rv[0] = ax / s2 * th;
        rv[1] = ay / s2 * th;
        rv[2] = az / s2 * th;
        return;
    }
    if (th < 1e-3) { /* near identity: first order */
        rv[0] = 0.5 * ax;
        rv[1] = 0.5 * ay;
        rv[2] = 0.5 * az;
        return;
    }
    /* Near pi: k k^T = (R + I) / 2; take the largest diagonal column. */
    double kx = sqrt(fmax(0, (R[0] + 1) / 2)), ky = sqrt(fmax(0, (R[4] + 1) / 2)),
           kz = sqrt(fmax(0, (R[8] + 1) / 2));
    if (kx >= ky && kx >= kz) {
        ky = copysign(ky, R[1] + R[3]);
        kz = copysign(kz, R[2] + R[6]);
    } else if (ky >= kz) {
        kx = copysign(kx, R[1] + R[3]);
        kz = copysign(kz, R[5] + R[7]);
    } else {
        kx = copysign(kx, R[2] + R[6]);
        ky = copysign(ky, R[5] + R[7]);
    }
    double n = sqrt(kx * kx + ky * ky + kz * kz);
    rv[0] = kx / n * th;
    rv[1] = ky / n * th;
    rv[2] = kz / n * th;
}

void lr_pose_compose(const lr_pose *a, const lr_pose *b, lr_pose *out)
{
    lr_pose r;
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++)
            r.R[3 * i + j] = a->R[3 * i] * b->R[j] + a->R[3 * i + 1] * b->R[3 + j] +
                             a->R[3 * i + 2] * b->R[6 + j];
        r.T[i] = a->R[3 * i] * b->T[0] + a->R[3 * i + 1] * b->T[1] + a->R[3 * i + 2] * b->T[2] +
                 a->T[i];
    }
    *out = r;
}

lr_vec3 lr_pose_center(const lr_pose *p)
{
    /* C = -R^T T */
    const double *R = p->R, *T = p->T;
    return lr_v3(-(R[0] * T[0] + R[3] * T[1] + R[6] * T[2]),
                 -(R[1] * T[0] + R[4] * T[1] + R[7] * T[2]),
                 -(R[2] * T[0] + R[5] * T[1] + R[8] * T[2]));
}

/* R^T d: a device-frame direction in scene coordinates. */
static lr_vec3 to_scene(const double R[9], double x, double y, double z)
{
    return lr_v3(R[0] * x + R[3] * y + R[6] * z, R[1] * x + R[4] * y + R[7] * z,
                 R[2] * x + R[5] * y + R[8] * z);
}

int lr_camview_create(const lr_intrinsics *k, const lr_pose *pose, int max_side,
                      lr_camview **out, lr_err *e)
{
    *out = NULL;
    int rc = lr_intrinsics_check(k, "camera", e);
    if (rc)
        return rc;
    for (int i = 0; i < 9; i++)
        if (!isfinite(pose->R[i]))
            return lr_err_set(e, LR_EINVAL, "camera pose: R is not finite");
    for (int i = 0; i < 3; i++)
        if (!isfinite(pose->T[i]))
            return lr_err_set(e, LR_EINVAL, "camera pose: T is not finite");
    /* A rotation: R R^T = I to 1e-6 (the pose file checks the same on load). */
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double d = pose->R[3 * i] * pose->R[3 * j] + pose->R[3 * i + 1] * pose->R[3 * j + 1] +
                       pose->R[3 * i + 2] * pose->R[3 * j + 2];
            if (fabs(d - (i == j)) > 1e-6)
                return lr_err_set(e, LR_EINVAL, "camera pose: R is not a rotation");
        }
    if (max_side <= 0)
        max_side = 4096;
    lr_camview *v = calloc(1, sizeof *v);
    size_t n = (size_t)k->width * k->height;
    if (!v || !(v->map = malloc(n * 2 * sizeof *v->map)) ||
        !(v->ray_xy = malloc(n * 2 * sizeof *v->ray_xy))) {
        lr_camview_destroy(v);
        return lr_err_set(e, LR_ENOMEM, "camera view: out of memory");
    }
    v->k = *k;
    v->pose = *pose;
    double xmax = 0, ymax = 0;
    long valid = 0;
    for (int y = 0; y < k->height; y++)
        for (int x = 0; x < k->width; x++) {
            size_t i = (size_t)y * k->width + x;
            double uv[2] = {x, y}, xy[2];
            if (lr_intrinsics_undistort(k, uv, xy, NULL)) {
                v->ray_xy[2 * i] = v->ray_xy[2 * i + 1] = NAN;
                continue;
            }
            v->ray_xy[2 * i] = xy[0];
            v->ray_xy[2 * i + 1] = xy[1];
            xmax = fmax(xmax, fabs(xy[0]));
            ymax = fmax(ymax, fabs(xy[1]));
            valid++;
        }
    if (valid == 0) {
        lr_camview_destroy(v);
        return lr_err_set(e, LR_EINVAL, "camera view: no pixel of the %dx%d camera undistorts",
                          k->width, k->height);
    }
    /* f_r = the larger focal length: the render is at least as sharp as the camera. Two
     * pixels of margin on each side keep the bilinear footprint inside. */
    v->f_r = fmax(k->fx, k->fy);
    v->rw = 2 * (int)ceil(v->f_r * xmax + 2.0);
    v->rh = 2 * (int)ceil(v->f_r * ymax + 2.0);
    if (v->rw > max_side || v->rh > max_side) {
        int rw = v->rw, rh = v->rh;
        lr_camview_destroy(v);
        return lr_err_set(e, LR_EINVAL,
                          "camera view: the camera's field needs a %dx%d pinhole render "
                          "(more than %d px a side)",
                          rw, rh, max_side);
    }
    for (size_t i = 0; i < n; i++) {
        double xn = v->ray_xy[2 * i], yn = v->ray_xy[2 * i + 1];
        v->map[2 * i] = (float)(v->f_r * xn + 0.5 * v->rw - 0.5);
        v->map[2 * i + 1] = (float)(v->f_r * yn + 0.5 * v->rh - 0.5);
    }
    *out = v;
    return LR_OK;
}

void lr_camview_destroy(lr_camview *v)
{
    if (!v)
        return;
    free(v->map);
    free(v->ray_xy);
    free(v);
}

void lr_camview_size(const lr_camview *v, int *width, int *height)
{
    *width = v->k.width;
    *height = v->k.height;
}

void lr_camview_render_size(const lr_camview *v, int *width, int *height)
{
    *width = v->rw;
    *height = v->rh;
}

static int set_vec(lr_scene *s, const char *key, lr_vec3 p, unsigned *dirty, lr_err *e)
{
    char buf[160];
    snprintf(buf, sizeof buf, "%.17g,%.17g,%.17g", p.x, p.y, p.z);
    return lr_scene_set(s, key, buf, dirty, e);
}

int lr_camview_apply(const lr_camview *v, lr_scene *s, unsigned *dirty, lr_err *e)
{
    const double *R = v->pose.R;
    lr_vec3 c = lr_pose_center(&v->pose);
    /* Forward is the device's +Z, image up its -Y; the target distance is arbitrary. */
    lr_vec3 fwd = to_scene(R, 0, 0, 1), up = to_scene(R, 0, -1, 0);
    lr_vec3 target = lr_v3_add(c, lr_v3_scale(fwd, 1000.0));
    char fov[64];
    snprintf(fov, sizeof fov, "%.17g", 2.0 * atan(0.5 * v->rh / v->f_r) * (180.0 / M_PI));
    int rc = lr_scene_set(s, "camera.type", "perspective", dirty, e);
    if (!rc)
        rc = lr_scene_set(s, "camera.fov_deg", fov, dirty, e);
    if (rc)
        return lr_err_prefix(e, "camera view");
    /* Each change is validated on its own (position != target, up not along the view), so
     * one order can pass through an invalid intermediate camera that another avoids. */
    static const int orders[3][3] = {{0, 1, 2}, {2, 0, 1}, {1, 2, 0}};
    for (int o = 0; o < 3; o++) {
        rc = LR_OK;
        for (int i = 0; i < 3 && !rc; i++) {
            int f = orders[o][i];
            rc = set_vec(s, f == 0 ? "camera.up" : f == 1 ? "camera.position" : "camera.target",
                         f == 0 ? up : f == 1 ? c : target, dirty, e);
        }
        if (!rc)
            return LR_OK;
    }
    return lr_err_prefix(e, "camera view");
}

static void sample(const lr_image *img, double x, double y, float out[3])
{
    int W = img->width, H = img->height;
    x = x < 0 ? 0 : x > W - 1 ? W - 1 : x;
    y = y < 0 ? 0 : y > H - 1 ? H - 1 : y;
    int x0 = (int)x, y0 = (int)y;
    int x1 = x0 + 1 < W ? x0 + 1 : x0, y1 = y0 + 1 < H ? y0 + 1 : y0;
    double fx = x - x0, fy = y - y0;
    for (int c = 0; c < 3; c++) {
        double a = img->rgb[3 * ((size_t)y0 * W + x0) + c], b = img->rgb[3 * ((size_t)y0 * W + x1) + c];
        double d = img->rgb[3 * ((size_t)y1 * W + x0) + c], f = img->rgb[3 * ((size_t)y1 * W + x1) + c];
        out[c] = (float)((a * (1 - fx) + b * fx) * (1 - fy) + (d * (1 - fx) + f * fx) * fy);
    }
}

int lr_camview_remap(const lr_camview *v, const lr_image *pinhole, lr_image *out, lr_err *e)
{
    if (pinhole->width != v->rw || pinhole->height != v->rh)
        return lr_err_set(e, LR_EINVAL,
                          "camera view: pinhole render is %dx%d, the view needs %dx%d",
                          pinhole->width, pinhole->height, v->rw, v->rh);
    int rc = lr_image_alloc(out, v->k.width, v->k.height, e);
    if (rc)
        return rc;
    size_t n = (size_t)v->k.width * v->k.height;
    for (size_t i = 0; i < n; i++) {
        if (isnan(v->map[2 * i]))
            continue; /* stays black */
        sample(pinhole, v->map[2 * i], v->map[2 * i + 1], out->rgb + 3 * i);
    }
    return LR_OK;
}

int lr_camview_ray(const lr_camview *v, double u, double vv, lr_vec3 *org, lr_vec3 *dir,
                   lr_err *e)
{
    double uv[2] = {u, vv}, xy[2];
    int rc = lr_intrinsics_undistort(&v->k, uv, xy, e);
    if (rc)
        return rc;
    *org = lr_pose_center(&v->pose);
    *dir = lr_v3_normalize(to_scene(v->pose.R, xy[0], xy[1], 1.0));
    return LR_OK;
}

int lr_camview_labels(const lr_camview *v, const lr_scene *s, uint8_t *labels, lr_err *e)
{
    (void)e;
    lr_vec3 org = lr_pose_center(&v->pose);
    size_t n = (size_t)v->k.width * v->k.height;
    for (size_t i = 0; i < n; i++) {
        double xn = v->ray_xy[2 * i], yn = v->ray_xy[2 * i + 1];
        if (isnan(xn)) {
            labels[i] = LR_LABEL_INVALID;
            continue;
        }
        lr_vec3 dir = lr_v3_normalize(to_scene(v->pose.R, xn, yn, 1.0));
        double best = INFINITY;
        uint8_t label = LR_LABEL_BACKGROUND;
        lr_hit h;
        for (int j = 0; j < lr_scene_object_count(s); j++)
            if (lr_bvh_intersect(lr_scene_object_at(s, j)->bvh, org, dir, 0.0, best, &h) &&
                h.t < best) {
                best = h.t;
                label = LR_LABEL_OBJECT;
            }
        for (int j = 0; j < lr_scene_receiver_count(s); j++)
            if (lr_bvh_intersect(lr_scene_receiver_at(s, j)->bvh, org, dir, 0.0, best, &h) &&
                h.t < best) {
                best = h.t;
                label = LR_LABEL_RECEIVER;
            }
        labels[i] = label;
    }
    return LR_OK;
}
